//! Errors at the boundary: every Rust error becomes one exception of the small hierarchy in
//! `stf_lab/_errors.py` (`StfLabError` → `RecordError`, `ExperimentError`, `ModelError`,
//! `FitError`, `Interrupted`), with the message the command line prints (`{:#}`: the whole
//! context chain, so file, line and key are in it).
//!
//! The class is chosen from the error itself where its chain holds a typed core or plugins
//! error (a record's, a model's or script's, a fit's or discovery's), else from what the call
//! was doing ([`Kind`] given by the caller): reading an experiment file is an
//! `ExperimentError` unless a record or script underneath failed.

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use stf_core::data::record::{LayoutError, RecordError};
use stf_core::discovery::DiscoveryError;
use stf_core::fit::FitError;
use stf_core::physics::force_model::ModelError;
use stf_plugins::ScriptError;

/// The exception classes of `stf_lab._errors`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A record could not be read or is not usable.
    Record,
    /// An experiment file (or an experiment built in Python) is not valid.
    Experiment,
    /// A model (built-in name, sum or script) could not be resolved or evaluated.
    Model,
    /// A fit, comparison or discovery could not run.
    Fit,
    /// Ctrl-C (the notebook's stop button) ended the run; nothing was written.
    Interrupted,
    /// Anything else (the base class).
    Other,
}

impl Kind {
    /// The class name in `stf_lab._errors`.
    pub fn class_name(self) -> &'static str {
        match self {
            Kind::Record => "RecordError",
            Kind::Experiment => "ExperimentError",
            Kind::Model => "ModelError",
            Kind::Fit => "FitError",
            Kind::Interrupted => "Interrupted",
            Kind::Other => "StfLabError",
        }
    }
}

/// The kind of `err` by the typed errors in its chain, else `default`.
pub fn kind_of(err: &anyhow::Error, default: Kind) -> Kind {
    for cause in err.chain() {
        if cause.is::<RecordError>() || cause.is::<LayoutError>() {
            return Kind::Record;
        }
        if cause.is::<ScriptError>() || cause.is::<ModelError>() {
            return Kind::Model;
        }
        if cause.is::<FitError>() || cause.is::<DiscoveryError>() {
            return Kind::Fit;
        }
    }
    default
}

/// A Python exception of class `kind` carrying `message`.
pub fn py_error(py: Python<'_>, kind: Kind, message: String) -> PyErr {
    let class = py
        .import("stf_lab._errors")
        .and_then(|m| m.getattr(kind.class_name()));
    match class {
        Ok(class) => match class.call1((message.clone(),)) {
            Ok(instance) => PyErr::from_value(instance),
            Err(e) => e,
        },
        Err(_) => PyRuntimeError::new_err(message),
    }
}

/// `err` as the Python exception of its kind (`default` when its chain does not say), with the
/// command line's message.
pub fn to_py(py: Python<'_>, err: &anyhow::Error, default: Kind) -> PyErr {
    py_error(py, kind_of(err, default), format!("{err:#}"))
}

/// A failed call: its error and the kind it defaults to.
pub struct CallError {
    /// What went wrong.
    pub error: anyhow::Error,
    /// The exception class when the error's chain does not choose one.
    pub kind: Kind,
}

impl CallError {
    /// `error`, of `kind` unless its chain says otherwise.
    pub fn new(error: anyhow::Error, kind: Kind) -> Self {
        CallError { error, kind }
    }

    /// The Python exception.
    pub fn into_py(self, py: Python<'_>) -> PyErr {
        to_py(py, &self.error, self.kind)
    }
}

/// `Result<T, anyhow::Error>` → `CallError` of a default kind.
pub trait OrKind<T> {
    /// This result with its error defaulting to `kind`.
    fn or_kind(self, kind: Kind) -> Result<T, CallError>;
}

impl<T> OrKind<T> for anyhow::Result<T> {
    fn or_kind(self, kind: Kind) -> Result<T, CallError> {
        self.map_err(|e| CallError::new(e, kind))
    }
}
