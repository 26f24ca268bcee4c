//! Figures and self-contained reports: the plots the source study uses (time histories,
//! hysteresis loops coloured by time, the frequency response with its smoothed trend, measured
//! against fitted force), each written as SVG, PNG and a CSV of every plotted series, and a
//! report gathering tables and figures into one self-contained `report.html` and a `report.md`.
//!
//! The API takes plain data (slices of `f64`, labels), so it knows nothing of fitting.
//! Fonts are embedded in the binary ([`font`]), so rendering needs no system library. Every
//! file is written atomically (a temporary file beside the target, then a rename:
//! [`crate::writing::atomic`]).
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use std::path::Path;
//! use stf_lab::report;
//! let t: Vec<f64> = (0..1000).map(|i| i as f64 * 1e-3).collect();
//! let x: Vec<f64> = t.iter().map(|t| (20.0 * t).sin() * 1e-3).collect();
//! let f: Vec<f64> = t.iter().map(|t| (20.0 * t).cos()).collect();
//! let files = report::hysteresis(Path::new("out"), "loop_x", ("x, m", &x), ("F_STF, N", &f), &t)?;
//! let mut report = report::Report::new("Power-law fit");
//! report.intro.push("What was fitted and how well.".into());
//! let mut section = report::Section::new("Hysteresis");
//! section.figures.push(report::FigureRef::new(files, "F_STF against x, coloured by time."));
//! report.sections.push(section);
//! report::write_html(&report, Path::new("out/report.html"))?;
//! # Ok(()) }
//! ```

mod colour;
mod decimate;
mod document;
mod envelope;
mod error;
mod error_bars;
mod extrema;
mod figure;
mod font;
mod frequency_response;
mod html;
mod hysteresis;
mod markdown;
mod measured_vs_fitted;
mod motion_labels;
mod parity;
mod plot_range;
mod print_check;
mod raster;
mod regime_errors;
mod regime_time_windows;
mod regime_windows;
mod series_csv;
mod smoothing;
pub mod test_signals;
mod time_history;

pub use decimate::{decimate_indices, decimate_union, MAX_POINTS_PER_LINE};
pub use document::{FigureRef, Report, Section, Table};
pub use error::ReportError;
pub use error_bars::{error_bars, error_bars_with_curve, Curve, ErrorPoint, ErrorSeries};
pub use extrema::{extrema, Extremum, ExtremumKind};
pub use figure::MIN_TEXT_PT;
pub use figure::{milli, FigureFiles};
pub use frequency_response::{frequency_response, FrfCurve, FrfRole, RegimeChange};
pub use html::write_html;
pub use hysteresis::hysteresis;
pub use markdown::{md_text, write_markdown};
pub use measured_vs_fitted::{
    measured_vs_model, Quantity, DISPLACEMENT_MM, DISPLACEMENT_RESIDUAL_MM,
    DISPLACEMENT_VALIDATION_MM, STF_FORCE, STF_FORCE_RESIDUAL, STF_FORCE_VALIDATION,
};
pub use motion_labels::MotionLabels;
pub use parity::{parity, ParityQuantity, SampleGroup};
pub use print_check::{print_problems, printed_texts, PrintedText};
pub use raster::{stray_coloured_pixels, svg_to_png, PNG_SCALE};
pub use regime_errors::regime_errors;
pub use regime_time_windows::{regime_time_windows, TimeRow};
pub use regime_windows::{regime_windows, RegimeWindow, WindowSeries};
pub use series_csv::{read_csv_columns, Column};
pub use smoothing::{smooth_trend, Smoothing};
pub use time_history::{time_history, Motion};
