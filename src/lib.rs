//! `stf_lab`: the library behind the `stf-lab` program of the shear-thickening fluid lab. The
//! science is the study crate's (`stf_study`: experiment settings, fits, comparisons,
//! discovery, their typed results, re-exported here under their old paths); this crate runs
//! the [`commands`] (simulate, fit, compare, discover, models: each reads the experiment, runs
//! the study, writes its results through [`writing`] and renders its [`documents`], whose
//! figures [`report`] draws), [`campaign`]s of them over many records, and the [`terminal`]
//! (what is printed, the progress display, Ctrl-C). The binary (`src/main.rs`)
//! only parses the command line and calls one command; integration tests and fuzz targets use
//! the same functions.

// `!(a > b)` is how this crate says "not greater, or NaN": the NaN case is meant.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
#![deny(clippy::unwrap_used)]

pub use stf_study::{
    compare, data_layout, digits, discovery_curves, equation, experiment, fitting, identify,
    model_config, observer, outputs, param_table, plausibility, validation, verdict,
};

pub mod campaign;
pub mod commands;
pub mod documents;
pub mod report;
pub mod results;
pub mod terminal;
pub mod writing;
