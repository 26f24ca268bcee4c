//! A checked `[global]` section of a campaign: the model, the parameters shared by every
//! record, those that follow a power law of a condition, the held-out record and the level.
//! The campaign file's reader (the program's `campaign/global_file.rs`) builds it.

use crate::experiment::{FitLevel, ModelEntry};

/// A parameter made a power law of a condition: `param = param0·(condition/reference)^p`.
#[derive(Clone, Debug, PartialEq)]
pub struct Law {
    /// The model's parameter (`K`).
    pub param: String,
    /// The condition it follows (a name of `campaign.conditions`).
    pub condition: String,
    /// The condition's reference value, at which the parameter is `param0`.
    pub reference: f64,
}

/// A checked `[global]` section.
#[derive(Clone, Debug)]
pub struct GlobalSpec {
    /// The model as written (`power_law`, `a + b`).
    pub model: String,
    /// The experiment's `[[models]]` entry it names (in the campaign's experiment).
    pub entry: ModelEntry,
    /// The experiment the model and the fit settings come from: the campaign's, else the
    /// first record's.
    pub experiment: std::path::PathBuf,
    /// Parameters with one value for every record.
    pub shared: Vec<String>,
    /// Parameters following a law of a condition.
    pub laws: Vec<Law>,
    /// The held-out record: an index into the campaign's units.
    pub holdout: Option<usize>,
    /// What every fit aims at: `level`, else the experiment's `[fit] level`, else force.
    pub level: FitLevel,
    /// Line of `[global]` in the campaign file.
    pub line: usize,
}
