//! Named model parameters: name, unit, default and bounds.
//!
//! A [`ParamSpec`] describes one parameter of a force model; the values themselves travel as a
//! plain `&[f64]` in the order of the specs, resolved once when a model is configured, so the
//! right-hand side of the ODE never looks a name up.

use derive_setters::Setters;
use serde::Serialize;

/// One named parameter of a force model.
#[derive(Clone, Debug, PartialEq, Serialize, Setters)]
#[setters(generate = false)]
pub struct ParamSpec {
    /// Name used in experiment files and results (`K`, `n`, `power_law.K` in a sum).
    pub name: String,
    /// SI unit, as text (`"N·s/m"`); empty for dimensionless parameters.
    pub unit: String,
    /// Value used when the experiment file gives none.
    pub default: f64,
    /// Lower bound (inclusive).
    pub min: f64,
    /// Upper bound (inclusive).
    pub max: f64,
    /// One line saying what the parameter is.
    pub doc: String,
    /// The oscillator parameter this one duplicates, if any (a fluid's linear damping `c_s` is
    /// the same term as the oscillator's `c`): a fit may free one of the two, never both.
    #[setters(generate, strip_option)]
    pub same_as: Option<&'static str>,
}

impl ParamSpec {
    /// A parameter with its unit, default, bounds and one line of doc.
    pub fn new(name: &str, unit: &str, default: f64, min: f64, max: f64, doc: &str) -> Self {
        ParamSpec {
            name: name.to_string(),
            unit: unit.to_string(),
            default,
            min,
            max,
            doc: doc.to_string(),
            same_as: None,
        }
    }

    /// Whether `value` lies within the bounds.
    pub fn contains(&self, value: f64) -> bool {
        value >= self.min && value <= self.max
    }
}

/// The defaults of a list of specs, in order.
pub fn defaults(specs: &[ParamSpec]) -> Vec<f64> {
    specs.iter().map(|s| s.default).collect()
}
