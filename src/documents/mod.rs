//! The documents a command renders from the study's typed results: the report's sections
//! ([`standard_report`]: the record, the fits, validation; [`frequency_figure`]: the
//! frequency response of every swept record), the
//! regime windows and parity figures ([`regime_figures`], placed by [`window_placement`]),
//! the identification's report
//! ([`identify_report`]), and the comparison's `compare.md` text and loop tables
//! ([`compare_markdown`], [`compare_loops`], which also writes `cycles.csv`). The figures
//! themselves are drawn by [`crate::report`], which knows no science.

pub mod compare_loops;
pub mod compare_markdown;
pub mod frequency_figure;
pub mod identify_report;
pub mod regime_figures;
pub mod results_table;
pub mod standard_report;
pub mod window_placement;
