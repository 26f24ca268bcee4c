//! What a discovery run found: the effects named, the evidence of every step, the gap before
//! and after and the final model.

use std::sync::Arc;

use serde::Serialize;

use super::force_gap::GapLocation;
use super::score::Step;
use crate::fit::{FitResult, FittedParam, NoiseFloor};
use crate::physics::force_model::ForceModel;
use crate::physics::oscillator_params::OscillatorParams;

/// The outcome of a discovery at either level ([`super::discover_force`],
/// [`super::discover_trajectory`]): gaps, residuals and the floor are in the level's SI unit
/// (N at force level, m at trajectory level).
#[derive(Clone, Serialize)]
pub struct Discovery {
    /// The base model's name.
    pub base: String,
    /// The effects added, in order.
    pub effects: Vec<String>,
    /// Every step: the scores of every candidate and what was decided.
    pub steps: Vec<Step>,
    /// The final model's noise floor σ, N: the force sensor's noise with the kinematics'
    /// noise propagated through the final model.
    pub noise_floor: f64,
    /// Its parts: the sensor's noise (`measured`) and the kinematics' (`propagated`).
    pub noise_floor_parts: NoiseFloor,
    /// Held-out cycles and samples.
    pub holdout_cycles: usize,
    /// Held-out samples.
    pub holdout_samples: usize,
    /// RMS of measured − modelled F_STF over the whole record with the base fitted on it, N.
    pub gap_before: f64,
    /// The same with the final model fitted on the whole record, N.
    pub gap_after: f64,
    /// Where the base model's residual lives.
    pub where_before: GapLocation,
    /// Where the final model's residual lives.
    pub where_after: GapLocation,
    /// Measured − modelled force of the base at every sample, N (not serialized).
    #[serde(skip)]
    pub residual_before: Vec<f64>,
    /// Measured − modelled force of the final model at every sample, N (not serialized).
    #[serde(skip)]
    pub residual_after: Vec<f64>,
    /// The base model (not serialized; its name is `base`).
    #[serde(skip)]
    pub base_model: Arc<dyn ForceModel>,
    /// The base's parameter values fitted on the whole record, in its own order (without the
    /// offset).
    pub base_values: Vec<f64>,
    /// That fit's parameters with standard errors: the base's, the offset if fitted, and at
    /// trajectory level the refitted oscillator parameters and initial state.
    pub base_params: Vec<FittedParam>,
    /// The final model: the base, or a [`crate::physics::model_sum::ModelSum`] of the base and the
    /// effects (not serialized; its name is `final_model_name`).
    #[serde(skip)]
    pub final_model: Arc<dyn ForceModel>,
    /// The final model's name (`power_law + viscous`).
    pub final_model_name: String,
    /// The final model's parameter values in its own order (without the offset).
    pub final_values: Vec<f64>,
    /// The final fit's parameters with standard errors (and `f_off` if fitted).
    pub final_params: Vec<FittedParam>,
    /// The final fit on the whole record.
    pub final_fit: FitResult,
    /// Sentences for the report: where the gap lives, what each step found, the ties.
    pub notes: Vec<String>,
    /// At trajectory level, the oscillator as refitted and S(μ) (not
    /// serialized); `None` at force level.
    #[serde(skip)]
    pub trajectory: Option<TrajectoryPart>,
}

/// What a trajectory-level discovery says beyond the shared report: the oscillator as
/// refitted with the base and the final model, S(μ), and the states their simulations start
/// from (their simulated x is the measured x less [`Discovery`]'s residuals). The final
/// `final_params` of the shared report hold the refitted oscillator parameters too (and
/// `x_off` if fitted).
#[derive(Clone, Debug)]
pub struct TrajectoryPart {
    /// The oscillator refitted with the base on the whole record.
    pub system_before: OscillatorParams,
    /// The oscillator refitted with the final model on the whole record.
    pub system_after: OscillatorParams,
    /// S(μ) of the base on the whole record, mm².
    pub s_before_mm2: f64,
    /// S(μ) of the final model on the whole record, mm².
    pub s_after_mm2: f64,
    /// The state (x0 m, v0 m/s) the base's simulation starts from: fitted, or the setup's
    /// estimate less the offset.
    pub initial_before: [f64; 2],
    /// The same for the final model.
    pub initial_after: [f64; 2],
}

impl Discovery {
    /// The final value of parameter `name`.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.final_fit.value(name)
    }

    /// The step at which `effect` was accepted.
    pub fn step_of(&self, effect: &str) -> Option<&Step> {
        self.steps
            .iter()
            .find(|s| s.accepted.as_deref() == Some(effect))
    }
}

impl std::fmt::Debug for Discovery {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Discovery")
            .field("base", &self.base)
            .field("effects", &self.effects)
            .field("noise_floor", &self.noise_floor)
            .field("gap_before", &self.gap_before)
            .field("gap_after", &self.gap_after)
            .field("final_model_name", &self.final_model_name)
            .field("final_params", &self.final_params)
            .field("notes", &self.notes)
            .finish_non_exhaustive()
    }
}
