//! Errors at the boundary: every study error becomes one exception of the small hierarchy in
//! `stf_lab/_errors.py` (`StfLabError` → `RecordError`, `ExperimentError`, `ModelError`,
//! `FitError` → `DiscoveryError`, `Interrupted`), with the message the command line prints
//! after `error:` (the whole context chain: file, line and key where it has them). The class
//! is the study's [`ErrorKind`], read from the typed error at the chain's root.

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use stf_study::error::{ErrorKind, StudyError};

/// The exception class of `kind` in `stf_lab._errors`.
pub fn class_name(kind: ErrorKind) -> &'static str {
    match kind {
        ErrorKind::Record => "RecordError",
        ErrorKind::Experiment => "ExperimentError",
        ErrorKind::Model => "ModelError",
        ErrorKind::Fit => "FitError",
        ErrorKind::Discovery => "DiscoveryError",
        ErrorKind::Interrupted => "Interrupted",
    }
}

/// A Python exception of class `class` (of `stf_lab._errors`) carrying `message`.
pub fn py_error(py: Python<'_>, class: &str, message: String) -> PyErr {
    let class = py.import("stf_lab._errors").and_then(|m| m.getattr(class));
    match class {
        Ok(class) => match class.call1((message.clone(),)) {
            Ok(instance) => PyErr::from_value(instance),
            Err(e) => e,
        },
        Err(_) => PyRuntimeError::new_err(message),
    }
}

/// `err` as the Python exception of its kind, with the command line's message.
pub fn to_py(py: Python<'_>, err: &StudyError) -> PyErr {
    py_error(py, class_name(err.kind), err.message.clone())
}

/// An error of this package's own (a figure, a thread), not of the study: `StfLabError`.
pub fn other(py: Python<'_>, message: String) -> PyErr {
    py_error(py, "StfLabError", message)
}

/// `anyhow` errors (the few steps restated here) as study errors, their kind read from the
/// chain as the study reads it.
pub fn study(e: anyhow::Error) -> StudyError {
    StudyError::from(e)
}

/// A study error of `kind` with `message`.
pub fn of_kind(kind: ErrorKind, message: impl Into<String>) -> StudyError {
    StudyError {
        kind,
        message: message.into(),
    }
}
