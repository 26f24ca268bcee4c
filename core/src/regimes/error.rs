//! Errors of the regime analysis: inputs that cannot be analysed, with what was wrong.

use thiserror::Error;

use crate::data::force_data::ForceDataError;

/// Why a regime analysis could not run.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RegimeError {
    /// Two signals that must be sampled together have different lengths.
    #[error("signal `{name}` has {len} samples, `t` has {expected}")]
    LengthMismatch {
        /// The signal's name.
        name: &'static str,
        /// Its length.
        len: usize,
        /// The length of `t`.
        expected: usize,
    },
    /// A signal holds a NaN or an infinity.
    #[error("signal `{name}` is not finite at sample {index}")]
    NonFinite {
        /// The signal's name.
        name: &'static str,
        /// The first bad sample.
        index: usize,
    },
    /// Time does not increase strictly.
    #[error("time does not increase strictly at sample {index}")]
    TimeNotIncreasing {
        /// The first sample whose time is not after the previous one.
        index: usize,
    },
    /// Too few samples for the estimate asked for.
    #[error("{what} needs at least {needed} samples, got {got}")]
    TooShort {
        /// What was being computed.
        what: &'static str,
        /// Samples needed.
        needed: usize,
        /// Samples given.
        got: usize,
    },
    /// A cycle's indices do not fit the signals.
    #[error("cycle {start}..{end} does not fit {len} samples")]
    BadCycle {
        /// First sample.
        start: usize,
        /// First sample of the next cycle.
        end: usize,
        /// Number of samples.
        len: usize,
    },
    /// A threshold is out of its range.
    #[error("regime threshold `{name}` = {value}: {why}")]
    BadThreshold {
        /// The threshold's key in the experiment file.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The allowed range.
        why: &'static str,
    },
}

impl From<ForceDataError> for RegimeError {
    fn from(e: ForceDataError) -> Self {
        match e {
            ForceDataError::LengthMismatch {
                name,
                len,
                expected,
            } => RegimeError::LengthMismatch {
                name,
                len,
                expected,
            },
            ForceDataError::NonFinite { name, index, .. } => RegimeError::NonFinite { name, index },
            ForceDataError::TimeNotIncreasing { index } => RegimeError::TimeNotIncreasing { index },
        }
    }
}

/// Check that every sample of `x` is finite.
pub(crate) fn check_finite(name: &'static str, x: &[f64]) -> Result<(), RegimeError> {
    match x.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(RegimeError::NonFinite { name, index }),
        None => Ok(()),
    }
}

/// Check that `x` has `n` values (samples, or labels of `n` cycles).
pub(crate) fn check_len<T>(name: &'static str, x: &[T], n: usize) -> Result<(), RegimeError> {
    if x.len() == n {
        Ok(())
    } else {
        Err(RegimeError::LengthMismatch {
            name,
            len: x.len(),
            expected: n,
        })
    }
}
