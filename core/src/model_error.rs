//! The error a force model raises when it cannot evaluate, in its own module beneath both
//! the physics (which raises it) and the numerics (whose integrators stop on it and report
//! when), so that neither layer imports the other's errors. Its public path is
//! `physics::force_model::ModelError`.

use thiserror::Error;

/// A force model failed to evaluate (a script error, a non-finite result, …).
#[derive(Debug, Error, Clone, PartialEq)]
#[error("model `{model}`: {message}")]
pub struct ModelError {
    /// The model's name, or a script's path.
    pub model: String,
    /// What went wrong; for scripts, with the line.
    pub message: String,
}

impl ModelError {
    /// An error of model `model` saying `message`.
    pub fn new(model: impl Into<String>, message: impl Into<String>) -> Self {
        ModelError {
            model: model.into(),
            message: message.into(),
        }
    }
}
