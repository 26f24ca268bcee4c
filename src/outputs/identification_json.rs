//! `fit.json` of an `[[identify]]` experiment: the oscillator identified stage by stage
//! against each stage's record of displacement, and the result as the one model `none`, so
//! that tools reading `models[].params` / `rms` of a plain fit read it too.

use std::collections::BTreeMap;

use serde::Serialize;
use stf_core::fit::{Convergence, FitResult, FitWarning, NoiseFloor, StatedWarning};
use stf_core::physics::oscillator_params::OscillatorParams;

use super::{errors_by_name, values_by_name};

/// The whole of the identification's `fit.json`.
#[derive(Serialize)]
pub struct IdentificationJson<'a> {
    /// The experiment file, as given.
    pub experiment: String,
    /// Always `trajectory`.
    pub level: &'static str,
    /// Each stage, in order.
    pub stages: &'a [StageJson],
    /// The oscillator after the last stage.
    pub system: OscillatorParams,
    /// One entry, `none`: the identified oscillator.
    pub models: [IdentifiedJson<'a>; 1],
}

impl<'a> IdentificationJson<'a> {
    /// The document of `stages` that ended with `system`.
    pub fn new(
        experiment: &std::path::Path,
        stages: &'a [StageJson],
        system: OscillatorParams,
    ) -> Self {
        let warnings = stages
            .iter()
            .enumerate()
            .flat_map(|(i, s)| {
                s.warnings.iter().map(move |w| StageWarning {
                    stage: i + 1,
                    warning: w.stated(),
                })
            })
            .collect();
        IdentificationJson {
            experiment: experiment.display().to_string(),
            level: "trajectory",
            stages,
            system,
            models: [IdentifiedJson {
                name: "none",
                params: system,
                rms: stages.last().map(|s| s.rms),
                warnings,
            }],
        }
    }
}

/// One identification stage.
#[derive(Serialize)]
pub struct StageJson {
    /// The stage's record (its path).
    pub record: String,
    /// The oscillator parameters it fits.
    pub free: Vec<String>,
    /// Fitted values by name (SI units).
    pub params: BTreeMap<String, f64>,
    /// Standard errors by name (SI units); null where not determined.
    pub std_errors: BTreeMap<String, f64>,
    /// Mean squared displacement error S(μ), mm².
    pub s_mm2: Option<f64>,
    /// RMS displacement residual, m.
    pub rms: f64,
    /// Akaike information criterion; null if not finite.
    pub aic: f64,
    /// Bayesian information criterion; null if not finite.
    pub bic: f64,
    /// Simulations run.
    pub evaluations: u64,
    /// Whether the optimiser converged.
    pub converged: bool,
    /// How it ended.
    pub convergence: Convergence,
    /// The position noise floor, m.
    pub noise_floor: NoiseFloor,
    /// Why the stage is not to be trusted as it stands (`kind`, `message`, data).
    #[serde(serialize_with = "stated")]
    pub warnings: Vec<FitWarning>,
}

impl StageJson {
    /// The stage fitting `free` on `record` to `result`.
    pub fn new(
        record: String,
        free: Vec<String>,
        result: &FitResult,
        noise_floor: NoiseFloor,
        warnings: Vec<FitWarning>,
    ) -> Self {
        StageJson {
            record,
            free,
            params: values_by_name(&result.params),
            std_errors: errors_by_name(&result.params, |p| p.std_error),
            s_mm2: result.s_mm2,
            rms: result.rms,
            aic: result.aic,
            bic: result.bic,
            evaluations: result.evaluations,
            converged: result.convergence.converged(),
            convergence: result.convergence.clone(),
            noise_floor,
            warnings,
        }
    }
}

/// Warnings as stated in JSON: `kind`, `message` and data.
fn stated<S: serde::Serializer>(warnings: &[FitWarning], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(warnings.iter().map(FitWarning::stated))
}

/// A warning of one stage, in the identified model's `warnings`.
#[derive(Serialize)]
pub struct StageWarning<'a> {
    /// The stage, from 1.
    pub stage: usize,
    /// `kind`, `message` and data.
    #[serde(flatten)]
    pub warning: StatedWarning<'a>,
}

/// The identified oscillator as the model `none`.
#[derive(Serialize)]
pub struct IdentifiedJson<'a> {
    /// Always `none`: no STF model.
    pub name: &'static str,
    /// The oscillator's parameters (SI units).
    pub params: OscillatorParams,
    /// The last stage's RMS displacement residual, m; null if not finite.
    pub rms: Option<f64>,
    /// Every stage's warnings, each with its `stage`.
    pub warnings: Vec<StageWarning<'a>>,
}
