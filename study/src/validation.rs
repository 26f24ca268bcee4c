//! Validation on a second record (`[validate]`): estimate on one measurement, validate on
//! another. The record is read with the `[data]` mapping of the first and checked — it must
//! exist and hold what the fits need (`f_stf` at force level, the drive φ / ω or `u` at
//! trajectory level) — before any fit starts ([`load`]).
//!
//! `fit` scores every fitted model on it with its fitted parameters ([`score_fits`]): at force
//! level the force predicted from the record's kinematics against its `f_stf` (N), at
//! trajectory level the fitted oscillator and model driven by the record's drive against its
//! `x` (m), from its own initial state (fitted on it when the fit fits `x0`, `v0`, else its
//! estimate), per regime on the rotor rig. `discover` scores its base and final models
//! ([`score_discovery`]). The scoring itself is core's
//! (`stf_core::fit::Validation`).

use std::sync::Arc;

use anyhow::Result;
use rayon::prelude::*;
use serde::Serialize;
use stf_core::data::force_data::ForceData;
use stf_core::data::kinematics::Kinematics;
use stf_core::discovery::{Discovery, DiscoveryValidation};
use stf_core::fit::TrajectoryFit;
use stf_core::physics::excitation::Excitation;
use stf_core::regimes::{classify, rms_by_regime, Cycle, Regime};

use crate::digits::shown;
use crate::experiment::{Experiment, FitLevel, ValidateSpec};
use crate::fitting::{cycles_of, read_record, FitData, ModelFit, Predictor};

/// The second record, ready to score models on.
pub struct ValidationRecord {
    /// Where it came from.
    pub spec: ValidateSpec,
    /// The record (cut to its window) and its kinematics; the level is the fits'.
    pub data: FitData,
    /// Its drive, for simulations.
    pub excitation: Arc<Excitation>,
    /// Its rotor cycles and their regimes (the rotor rig only).
    pub regimes: Option<(Vec<Cycle>, Vec<Regime>)>,
}

impl ValidationRecord {
    /// The unit of the errors: N at force level, m at trajectory level.
    pub fn unit(&self) -> &'static str {
        self.data.si_unit()
    }
}

/// Read and check the experiment's `[validate]` record (none without the section) for fits
/// at the level of `estimation`, the record they are fitted to.
pub fn load(exp: &Experiment, estimation: &FitData) -> Result<Option<ValidationRecord>> {
    let Some(spec) = &exp.validate else {
        return Ok(None);
    };
    let key = "validate.file";
    if let Some(problem) = stf_core::data::bounded::record_path_problem(&spec.file) {
        return Err(spec.error(key, problem));
    }
    let mut record = read_record(exp, &spec.file).map_err(|e| spec.error(key, format!("{e:#}")))?;
    let record_warnings = crate::plausibility::check(exp, &spec.file, &record)
        .map_err(|e| spec.error(key, format!("{e:#}")))?;
    check_columns(exp, spec, &record, estimation)?;
    if let Some((t0, t1)) = spec.window {
        let span = crate::digits::time_span(&record.t);
        record = record.slice_time(t0, t1);
        if record.len() < 10 {
            let msg = format!(
                "[{}, {}] keeps {} samples of {}, whose times run {span}: give a window of at \
                 least 10 samples within them",
                shown(t0),
                shown(t1),
                record.len(),
                spec.given
            );
            return Err(spec.error("validate.window", msg));
        }
    }
    let kinematics = Kinematics::from_record(&record, &exp.kinematics)
        .map_err(|e| spec.error(key, crate::fitting::kinematics_error(&e, &spec.given)))?;
    let data = FitData {
        record,
        kinematics,
        level: estimation.level,
        system_estimate: None,
        record_warnings,
        units: crate::shown_units::ShownUnits::of(&exp.data_layout, estimation.level),
        v_measured: false,
        channels: crate::channels::Channels::none(),
    };
    Ok(Some(ValidationRecord {
        excitation: Arc::new(data.kinematics.excitation()),
        regimes: regimes_of(exp, &data),
        spec: spec.clone(),
        data,
    }))
}

/// The columns the fits need in the validation record: `f_stf` at force level; at trajectory
/// level the drive the estimation record has (φ or ω of a rotor, or a force `u`).
fn check_columns(
    exp: &Experiment,
    spec: &ValidateSpec,
    record: &stf_core::data::record::Record,
    estimation: &FitData,
) -> Result<()> {
    let column = |signal: &str| {
        let channel = stf_core::data::record::Signal::from_name(signal)
            .map(|s| exp.data_layout.channel(s).column.clone());
        match channel {
            Some(stf_core::data::record::Column::Name(n)) if n != signal => {
                format!("`{signal}` (`{n}`)")
            }
            Some(stf_core::data::record::Column::Number(i)) => format!("`{signal}` (column {i})"),
            _ => format!("`{signal}`"),
        }
    };
    let lacks = |what: String, why: &str| {
        let msg = format!("{} has no {what} column, which {why}", spec.given);
        Err(spec.error("validate.file", msg))
    };
    if estimation.level == FitLevel::Force && record.f_stf.is_none() {
        return lacks(column("f_stf"), "force-level fits are scored against");
    }
    if estimation.level == FitLevel::Trajectory {
        let k = &estimation.kinematics;
        if (k.phi.is_some() || k.omega.is_some()) && record.phi.is_none() && record.omega.is_none()
        {
            let what = format!("{} or {}", column("phi"), column("omega"));
            return lacks(what, "drives the simulations of a rotor rig");
        }
        if k.phi.is_none() && k.omega.is_none() && k.u.is_some() && record.u.is_none() {
            return lacks(column("u"), "drives the simulations of a shaker rig");
        }
    }
    Ok(())
}

/// The rotor cycles of the record and their regimes, classified on its measured `f_stf` or,
/// without one, on the force recovered from its kinematics; `None` without a rotor or when
/// the cycles cannot be classified.
fn regimes_of(exp: &Experiment, data: &FitData) -> Option<(Vec<Cycle>, Vec<Regime>)> {
    let k = &data.kinematics;
    if k.phi.is_none() && k.omega.is_none() {
        return None;
    }
    let cycles = cycles_of(data).ok()?;
    let recovered;
    let f = match data.record.f_stf.as_deref() {
        Some(f) => f,
        None => {
            recovered = k.recovered_force(&exp.system);
            &recovered
        }
    };
    let sig = ForceData {
        t: &k.t,
        x: &k.x,
        v: &k.v,
        a: &k.a,
        f,
    };
    let c = classify(&sig, cycles, &exp.regimes).ok()?;
    Some((c.cycles, c.labels))
}

pub use crate::fitting::ModelValidation;

/// Score one fitted model on the validation record with its fitted values.
fn score_fit(fit: &ModelFit, rec: &ValidationRecord) -> ModelValidation {
    let follows = fit.configured.as_ref().map_or(&[][..], |c| &c.channels[..]);
    let scored = match &fit.predictor {
        _ if !follows.is_empty() => Err(stf_core::fit::FitError::BadData(format!(
            "it follows the record's channel(s) {}, which a model reads from the record it \
             was fitted on: scoring it on a second record is not supported yet",
            follows.join(", ")
        ))),
        Predictor::Force(f) => f.validate(&rec.data.force_data(), &fit.values),
        Predictor::Trajectory(f) => {
            let (x0, v0) = rec.data.kinematics.initial_state();
            let on_record = f.clone().excitation(rec.excitation.clone()).initial(x0, v0);
            on_record.validate(&rec.data.trajectory_data(), &fit.values)
        }
    };
    let per_regime = match (&scored, &rec.regimes) {
        (Ok(s), Some((cycles, labels))) => {
            rms_by_regime(rec.data.target(), &s.predicted, cycles, labels).ok()
        }
        _ => None,
    };
    ModelValidation {
        file: rec.spec.given.clone(),
        unit: rec.unit(),
        error: scored
            .as_ref()
            .err()
            .map(|e| format!("scoring `{}`: {e}", fit.label)),
        score: scored.ok(),
        per_regime,
    }
}

/// Score every fitted model on the validation record, in parallel.
pub fn score_fits(fits: &mut [ModelFit], rec: &ValidationRecord) {
    fits.par_iter_mut().for_each(|f| {
        f.validation = Some(score_fit(f, rec));
    });
}

/// A discovery's base and final models on the validation record (discovery.json's
/// `validation`; errors in N at force level, m at trajectory level).
#[derive(Clone, Debug, Serialize)]
pub struct DiscoveryScore {
    /// The record, as the experiment names it.
    pub file: String,
    /// Unit of the errors.
    pub unit: &'static str,
    /// RMS error of the base model as fitted (null if it could not be scored).
    pub rms_before: Option<f64>,
    /// RMS error of the final model as fitted.
    pub rms_after: Option<f64>,
    /// The same over the RMS of the measured signal.
    pub normalised_before: Option<f64>,
    /// The same for the final model.
    pub normalised_after: Option<f64>,
    /// RMS of the measured signal.
    pub measured_rms: Option<f64>,
    /// Samples scored.
    pub samples: usize,
    /// Whether the initial state was fitted to the record (trajectory level only).
    pub initial_fitted: Option<bool>,
    /// The record's own offset (`f_off` N, `x_off` m) as fitted on it with the final model,
    /// if the discovery fitted one: an offset belongs to the sensor, so it is fitted again on
    /// the record, every model value held.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset: Option<f64>,
    /// Whether that offset (with either model) ended at or is held by a bound (± twice the
    /// record's largest |value|): the errors are then biased.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub offset_on_bound: bool,
    /// Why the models could not be scored, if they could not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The final model's prediction at every sample (not serialized).
    #[serde(skip)]
    pub predicted_after: Vec<f64>,
}

impl DiscoveryScore {
    fn of<E: std::fmt::Display>(
        rec: &ValidationRecord,
        scored: Result<DiscoveryValidation, E>,
    ) -> Self {
        let finite = |v: f64| v.is_finite().then_some(v);
        let (before, after, error) = match scored {
            Ok(v) => (Some(v.before), Some(v.after), None),
            Err(e) => (None, None, Some(e.to_string())),
        };
        DiscoveryScore {
            file: rec.spec.given.clone(),
            unit: rec.unit(),
            rms_before: before.as_ref().map(|b| b.rms),
            rms_after: after.as_ref().map(|a| a.rms),
            normalised_before: before.as_ref().and_then(|b| finite(b.normalised)),
            normalised_after: after.as_ref().and_then(|a| finite(a.normalised)),
            measured_rms: after.as_ref().map(|a| a.measured_rms),
            samples: rec.data.record.len(),
            initial_fitted: (rec.data.level == FitLevel::Trajectory)
                .then(|| after.as_ref().is_some_and(|a| a.initial_fitted)),
            offset: after.as_ref().and_then(|a| a.offset),
            offset_on_bound: before.as_ref().is_some_and(|b| b.offset_on_bound)
                || after.as_ref().is_some_and(|a| a.offset_on_bound),
            error,
            predicted_after: after.map(|a| a.predicted).unwrap_or_default(),
        }
    }

    /// `file: rms a → b unit (normalised …)`, the score in words (`scale` to the shown unit).
    pub fn summary(&self, unit: &str, scale: f64) -> String {
        match (self.rms_before, self.rms_after) {
            (Some(b), Some(a)) => format!(
                "validation on {} ({} samples): RMS {:.4} → {:.4} {unit} ({:.3} → {:.3} of the \
                 measured RMS)",
                self.file,
                self.samples,
                b * scale,
                a * scale,
                self.normalised_before.unwrap_or(f64::NAN),
                self.normalised_after.unwrap_or(f64::NAN)
            ),
            _ => format!(
                "validation on {}: not scored ({})",
                self.file,
                self.error.as_deref().unwrap_or("unknown")
            ),
        }
    }
}

/// Score a discovery's base and final models on the validation record: along its
/// kinematics (force level) or simulated with its drive and the experiment's integrator
/// (trajectory level).
pub fn score_discovery(
    exp: &Experiment,
    found: &Discovery,
    rec: &ValidationRecord,
) -> DiscoveryScore {
    let scored = match &found.trajectory {
        None => found.validate(&rec.data.force_data()),
        Some(_) => {
            let (x0, v0) = rec.data.kinematics.initial_state();
            let on = TrajectoryFit::new(exp.system, rec.excitation.clone())
                .sim_settings(exp.integrator.clone())
                .initial(x0, v0);
            found.validate_trajectory(&on, &rec.data.trajectory_data())
        }
    };
    DiscoveryScore::of(rec, scored)
}
