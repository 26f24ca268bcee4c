//! `fit.json` of an `[[identify]]` experiment: the oscillator identified stage by stage
//! against each stage's record of displacement, and the result as the one model `none`, so
//! that tools reading `models[].params` / `rms` of a plain fit read it too.

use serde::Serialize;
use stf_core::fit::StatedWarning;
use stf_core::physics::oscillator_params::{OscParam, OscillatorParams};

use super::fit_json::ResultJson;
use crate::experiment::StageSpec;
use crate::identify::StageOutcome;

/// The whole of the identification's `fit.json`.
#[derive(Serialize)]
pub struct IdentificationJson<'a> {
    /// The experiment file, as given.
    pub experiment: String,
    /// Always `trajectory`.
    pub level: &'static str,
    /// Each stage, in order.
    pub stages: Vec<StageJson<'a>>,
    /// The oscillator after the last stage.
    pub system: OscillatorParams,
    /// One entry, `none`: the identified oscillator.
    pub models: [IdentifiedJson<'a>; 1],
    /// The report's opening paragraph, from `system` and each stage's S(μ) and floor.
    pub verdict: String,
    /// The units of the values above on the stages' records.
    pub units: IdentificationUnits,
}

/// The units of an identification's values, the records' own: x in m (or V for x in volts),
/// S(μ) and its floor in mm² (or mV²), each parameter of `system` in its unit with lengths
/// and forces in the records' units.
#[derive(Serialize)]
pub struct IdentificationUnits {
    /// Displacements and the RMS residual (`rms`, `x0`).
    pub x: &'static str,
    /// S(μ) and its floor (`s_mm2`, `floor_mm2`).
    pub s_mm2: &'static str,
    /// Each oscillator parameter's unit, by name.
    pub system: std::collections::BTreeMap<String, String>,
}

impl IdentificationUnits {
    /// The units on records shown in `units`.
    pub fn of(units: &crate::shown_units::ShownUnits) -> IdentificationUnits {
        let system = OscParam::ALL
            .into_iter()
            .map(|p| {
                let unit = crate::param_units::in_record_units(p.unit(), units);
                (p.to_string(), unit)
            })
            .collect();
        IdentificationUnits {
            x: units.x_si,
            s_mm2: units.x_squared,
            system,
        }
    }
}

impl<'a> IdentificationJson<'a> {
    /// The document of the stages `specs` that came out as `outcomes` and ended with
    /// `system`, on records shown in `units`.
    pub fn new(
        experiment: &std::path::Path,
        specs: &[StageSpec],
        outcomes: &'a [StageOutcome],
        system: OscillatorParams,
        units: &crate::shown_units::ShownUnits,
    ) -> Self {
        let warnings = outcomes
            .iter()
            .enumerate()
            .flat_map(|(i, s)| {
                s.warnings.iter().map(move |w| StageWarning {
                    stage: i + 1,
                    warning: w.stated(),
                })
            })
            .collect();
        let stages = specs.iter().zip(outcomes).map(|(spec, o)| StageJson {
            record: &o.record,
            free: spec.free.iter().map(OscParam::to_string).collect(),
            result: ResultJson::new(&o.result, Some(o.floor), &o.warnings),
            floor_mm2: o.floor_mm2(),
            s_over_floor: o.s_over_floor(),
        });
        IdentificationJson {
            experiment: experiment.display().to_string(),
            level: "trajectory",
            stages: stages.collect(),
            system,
            models: [IdentifiedJson {
                name: "none",
                params: system,
                rms: outcomes.last().map(|s| s.result.rms),
                warnings,
            }],
            verdict: crate::verdict::identify_verdict(outcomes, &system, units),
            units: IdentificationUnits::of(units),
        }
    }
}

/// One identification stage.
#[derive(Serialize)]
pub struct StageJson<'a> {
    /// The stage's record (its path).
    pub record: &'a str,
    /// The oscillator parameters it fits.
    pub free: Vec<String>,
    /// Its values, errors, S(μ) (mm²), residual (m), criteria, position noise floor and
    /// warnings, as every fit states them.
    #[serde(flatten)]
    pub result: ResultJson<'a>,
    /// The position noise floor as a mean square, mm² (S(μ)'s floor).
    pub floor_mm2: f64,
    /// S(μ) over that floor.
    pub s_over_floor: f64,
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
