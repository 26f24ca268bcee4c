//! Why a simulation stopped.

use crate::model_error::ModelError;
use thiserror::Error;

/// A simulation could not be completed; each failure says when it happened.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SimError {
    /// The step size collapsed below what floating point can resolve.
    #[error("step size became too small at t = {time} s")]
    StepSizeTooSmall {
        /// Time, s.
        time: f64,
    },
    /// The step budget ran out.
    #[error("gave up at t = {time} s after {steps} steps")]
    TooManySteps {
        /// Time, s.
        time: f64,
        /// Steps taken.
        steps: u64,
    },
    /// The force model failed.
    #[error("at t = {time} s: {source}")]
    Model {
        /// Time, s.
        time: f64,
        /// What the model said.
        source: ModelError,
    },
    /// A NaN or infinity appeared.
    #[error("at t = {time} s: {what} is not finite")]
    NonFinite {
        /// Time, s.
        time: f64,
        /// Which quantity.
        what: String,
    },
    /// The effective mass m + m_a is not positive.
    #[error("at t = {time} s: the effective mass m + m_a = {mass} kg is not positive")]
    NonPositiveMass {
        /// Time, s.
        time: f64,
        /// m + m_a, kg.
        mass: f64,
    },
    /// The settings or the request make no sense.
    #[error("invalid simulation request: {0}")]
    BadSettings(String),
}

impl SimError {
    /// The time at which the failure happened, if it has one.
    pub fn time(&self) -> Option<f64> {
        match self {
            SimError::StepSizeTooSmall { time }
            | SimError::TooManySteps { time, .. }
            | SimError::Model { time, .. }
            | SimError::NonFinite { time, .. }
            | SimError::NonPositiveMass { time, .. } => Some(*time),
            SimError::BadSettings(_) => None,
        }
    }
}
