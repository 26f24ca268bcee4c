//! The study's error: what went wrong, as a message that names the file, line and key, and
//! its kind, so that a front end can tell a bad experiment from a bad record, a model that
//! fails, a fit or discovery that cannot go on, or a stopped run (the Python package raises
//! one exception class per kind). The workflows build their errors with context
//! (`anyhow`); at the study's edge ([`crate::prelude`]) the chain becomes one
//! [`StudyError`], its kind read from the typed error at its root.

use stf_core::data::bounded::BoundedError;
use stf_core::data::record::RecordError;
use stf_core::discovery::DiscoveryError;
use stf_core::fit::FitError;
use stf_core::numerics::integrate::SimError;
use stf_core::physics::force_model::ModelError;
use stf_plugins::ScriptError;

/// What kind of thing went wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ErrorKind {
    /// The settings: an experiment file, a key, a value, a missing section.
    Experiment,
    /// A record: missing, unreadable, too large, a column or unit wrong.
    Record,
    /// A force model: a script that fails or a model that cannot be evaluated.
    Model,
    /// A fit or a simulation that cannot go on.
    Fit,
    /// A discovery that cannot go on.
    Discovery,
    /// The run was stopped by its observer.
    Interrupted,
}

/// A study that failed: its message (the whole context chain, e.g. `exp.toml:3:
/// \`data.units.x\`: …`) and its kind.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct StudyError {
    /// What kind of thing went wrong.
    pub kind: ErrorKind,
    /// The message, as the command line prints it.
    pub message: String,
}

impl StudyError {
    /// A run stopped by its observer.
    pub fn interrupted() -> Self {
        StudyError {
            kind: ErrorKind::Interrupted,
            message: "interrupted".into(),
        }
    }
}

impl From<anyhow::Error> for StudyError {
    fn from(e: anyhow::Error) -> Self {
        let kind = e.chain().find_map(kind_of).unwrap_or(ErrorKind::Experiment);
        StudyError {
            kind,
            message: format!("{e:#}"),
        }
    }
}

/// The kind of one error of a chain, if it is one the study knows.
fn kind_of(e: &(dyn std::error::Error + 'static)) -> Option<ErrorKind> {
    if e.is::<Interrupted>() {
        Some(ErrorKind::Interrupted)
    } else if e.is::<RecordError>() || e.is::<BoundedError>() {
        Some(ErrorKind::Record)
    } else if let Some(script) = e.downcast_ref::<ScriptError>() {
        // A name no model has, or a script path that is not one, is a mistake of the
        // settings; a script that fails is the model's.
        Some(match script {
            ScriptError::UnknownModel { .. }
            | ScriptError::NotAScript { .. }
            | ScriptError::Read { .. } => ErrorKind::Experiment,
            _ => ErrorKind::Model,
        })
    } else if e.is::<ModelError>() {
        Some(ErrorKind::Model)
    } else if e.is::<DiscoveryError>() {
        Some(ErrorKind::Discovery)
    } else if e.is::<FitError>() || e.is::<SimError>() {
        Some(ErrorKind::Fit)
    } else {
        None
    }
}

/// The error a workflow returns when its observer asks it to stop.
#[derive(Debug, thiserror::Error)]
#[error("interrupted: the run was stopped before it finished; nothing was written")]
pub struct Interrupted;
