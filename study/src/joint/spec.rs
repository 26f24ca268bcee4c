//! A checked `[global]` section of a campaign: the model, the parameters shared by every
//! record, those that follow a law of a condition, the held-out record and the level.
//! The campaign file's reader (the program's `campaign/global_file.rs`) builds it.

use crate::experiment::{FitLevel, ModelEntry};

pub use stf_core::physics::channel_law::Law as Form;

/// A parameter made a law of a condition c: without a `form`,
/// `param = param0·(c/reference)^param_p`; with one, the channel law of x = c/reference
/// (`linear` P_gain·x, `affine` P_base + P_gain·x, `power` P_base + P_gain·|x|^P_exp).
#[derive(Clone, Debug, PartialEq)]
pub struct Law {
    /// The model's parameter (`K`).
    pub param: String,
    /// The condition it follows (a name of `campaign.conditions`).
    pub condition: String,
    /// The condition's reference value: c is divided by it (1 for a linear or affine law
    /// given none).
    pub reference: f64,
    /// The law's form (`law = "…"`); `None`: the power law without offset.
    pub form: Option<Form>,
}

impl Law {
    /// The law's variable at condition value `c`: c/reference.
    pub fn ratio(&self, c: f64) -> f64 {
        c / self.reference
    }
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
