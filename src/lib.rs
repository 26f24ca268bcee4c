//! `stf_lab`: the library behind the `stf-lab` program of the shear-thickening fluid lab. It
//! reads experiment files ([`experiment`]), runs the commands (`cmd_*`: simulate, fit,
//! compare, discover, models, and [`campaign`]s of them over many records), scores fitted models on a second record ([`validation`]), and
//! writes results ([`outputs`]: one `Serialize` type a file, written by [`output`]), figures
//! and reports ([`report`], [`standard_report`],
//! [`discovery_curves`]). The binary (`src/main.rs`) only parses the command line and
//! calls one `cmd_*::run`; integration tests and fuzz targets use the same functions.

// `!(a > b)` is how this crate says "not greater, or NaN": the NaN case is meant.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
#![deny(clippy::unwrap_used)]

pub mod campaign;
pub mod cmd_campaign;
pub mod cmd_compare;
pub mod cmd_discover;
pub mod cmd_fit;
pub mod cmd_models;
pub mod cmd_simulate;
pub mod compare_loops;
pub mod compare_markdown;
pub mod data_layout;
pub mod digits;
pub mod discovery_curves;
pub mod experiment;
pub mod fitting;
pub mod identify_report;
pub mod interrupt;
pub mod model_config;
pub mod output;
pub mod output_lock;
pub mod outputs;
pub mod param_table;
pub mod plausibility;
pub mod progress;
pub mod regime_figures;
pub mod report;
pub mod results_dir;
pub mod script_plan;
pub mod staged_files;
pub mod standard_report;
pub mod terminal;
pub mod validation;
pub mod verdict;
