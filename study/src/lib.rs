//! `stf_study`: the shear-thickening fluid lab's workflow as a typed library. It takes a
//! record and typed settings ([`experiment::Experiment`], read from an experiment file or
//! built in code) and returns typed results for every workflow the `stf-lab` commands run:
//! fit at force or trajectory level ([`fitting`]), staged identification, comparison regime by
//! regime ([`compare`]), discovery ([`discover`]), validation on a second record
//! ([`validation`]) and the campaign's joint fit. Every decision that makes a number what it
//! is (the fit level, the oscillator a record shows, bounds that follow the record, noise
//! floors, warnings, verdicts) is taken here, once; the command line, the reports, campaigns
//! and the Python package only render and write these results. The results are the
//! `Serialize` types of [`outputs`]: what a command writes as JSON is one of them.
//!
//! A researcher starts from [`prelude`]: `read_experiment`, then `fit`, `compare`, `discover`
//! or `identify`, each returning a typed result or a [`error::StudyError`].
//!
//! Layers: `stf-lab` (program) → `stf-study` → `stf-plugins` → `stf-models` → `stf-core`.

// `!(a > b)` is how this crate says "not greater, or NaN": the NaN case is meant.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
#![deny(clippy::unwrap_used)]

pub mod channel_laws;
pub mod channels;
pub mod compare;
pub mod data_layout;
pub mod digits;
pub mod discover;
pub mod discovered_entry;
pub mod discovery_curves;
pub mod equation;
pub mod error;
pub mod experiment;
pub mod fit;
pub mod fitting;
pub mod identify;
pub mod joint;
pub mod measured_velocity;
pub mod model_config;
pub mod observer;
pub mod outputs;
pub mod param_table;
pub mod param_units;
pub mod plausibility;
pub mod plausible_scale;
pub mod prelude;
pub mod rig_words;
pub mod script_plan;
pub mod shown_units;
pub mod simulate;
pub mod validation;
pub mod verdict;
