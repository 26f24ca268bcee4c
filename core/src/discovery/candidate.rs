//! A candidate effect: a named force model that discovery may add to the current model.

use std::sync::Arc;

use super::error::DiscoveryError;
use crate::physics::force_model::ForceModel;

/// An effect the discovery may add, by name (e.g. a name of docs/ARCHITECTURE.md §5, or a script's).
///
/// The model's parameters start at their defaults when the candidate is tried; its name in
/// the sum is the model's own [`ForceModel::name`], `name` is what reports call the effect.
#[derive(Clone)]
pub struct Candidate {
    /// The effect's name in reports.
    pub name: String,
    /// The model of the effect.
    pub model: Arc<dyn ForceModel>,
}

impl Candidate {
    /// A candidate called `name` whose force is `model`'s.
    pub fn new(name: impl Into<String>, model: Arc<dyn ForceModel>) -> Self {
        Candidate {
            name: name.into(),
            model,
        }
    }
}

/// Check that no two of `candidates` share a name or a model name.
pub(super) fn distinct(candidates: &[Candidate]) -> Result<(), DiscoveryError> {
    for (i, c) in candidates.iter().enumerate() {
        let twice = candidates[..i]
            .iter()
            .any(|d| d.name == c.name || d.model.name() == c.model.name());
        if twice {
            return Err(DiscoveryError::DuplicateCandidate(c.name.clone()));
        }
    }
    Ok(())
}

impl std::fmt::Debug for Candidate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Candidate")
            .field("name", &self.name)
            .field("model", &self.model.name())
            .finish()
    }
}
