//! Why a fit could not start or run: typed errors naming the parameter or datum at fault.
//!
//! A failure *inside* a fit (a simulation that diverges, a model that errs for some parameter
//! values) is not an error: it becomes a penalty and is counted in the result. These errors
//! are for requests that make no sense and for starts that cannot even be evaluated.

use thiserror::Error;

use crate::data::force_data::ForceDataError;

/// A fit request was invalid or could not be run.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum FitError {
    /// No parameter of that name exists.
    #[error("unknown parameter `{name}`; known: {known}")]
    UnknownParam {
        /// The name asked for.
        name: String,
        /// The names that exist, comma-separated.
        known: String,
    },
    /// A name that both the oscillator and the STF model use.
    #[error("parameter `{0}` is both an oscillator and a model parameter; rename the model's")]
    AmbiguousParam(String),
    /// The same parameter listed twice.
    #[error("parameter `{0}` is listed twice")]
    DuplicateParam(String),
    /// Bounds with `min ≥ max` or NaN.
    #[error("parameter `{name}`: bounds must satisfy min < max (got min {min}, max {max})")]
    BadBounds {
        /// Parameter.
        name: String,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// A start value outside its bounds (or not finite).
    #[error("parameter `{name}`: start value {value} lies outside [{min}, {max}]")]
    OutOfBounds {
        /// Parameter.
        name: String,
        /// The start value.
        value: f64,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Two free parameters that are one term of the equation, or an offset that does nothing.
    #[error("{0}")]
    SameTerm(String),
    /// The data cannot be fitted (lengths differ, too few samples, NaN, …).
    #[error("bad data: {0}")]
    BadData(String),
    /// Settings out of range.
    #[error("bad fit settings: {0}")]
    BadSettings(String),
    /// The model cannot be evaluated at the start values: there is nothing to improve on.
    #[error("the start values cannot be evaluated: {0}")]
    StartFails(String),
    /// The optimiser itself reported an error.
    #[error("optimiser error: {0}")]
    Solver(String),
    /// The trace of the fit's iterations ([`FitSettings::trace`](super::FitSettings::trace))
    /// cannot be written.
    #[error("cannot write the fit's trace to {path}: {reason}")]
    Trace {
        /// The trace file.
        path: String,
        /// Why.
        reason: String,
    },
}

impl From<ForceDataError> for FitError {
    fn from(e: ForceDataError) -> Self {
        FitError::BadData(e.to_string())
    }
}
