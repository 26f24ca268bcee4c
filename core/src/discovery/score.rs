//! The evidence for one candidate at one step, and one step of the search.

use serde::Serialize;

use crate::fit::{FittedParam, NoiseFloor};

/// How a candidate added to the current model scored.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CandidateScore {
    /// The effect's name.
    pub name: String,
    /// RMS residual on the held-out cycles of the sum fitted on the others, N.
    pub holdout_rms: f64,
    /// RMS residual on the training samples, N.
    pub train_rms: f64,
    /// AIC of the fit on the training samples.
    pub aic: f64,
    /// BIC of the fit on the training samples.
    pub bic: f64,
    /// AIC minus the current model's (negative: better).
    pub delta_aic: f64,
    /// BIC minus the current model's (negative: better).
    pub delta_bic: f64,
    /// Fall of the held-out RMS from the current model's, N.
    pub holdout_gain: f64,
    /// Paired z of the held-out gain over independent units: blocks of held-out samples
    /// (force level) or held-out cycles (trajectory level); see [`super::acceptance`].
    pub gain_z: f64,
    /// The units `gain_z` is over: its effective sample size.
    pub effective_n: usize,
    /// Share of the base model's held-out gap (mean square above the noise floor) that this
    /// candidate removes at this step: (MSE_current − MSE_candidate) / (MSE_base − σ²).
    pub explained_fraction: f64,
    /// Share of the current model's held-out excess over its noise floor that this candidate
    /// removes: (MSE_current − MSE_candidate) / (MSE_current − σ²), the excess counted as at
    /// least what the held-out units resolve; must reach `min_explained`.
    pub explained_share: f64,
    /// The candidate's own parameters as fitted on the training samples.
    pub params: Vec<FittedParam>,
    /// Whether the candidate passed the acceptance rule.
    pub significant: bool,
    /// Why the fit failed, if it did (the candidate then scores nothing).
    pub failure: Option<String>,
    /// Evaluations of the model in the fit.
    pub evaluations: u64,
    /// Wall time of the fit, s.
    pub wall_seconds: f64,
}

/// One round: every candidate tried on the current model, and what was done.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Step {
    /// The model the candidates were added to (`power_law + viscous`).
    pub current: String,
    /// The current model's held-out RMS, N.
    pub current_holdout_rms: f64,
    /// The units of the paired test: the effective sample size (held-out blocks at force
    /// level, held-out cycles at trajectory level).
    pub effective_n: usize,
    /// The length of the force-level test's blocks, samples (`None`: whole cycles).
    pub block_samples: Option<usize>,
    /// The current model's noise floor and its parts: the measured signal's own noise and
    /// the kinematics' noise propagated through the model (force level).
    pub floor: NoiseFloor,
    /// Every candidate's score, best held-out RMS first.
    pub candidates: Vec<CandidateScore>,
    /// The effect added at this step, if any.
    pub accepted: Option<String>,
    /// Significant candidates whose held-out RMS is within the margin of the accepted one:
    /// they explain the data equally well.
    pub tie_with: Vec<String>,
    /// One line saying what was decided and why.
    pub verdict: String,
}
