//! The source study's identification (`[[identify]]` stages): each stage fits the
//! oscillator's parameters against a record's displacement, starting from the values the
//! earlier stages found (or a stage's preset and `set` values); [`identify`] returns every
//! stage's fit, noise floor, warnings and simulated displacement, and the oscillator found.

use anyhow::{Context, Result};
use stf_core::data::kinematics::Kinematics;
use stf_core::fit::{
    fit_warnings, FitResult, FitWarning, NoiseFloor, ShownIn, TrajectoryData, TrajectoryFit,
};
use stf_core::physics::oscillator_params::{OscParam, OscillatorParams};

use crate::experiment::{Experiment, FitLevel};
use crate::fitting::{oscillator_fit, system_param};
use crate::observer::{fit_message, Observer};
use crate::shown_units::ShownUnits;

impl StageOutcome {
    /// The position noise floor as a mean square, mm² (S(μ)'s floor).
    pub fn floor_mm2(&self) -> f64 {
        (self.floor.sigma * 1e3).powi(2)
    }

    /// S(μ) over its floor: 1 is a fit at the noise.
    pub fn s_over_floor(&self) -> f64 {
        self.result.s_mm2.unwrap_or(f64::NAN) / self.floor_mm2()
    }
}

/// The identification's result: each stage as fitted, and the oscillator they found.
pub struct Identification {
    /// The stages, in order.
    pub stages: Vec<StageOutcome>,
    /// The oscillator after the last stage.
    pub system: OscillatorParams,
}

/// One identification stage as fitted.
pub struct StageOutcome {
    /// The stage's record, as given.
    pub record: String,
    /// Its times, s.
    pub t: Vec<f64>,
    /// Its measured displacement, m.
    pub x: Vec<f64>,
    /// The displacement simulated with the stage's fitted values, m (empty if it failed).
    pub simulated: Vec<f64>,
    /// Its rotor speed, rad/s (a swept record; none for free vibration or a shaker).
    pub omega: Option<Vec<f64>>,
    /// The fit.
    pub result: FitResult,
    /// Its noise floor (the position noise).
    pub floor: NoiseFloor,
    /// Its warnings.
    pub warnings: Vec<FitWarning>,
}

/// The oscillator stage `i` of `exp` starts from: `system` as the earlier stages left it,
/// its preset's values for the parameters no earlier stage found, then its `set` values.
fn stage_start(exp: &Experiment, i: usize, system: &mut OscillatorParams) {
    let stage = &exp.identify[i];
    if let Some(preset) = stage.preset {
        let found: Vec<OscParam> = exp.identify[..i]
            .iter()
            .flat_map(|s| &s.free)
            .copied()
            .collect();
        for param in OscParam::ALL {
            if !found.contains(&param) {
                system[param] = preset[param];
            }
        }
    }
    for &(param, value) in &stage.set {
        system[param] = value;
    }
}

/// The source study's identification: each stage fits the oscillator's parameters against a
/// record's displacement, starting from the previous stage's values.
pub fn identify(exp: &Experiment, progress: &dyn Observer) -> Result<Identification> {
    if let Some(spec) = &exp.validate {
        let msg = "scores the fits of `[[models]]`; `[[identify]]` stages are not scored";
        return Err(spec.error("validate", msg));
    }
    let mut system = exp.system;
    let mut outcomes = Vec::new();
    let units = ShownUnits::of(&exp.data_layout, FitLevel::Trajectory);
    for (i, stage) in exp.identify.iter().enumerate() {
        stage_start(exp, i, &mut system);
        let record = crate::fitting::read_record(exp, &stage.data)?;
        let k = Kinematics::from_record(&record, &exp.kinematics).map_err(|e| {
            let file = stage.data.display().to_string();
            anyhow::anyhow!("{}", crate::fitting::kinematics_error(&e, &file))
        })?;
        let mut fit = oscillator_fit(exp, system, &k).settings(exp.fit.settings.clone());
        let mut free: Vec<_> = stage
            .free
            .iter()
            .map(|&param| system_param(param, &system, &k))
            .collect();
        if exp.fit.fit_initial {
            free.extend(k.initial_state_params());
        }
        fit = free.iter().cloned().fold(fit, TrajectoryFit::free);
        let bar = progress.job(&format!("stage {} of {}", i + 1, exp.identify.len()));
        let observer =
            |p: stf_core::fit::FitProgress| bar.message(&fit_message(&p, units.x, units.scale));
        let data = TrajectoryData {
            t: &record.t,
            x: &record.x,
        };
        let result = fit.fit(&data, Some(&observer)).with_context(|| {
            format!(
                "{}:{}: identification stage {} failed",
                exp.path.display(),
                stage.line,
                i + 1
            )
        })?;
        bar.finish();
        progress.finished(&format!("identification stage {}", i + 1));
        for &param in &stage.free {
            if let Some(v) = result.value(param.name()) {
                system[param] = v;
            }
        }
        let floor =
            NoiseFloor::displacement(k.sigma_x).shown_in(ShownIn::new(units.x, units.scale));
        let warnings = fit_warnings(&result, &free, Some(&floor));
        let values: Vec<f64> = result.params.iter().map(|p| p.value).collect();
        outcomes.push(StageOutcome {
            record: stage.data.display().to_string(),
            simulated: fit.predict(&data, &values).unwrap_or_default(),
            t: record.t.clone(),
            x: record.x.clone(),
            omega: k.omega.clone(),
            result,
            floor,
            warnings,
        });
    }
    Ok(Identification {
        stages: outcomes,
        system,
    })
}
