//! `fit.json` of `stf-lab fit` (models fitted to one record), and the per-model fit that
//! `compare.json` repeats under each model's `fit` (docs/ARCHITECTURE.md §6).

use std::collections::BTreeMap;

use serde::Serialize;
use stf_core::data::estimate::LinearEstimate;
use stf_core::fit::{Convergence, ErrorBlocks, FitResult, FitWarning, NoiseFloor, StatedWarning};
use stf_core::numerics::derivative::{noise_estimate, NoiseEstimate};
use stf_core::numerics::reconstruct::DriveReport;
use stf_core::physics::oscillator_params::OscillatorParams;

use super::{errors_by_name, values_by_name};
use crate::experiment::FitLevel;
use crate::fitting::{FitData, ModelFit};
use crate::validation::ModelValidation;
use crate::verdict::FitVerdict;

/// The whole of `fit.json`.
#[derive(Serialize)]
pub struct FitJson<'a> {
    /// The experiment file, as given.
    pub experiment: String,
    /// The record fitted (its path).
    pub record: &'a str,
    /// `force` (against `f_stf`) or `trajectory` (against `x`).
    pub level: &'static str,
    /// Samples fitted (after the time window).
    pub samples: usize,
    /// The polynomial filter v and a were derived with.
    pub motion_filter: MotionFilter,
    /// How the measured drive was rebuilt (null for free vibration).
    pub drive: &'a Option<DriveReport>,
    /// The noise of the fitted signal (N or m) and how it was estimated.
    pub noise_estimate: NoiseEstimate,
    /// The linear oscillator taken from the record, when no `[system]` was given.
    pub system_estimate: Option<LinearEstimate>,
    /// One entry per model, in the experiment's order.
    pub models: Vec<ModelFitJson<'a>>,
    /// The best model, how far the others are behind, and the report's opening paragraph.
    pub verdict: FitVerdict,
}

impl<'a> FitJson<'a> {
    /// `fit.json` of `fits` on `data`.
    pub fn new(experiment: &std::path::Path, data: &'a FitData, fits: &'a [ModelFit]) -> Self {
        let filter = &data.kinematics.motion_filter;
        FitJson {
            experiment: experiment.display().to_string(),
            record: &data.record.source,
            level: data.level.name(),
            samples: data.record.len(),
            motion_filter: MotionFilter {
                order: filter.order(),
                window: filter.window(),
            },
            drive: &data.kinematics.drive,
            noise_estimate: noise_estimate(data.target()),
            system_estimate: data.system_estimate,
            models: fits.iter().map(|f| ModelFitJson::new(f, data)).collect(),
            verdict: FitVerdict::new(fits, data.shown()),
        }
    }
}

/// The sliding polynomial filter of the kinematics.
#[derive(Serialize)]
pub struct MotionFilter {
    /// Polynomial order.
    pub order: usize,
    /// Window, samples.
    pub window: usize,
}

/// One fitted model.
#[derive(Serialize)]
pub struct ModelFitJson<'a> {
    /// The model's name (`none` for the bare oscillator).
    pub name: String,
    /// Its label, unique in the experiment.
    pub label: &'a str,
    /// `force` or `trajectory`.
    pub level: &'static str,
    /// The fitted force as an equation, values rounded to their standard errors
    /// (`F_STF = 4.07·|v|^1.51·sgn v`); null for the bare oscillator.
    pub equation: Option<String>,
    /// The values, errors, residual, criteria and warnings, as every fit states them.
    #[serde(flatten)]
    pub result: ResultJson<'a>,
    /// Standard errors as if the residuals were independent, by name; null where unknown.
    pub naive_std_errors: BTreeMap<String, f64>,
    /// The blocks the robust errors were computed over.
    pub error_blocks: Option<ErrorBlocks>,
    /// Names of the parameters held at their values.
    pub fixed: Vec<&'a str>,
    /// `N` (force level) or `m` (trajectory level; `V` for x in volts): the unit of `rms`.
    pub rms_unit: &'static str,
    /// Each parameter's unit by name, as `params.csv` gives it (SI, with lengths and forces
    /// in the record's own units: V on a record in volts).
    pub param_units: BTreeMap<String, String>,
    /// Samples fitted.
    pub n_points: usize,
    /// Free parameters.
    pub n_free: usize,
    /// Evaluations that failed (a simulation that did not finish).
    pub failures: u64,
    /// The oscillator after the fit (trajectory level; null at force level).
    pub system: Option<OscillatorParams>,
    /// Correlation matrix of the free parameters; null where not finite.
    pub correlation: &'a [Vec<f64>],
    /// The error on the `[validate]` record (absent without one).
    #[serde(flatten)]
    pub validation: Option<ValidationJson<'a>>,
}

/// A model's error on the `[validate]` record, beside its fit.
#[derive(Serialize)]
pub struct ValidationJson<'a> {
    /// The RMS error on the second record (unit of `validation.unit`); null if not scored.
    pub validation_rms: Option<f64>,
    /// The whole score: `file`, `unit`, `rms`, `measured_rms`, `normalised`, … .
    pub validation: &'a ModelValidation,
}

impl<'a> ModelFitJson<'a> {
    /// The JSON of `fit` on `data`.
    pub fn new(fit: &'a ModelFit, data: &FitData) -> Self {
        let (r, level) = (&fit.result, data.level);
        ModelFitJson {
            name: fit.name(),
            label: &fit.label,
            level: level.name(),
            equation: fit.equation(),
            result: ResultJson::new(r, fit.floor, &fit.warnings),
            naive_std_errors: errors_by_name(&r.params, |p| p.naive_std_error),
            error_blocks: r.error_blocks,
            fixed: r
                .params
                .iter()
                .filter(|p| p.fixed)
                .map(|p| p.name.as_str())
                .collect(),
            rms_unit: data.si_unit(),
            param_units: crate::param_table::rows_of_fits(std::slice::from_ref(fit), &data.units)
                .into_iter()
                .map(|row| (row.parameter, row.unit))
                .collect(),
            n_points: r.n_points,
            n_free: r.n_free,
            failures: r.failures,
            system: (level == FitLevel::Trajectory).then_some(fit.system),
            correlation: &r.correlation,
            validation: fit.validation.as_ref().map(|v| ValidationJson {
                validation_rms: v.rms(),
                validation: v,
            }),
        }
    }
}

/// What every fit states of its result, in `fit.json`'s models and an identification's
/// stages.
#[derive(Serialize)]
pub struct ResultJson<'a> {
    /// Fitted (or held) values by parameter name, SI units.
    pub params: BTreeMap<String, f64>,
    /// Block-robust standard errors by name, SI units; null where not determined.
    pub std_errors: BTreeMap<String, f64>,
    /// RMS residual (N at force level, m at trajectory level).
    pub rms: f64,
    /// Mean squared displacement error, mm² (trajectory level).
    pub s_mm2: Option<f64>,
    /// Akaike information criterion; null if not finite.
    pub aic: f64,
    /// Bayesian information criterion; null if not finite.
    pub bic: f64,
    /// Model evaluations (simulations at trajectory level).
    pub evaluations: u64,
    /// Whether the optimiser converged.
    pub converged: bool,
    /// How it ended.
    pub convergence: &'a Convergence,
    /// The record's noise floor for this fit (same unit as `rms`).
    pub noise_floor: Option<NoiseFloor>,
    /// Why the fit is not to be trusted as it stands (`kind`, `message`, data).
    pub warnings: Vec<StatedWarning<'a>>,
}

impl<'a> ResultJson<'a> {
    /// The JSON of `r`, with its noise floor and warnings.
    pub fn new(r: &'a FitResult, floor: Option<NoiseFloor>, warnings: &'a [FitWarning]) -> Self {
        ResultJson {
            params: values_by_name(&r.params),
            std_errors: errors_by_name(&r.params, |p| p.std_error),
            rms: r.rms,
            s_mm2: r.s_mm2,
            aic: r.aic,
            bic: r.bic,
            evaluations: r.evaluations,
            converged: r.convergence.converged(),
            convergence: &r.convergence,
            noise_floor: floor,
            warnings: warnings.iter().map(FitWarning::stated).collect(),
        }
    }
}
impl crate::fit::Fitted {
    /// `fit.json` of the experiment `exp`.
    pub fn json<'a>(&'a self, exp: &'a crate::experiment::Experiment) -> FitJson<'a> {
        FitJson::new(&exp.path, &self.data, &self.fits)
    }
}
