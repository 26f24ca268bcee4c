//! `discovery.json` of `stf-lab discover`: the effects named, the gap before and after, every
//! step's evidence, the final model (with its experiment entry) and the values that redraw
//! `discovered.csv`; at trajectory level also the oscillator refitted with the models.

use std::collections::BTreeMap;

use serde::Serialize;
use stf_core::data::estimate::LinearEstimate;
use stf_core::discovery::{Discovery, GapLocation, Step, TrajectoryPart};
use stf_core::fit::{FittedParam, NoiseFloor};
use stf_core::numerics::derivative::{noise_estimate, NoiseEstimate};
use stf_core::numerics::reconstruct::DriveReport;
use stf_core::physics::oscillator_params::OscillatorParams;

use super::models_entry::SystemEntry;
use super::{errors_by_name, values_by_name};
use crate::discovery_curves::FittedCurves;
use crate::experiment::Experiment;
use crate::fitting::FitData;
use crate::validation::DiscoveryScore;
use crate::verdict::DiscoverVerdict;

/// The whole of `discovery.json`.
#[derive(Serialize)]
pub struct DiscoveryJson<'a> {
    /// The experiment file, as given.
    pub experiment: String,
    /// The record discovered on (its path).
    pub record: &'a str,
    /// How the measured drive was rebuilt (null for free vibration).
    pub drive: &'a Option<DriveReport>,
    /// The noise of the signal fitted (N or m) and how it was estimated.
    pub noise_estimate: NoiseEstimate,
    /// The base model as `[discover] base` names it (its terms joined by ` + `).
    pub base: String,
    /// The effects named, in the order added (docs/ARCHITECTURE.md §5).
    pub effects: &'a [String],
    /// The base's held-out RMS error, in `gap_unit`.
    pub gap_before: f64,
    /// The final model's held-out RMS error, in `gap_unit`.
    pub gap_after: f64,
    /// The RMS error noise alone leaves, in `gap_unit`.
    pub noise_floor: f64,
    /// The floor's parts: `measured`, `propagated`, `sigma`.
    pub noise_floor_parts: &'a NoiseFloor,
    /// `N` (force level) or `m` (trajectory level; `V` for x in volts).
    pub gap_unit: &'static str,
    /// Held-out cycles every step was scored on.
    pub holdout_cycles: usize,
    /// Where the base's error lies (regimes, parts of the cycle).
    pub where_before: &'a GapLocation,
    /// Where the final model's error lies.
    pub where_after: &'a GapLocation,
    /// Each step: every candidate's scores and the verdict.
    pub steps: &'a [Step],
    /// The final model, its values and its experiment entry.
    pub final_model: FinalModelJson<'a>,
    /// The values that redraw `discovered.csv`.
    pub fitted: FittedCurves,
    /// The record's plausibility warnings, then discovery's notes.
    pub notes: Vec<&'a String>,
    /// The oscillator side of a trajectory-level discovery (absent at force level).
    #[serde(flatten)]
    pub trajectory: Option<TrajectoryJson<'a>>,
    /// The base and final model on the `[validate]` record (absent without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub validation: Option<&'a DiscoveryScore>,
    /// What was named and the share of the excess it explains; the report's opening paragraph.
    pub verdict: Option<DiscoverVerdict>,
}

/// The keys only a trajectory-level discovery has.
#[derive(Serialize)]
pub struct TrajectoryJson<'a> {
    /// The linear oscillator taken from the record, when no `[system]` was given.
    pub system_estimate: Option<LinearEstimate>,
    /// Always `trajectory`.
    pub level: &'static str,
    /// The base's mean squared displacement error S, mm².
    pub s_before_mm2: f64,
    /// The final model's S, mm².
    pub s_after_mm2: f64,
    /// The oscillator parameters refitted with every model.
    pub refitted: &'a [String],
    /// The oscillator fitted with the base.
    pub system_before: OscillatorParams,
    /// The oscillator fitted with the final model.
    pub system: OscillatorParams,
    /// Wall time of the discovery, s.
    pub wall_seconds: f64,
}

/// The final model.
#[derive(Serialize)]
pub struct FinalModelJson<'a> {
    /// `a + b + …`.
    pub name: &'a str,
    /// The final force as an equation, values rounded to their standard errors
    /// (`F_STF = 4.01·|v|^1.501·sgn v + 19 987·x³`); null if a model cannot write it.
    pub equation: Option<String>,
    /// The model's fitted values by name (SI units; no offsets or initial state).
    pub params: BTreeMap<String, f64>,
    /// Standard errors of every fitted value by name; null where not determined.
    pub std_errors: BTreeMap<String, f64>,
    /// Every value of the final fit by name, SI units: the model's, an offset, and at
    /// trajectory level the refitted oscillator and initial state (`x0`, `v0`) — the values
    /// `std_errors` belong to.
    pub values: BTreeMap<String, f64>,
    /// The model as a `[[models]]` entry (TOML).
    pub experiment_entry: String,
    /// The refitted oscillator (trajectory level; absent at force level).
    #[serde(flatten)]
    pub system: Option<FinalSystemJson>,
}

/// The refitted oscillator of the final model.
#[derive(Serialize)]
pub struct FinalSystemJson {
    /// The refitted parameters by name, SI units (key `system`).
    #[serde(flatten)]
    pub refitted: SystemEntry,
    /// The same as a `[system]` table (TOML).
    pub system_entry: String,
}

impl<'a> DiscoveryJson<'a> {
    /// The document of the discovery `found` of `exp` on `data` (`score`: on the `[validate]`
    /// record): `model_params` are the final model's own values, `experiment_entry` their
    /// `[[models]]` entry, `fitted` the curves' values.
    pub fn new(
        (exp, data): (&'a Experiment, &'a FitData),
        (found, score): (&'a Discovery, Option<&'a DiscoveryScore>),
        model_params: &[&FittedParam],
        experiment_entry: String,
        fitted: FittedCurves,
    ) -> Self {
        DiscoveryJson {
            experiment: exp.path.display().to_string(),
            record: &data.record.source,
            drive: &data.kinematics.drive,
            noise_estimate: noise_estimate(data.target()),
            base: exp
                .discover
                .as_ref()
                .map_or_else(|| found.base.clone(), |d| d.base_text()),
            effects: &found.effects,
            gap_before: found.gap_before,
            gap_after: found.gap_after,
            noise_floor: found.noise_floor,
            noise_floor_parts: &found.noise_floor_parts,
            gap_unit: data.units.force_si,
            holdout_cycles: found.holdout_cycles,
            where_before: &found.where_before,
            where_after: &found.where_after,
            steps: &found.steps,
            final_model: FinalModelJson {
                name: &found.final_model_name,
                equation: crate::equation::force_equation(&*found.final_model, &found.final_params),
                params: values_by_name(model_params.iter().copied()),
                std_errors: errors_by_name(&found.final_params, |p| p.std_error),
                values: errors_by_name(&found.final_params, |p| p.value),
                experiment_entry,
                system: None,
            },
            fitted,
            notes: data.record_warnings.iter().chain(&found.notes).collect(),
            trajectory: None,
            validation: score,
            verdict: None,
        }
    }

    /// The same at trajectory level: `tf` refitted `names` of the oscillator (`system`) in
    /// `wall` seconds.
    pub fn with_trajectory(
        mut self,
        tf: &'a TrajectoryPart,
        names: &'a [String],
        system: FinalSystemJson,
        wall: f64,
        system_estimate: Option<LinearEstimate>,
        x_unit: &'static str,
    ) -> Self {
        self.gap_unit = x_unit;
        self.final_model.system = Some(system);
        self.trajectory = Some(TrajectoryJson {
            system_estimate,
            level: "trajectory",
            s_before_mm2: tf.s_before_mm2,
            s_after_mm2: tf.s_after_mm2,
            refitted: names,
            system_before: tf.system_before,
            system: tf.system_after,
            wall_seconds: wall,
        });
        self
    }
}
