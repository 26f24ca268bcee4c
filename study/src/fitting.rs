//! Fitting the models of an experiment to its record: the shared step of `fit`, `compare`
//! and `discover`.
//!
//! The record is read, cut to the experiment's time window, and its kinematics derived
//! once. Each model is then fitted on its own thread (rayon), deterministically, at force level
//! (against `f_stf`, along the kinematics) or trajectory level (against `x`, simulating the
//! oscillator driven as in the record), along one path ([`fit_model`]): the level's fit is
//! built, run, predicted with and given its noise floor by [`Predictor`], the one place that
//! knows the two levels apart.

use std::f64::consts::PI;
use std::sync::Arc;

use anyhow::{anyhow, bail, Context, Result};
use rayon::prelude::*;
use serde::Serialize;
use stf_core::data::estimate::{linear_oscillator, LinearEstimate};
use stf_core::data::force_data::ForceData;
use stf_core::data::kinematics::Kinematics;
use stf_core::data::record::Record;
use stf_core::fit::Validation;
use stf_core::fit::{
    fit_warnings, offset_param, FilterNoise, FitError, FitParam, FitResult, FitWarning, ForceFit,
    NoiseFloor, ShownIn, TrajectoryData, TrajectoryFit, DISPLACEMENT_OFFSET, FORCE_OFFSET,
};
use stf_core::physics::oscillator_params::{OscParam, OscillatorParams};
use stf_core::regimes::{PerRegime, RegimeRms};

use crate::channels::Channels;
use crate::digits::shown;
use crate::experiment::{Experiment, FitLevel};
use crate::model_config::{configure_for, ConfiguredModel};
use crate::observer::{fit_message, jobs_message, Job, Observer};
use crate::rig_words::RigWords;
use crate::shown_units::ShownUnits;
use stf_core::data::record_bounds::DataScales;

/// A record with its kinematics, ready to fit.
pub struct FitData {
    /// The record, cut to the time window.
    pub record: Record,
    /// Its kinematics.
    pub kinematics: Kinematics,
    /// The level fits run at.
    pub level: FitLevel,
    /// The linear oscillator the record shows, where the experiment's oscillator was taken
    /// from it (a trajectory-level fit of a rig driven by `u` with no `[system]`).
    pub system_estimate: Option<LinearEstimate>,
    /// What looks suspicious about the record ([`crate::plausibility`]), already printed.
    pub record_warnings: Vec<String>,
    /// The units the record's motion is shown in (mm, or mV for x in volts).
    pub units: ShownUnits,
    /// Whether v is the record's measured `v` column rather than the derivative filter's.
    pub v_measured: bool,
    /// The measured channels it carries: those the models' laws name and `[data] channels`.
    pub channels: Channels,
}

impl FitData {
    /// The unit errors and gaps are shown in, and the factor from the record's values: N at
    /// force level; at trajectory level the record's own (mm, or mV for x in volts).
    pub fn shown(&self) -> (&'static str, f64) {
        self.units.at_level(self.level)
    }

    /// The words that fit the record's rig: a rotor's cycles and regimes, or periods of the
    /// motion over the whole record.
    pub fn words(&self) -> RigWords {
        RigWords::of(&self.record)
    }

    /// The unit of the fitted signal as recorded: N at force level, m (or V) at trajectory level.
    pub fn si_unit(&self) -> &'static str {
        match self.level {
            FitLevel::Force => self.units.force_si,
            FitLevel::Trajectory => self.units.x_si,
        }
    }

    /// The sizes the models' bounds are widened to ([`stf_core::data::record_bounds`]): the measured
    /// force at force level, the force recovered with the oscillator `system` at trajectory
    /// level, along the record's motion.
    pub fn scales(&self, system: &OscillatorParams) -> DataScales {
        let k = &self.kinematics;
        let force = match (self.level, &self.record.f_stf) {
            (FitLevel::Force, Some(f)) => f.clone(),
            _ => k.recovered_force(system),
        };
        DataScales::of(&force, &k.x, &k.v, &k.a)
    }

    /// The measured signal fits aim at: `f_stf` (force level) or `x` (trajectory level).
    pub fn target(&self) -> &[f64] {
        match self.level {
            FitLevel::Force => self.record.f_stf.as_deref().unwrap_or(&[]),
            FitLevel::Trajectory => &self.record.x,
        }
    }

    /// The trajectory-level data: the measured displacement.
    pub fn trajectory_data(&self) -> TrajectoryData<'_> {
        TrajectoryData {
            t: &self.record.t,
            x: &self.record.x,
        }
    }

    /// The force-level data (f_stf must be present).
    pub fn force_data(&self) -> ForceData<'_> {
        let k = &self.kinematics;
        ForceData::new(
            &k.t,
            &k.x,
            &k.v,
            &k.a,
            self.record.f_stf.as_deref().unwrap_or(&[]),
        )
    }
}

/// Read a record as the experiment's `[data]` layout says (columns, units, offsets, …).
pub fn read_record(exp: &Experiment, file: &std::path::Path) -> Result<Record> {
    Ok(exp.data_layout.read(file)?)
}

/// Read the experiment's record and derive its kinematics. A trajectory-level experiment on
/// a rig driven by a measured force `u` with no `[system]` takes its oscillator from the
/// record: `m`, `c`, `k` of its linear ARX model ([`linear_oscillator`]), no dry friction.
pub fn load_data(exp: &mut Experiment) -> Result<FitData> {
    load_data_at(exp, None)
}

/// [`load_data`] at a level a command asks for (`[discover] level`), else the experiment's.
pub fn load_data_at(exp: &mut Experiment, asked: Option<FitLevel>) -> Result<FitData> {
    let Some(file) = &exp.data_file else {
        bail!("{}: has no [data] file to fit", exp.path.display());
    };
    if let Some(problem) = stf_core::data::bounded::record_path_problem(file) {
        bail!(
            "{}:{}: `data.file`: {problem}",
            exp.path.display(),
            exp.data_line
        );
    }
    let mut record = read_record(exp, file)?;
    let channels = read_channels(exp, file)?;
    let record_warnings = crate::plausibility::check(exp, file, &record)
        .with_context(|| format!("{}:{}: `[data]`", exp.path.display(), exp.data_line))?;
    if let Some((t0, t1)) = exp.data_window {
        let span = crate::digits::time_span(&record.t);
        record = record.slice_time(t0, t1);
        if record.len() < 10 {
            bail!(
                "{}:{}: `data.window` [{}, {}] keeps {} samples of {}, whose times run {span}: \
                 give a window of at least 10 samples within them",
                exp.path.display(),
                exp.data_line,
                shown(t0),
                shown(t1),
                record.len(),
                file.display()
            );
        }
    }
    let mut kinematics = Kinematics::from_record(&record, &exp.kinematics).map_err(|e| {
        anyhow!(
            "{}:{}: `[data]`: {}",
            exp.path.display(),
            exp.data_line,
            kinematics_error(&e, &file.display().to_string())
        )
    })?;
    let level = match asked.or(exp.fit.level) {
        Some(l) => l,
        None if record.f_stf.is_some() && (!exp.models.is_empty() || exp.discover.is_some()) => {
            FitLevel::Force
        }
        None => FitLevel::Trajectory,
    };
    if level == FitLevel::Force && record.f_stf.is_none() {
        bail!(
            "{}: a force-level fit needs an `f_stf` column, which {} lacks",
            exp.path.display(),
            file.display()
        );
    }
    let mut record_warnings = record_warnings;
    let mut v_measured = false;
    if let Some(v) = crate::measured_velocity::read(&exp.data_layout, file, exp.data_window) {
        let name = file.display().to_string();
        let warning = crate::measured_velocity::use_or_warn(&mut kinematics, v, &name);
        v_measured = warning.is_none();
        record_warnings.extend(warning);
    }
    let driven = record.phi.is_some() || record.omega.is_some() || record.u.is_some();
    if level == FitLevel::Trajectory && !driven {
        record_warnings.push(format!(
            "{}: no drive column (`phi`, `omega` or `u`): the trajectory-level fit simulates \
             it as a free vibration",
            file.display()
        ));
    }
    let system_estimate = match (&record.u, level, exp.system_given) {
        (Some(u), FitLevel::Trajectory, false) => {
            let dt = record.sample_step().unwrap_or(f64::NAN);
            let e = linear_oscillator(&record.x, u, dt)
                .with_context(|| format!("estimating the oscillator of {}", file.display()))?;
            exp.system = OscillatorParams {
                m: e.m,
                k: e.k,
                c: e.c,
                t_friction: 0.0,
                delta_t: 0.0,
                f0: 0.0,
                ..OscillatorParams::FORCED
            };
            Some(e)
        }
        _ => None,
    };
    Ok(FitData {
        record,
        kinematics,
        level,
        system_estimate,
        record_warnings,
        units: ShownUnits::of(&exp.data_layout, level),
        v_measured,
        channels,
    })
}

/// The channels of the record `file` that `exp` needs: those its models' laws (and its
/// truth's) name, and `[data] channels`.
pub fn read_channels(exp: &Experiment, file: &std::path::Path) -> Result<Channels> {
    let mut names = exp.data_channels.clone();
    let truth = exp.simulate.iter().flat_map(|s| &s.truth);
    for name in crate::channels::named_by(exp.models.iter().chain(truth)) {
        if !names.contains(&name) {
            names.push(name);
        }
    }
    crate::channels::read(&exp.data_layout, file, exp.data_window, &names)
        .map_err(|e| anyhow!("{}:{}: `[data]`: {e}", exp.path.display(), exp.data_line))
}

/// The terminal line saying where the oscillator came from, if the record gave it.
pub fn estimate_line(data: &FitData) -> Option<String> {
    data.system_estimate.map(|e| {
        format!(
            "oscillator from the record (a linear ARX model, no [system] given): m {:.4e}, \
             c {:.4e}, k {:.4e}; one-step error {:.2} % of x",
            e.m,
            e.c,
            e.k,
            100.0 * e.one_step_error
        )
    })
}

/// The record's rotor cycles (from φ, or ω integrated, or upward crossings of x); a record
/// with fewer than [`MIN_CYCLES`] of them (a positioning stroke) is cut into that many equal
/// stretches instead, so that some can be held out.
pub fn cycles_of(data: &FitData) -> Result<Vec<stf_core::regimes::Cycle>> {
    use stf_core::regimes::{cycles_from_phase, cycles_from_x, phase_from_omega, segments};
    let k = &data.kinematics;
    Ok(match (&k.phi, &k.omega) {
        (Some(phi), _) => cycles_from_phase(&k.t, phi)?,
        (None, Some(w)) => cycles_from_phase(&k.t, &phase_from_omega(&k.t, w)?)?,
        _ => {
            let of_x = cycles_from_x(&k.t, &k.x, 3.0 * k.sigma_x)?;
            let mut cycles = if of_x.len() < MIN_CYCLES {
                segments(&k.t, MIN_CYCLES)
            } else {
                of_x.clone()
            };
            let speeds = match &k.u {
                Some(u) => {
                    let rms = (u.iter().map(|v| v * v).sum::<f64>() / u.len().max(1) as f64).sqrt();
                    cycles_from_x(&k.t, u, 0.1 * rms)?
                }
                None => of_x,
            };
            drive_omega(&k.t, &speeds, &mut cycles);
            cycles
        }
    })
}

/// Give each cycle the ω of the `speeds` cycle (of the measured drive `u`, else of x) around
/// its middle, or the nearest one: equal stretches stand in for too few cycles and x's own
/// crossings beat near resonance, and their 2π/duration read as speeds the drive never
/// reached (ω 10.05 rad/s on a chirp ending at 9.42).
fn drive_omega(
    t: &[f64],
    speeds: &[stf_core::regimes::Cycle],
    cycles: &mut [stf_core::regimes::Cycle],
) {
    for c in cycles.iter_mut() {
        let nearest = speeds.iter().min_by(|a, b| {
            let d = |s: &stf_core::regimes::Cycle| {
                let (lo, hi) = (t[s.start], t[s.end.min(t.len() - 1)]);
                (lo - c.t_mid).max(c.t_mid - hi).max(0.0)
            };
            d(a).total_cmp(&d(b))
        });
        if let Some(s) = nearest {
            c.omega = s.omega;
        }
    }
}

/// The fewest cycles of x a record is scored by; fewer, and equal stretches stand in.
pub const MIN_CYCLES: usize = 32;

/// The fit a model's prediction comes from, to predict again on other data.
#[derive(Clone)]
pub enum Predictor {
    /// A force-level fit: the model's force along a record's kinematics.
    Force(ForceFit),
    /// A trajectory-level fit: the oscillator with the model, simulated.
    Trajectory(TrajectoryFit),
}

/// One fitted model.
pub struct ModelFit {
    /// The model as configured (start values and bounds).
    pub configured: Option<ConfiguredModel>,
    /// The fit.
    pub result: FitResult,
    /// The model's prediction of the target signal with the fitted parameters.
    pub fitted: Vec<f64>,
    /// The oscillator's parameters after the fit (trajectory level; else as given).
    pub system: OscillatorParams,
    /// A label unique within the experiment (the name, numbered if it repeats).
    pub label: String,
    /// The record's noise floor for this fit (none if it could not be estimated).
    pub floor: Option<NoiseFloor>,
    /// Why the result is not to be trusted as it stands (empty: no reason found).
    pub warnings: Vec<FitWarning>,
    /// The fit, to predict with `values` on other data.
    pub predictor: Predictor,
    /// The fitted values in the predictor's order: the model's parameters then the offset
    /// (force level), or the free parameters as listed (trajectory level).
    pub values: Vec<f64>,
    /// The model's error on the `[validate]` record, once scored.
    pub validation: Option<ModelValidation>,
}

impl ModelFit {
    /// The model's name (`none` for the bare oscillator).
    pub fn name(&self) -> String {
        self.configured
            .as_ref()
            .map_or_else(|| "none".to_string(), |c| c.model.name().to_string())
    }

    /// The fitted force as an equation (`F_STF = 4.07·|v|^1.51·sgn v`;
    /// [`crate::equation::force_equation`]); none for the bare oscillator.
    pub fn equation(&self) -> Option<String> {
        let c = self.configured.as_ref()?;
        crate::equation::force_equation(&*c.model, &self.result.params)
    }

    /// The fitted values of the model's parameters, in its order.
    pub fn model_values(&self) -> Vec<f64> {
        self.configured.as_ref().map_or_else(Vec::new, |c| {
            c.params
                .iter()
                .map(|p| self.result.value(&p.name).unwrap_or(p.value))
                .collect()
        })
    }
}

/// A fitted model's error on the validation record (fit.json's `validation`).
#[derive(Clone, Debug, Serialize)]
pub struct ModelValidation {
    /// The record, as the experiment names it.
    pub file: String,
    /// Unit of the errors: N (force level) or m (trajectory level).
    pub unit: &'static str,
    /// `rms`, `measured_rms`, `normalised`, `samples`, `initial`, `initial_fitted`.
    #[serde(flatten)]
    pub score: Option<Validation>,
    /// The same per regime of the record's rotor cycles (none without a rotor).
    pub per_regime: Option<PerRegime<RegimeRms>>,
    /// Why the model could not be scored, if it could not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

impl ModelValidation {
    /// The RMS error, if scored.
    pub fn rms(&self) -> Option<f64> {
        self.score.as_ref().map(|s| s.rms)
    }
}

/// Bounds for an oscillator parameter freed in a trajectory fit: a factor 5 around its
/// start (from 0 when it starts at 0). An offset starts where it is set and may take either
/// sign: `phi_off` within ±π, `f_off` and `u_off` within ± the record's force scale (the
/// largest drive plus the spring's force at the largest |x|).
pub fn system_param(param: OscParam, system: &OscillatorParams, k: &Kinematics) -> FitParam {
    let value = system[param];
    let (min, max, scale) = match param {
        OscParam::PhiOff => (-PI, PI, 0.01),
        OscParam::FOff | OscParam::UOff => {
            let x_max = k.x.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
            let drive_max = k.drive(system).iter().fold(0.0_f64, |m, d| m.max(d.abs()));
            let f = (drive_max + system.k * x_max).max(f64::MIN_POSITIVE);
            (value - f, value + f, 1e-3 * f)
        }
        _ if value > 0.0 => (value / 5.0, value * 5.0, 0.0),
        _ => (0.0, 10.0, 0.0),
    };
    let p = FitParam::new(param.name(), value).bounds(min, max);
    if scale > 0.0 {
        p.scale(scale)
    } else {
        p
    }
}

/// Fit one configured model (or, with `None`, the bare oscillator) to `data`, at its level:
/// the fit (`Predictor::build`), the prediction with the fitted values, the noise floor and
/// the warnings.
///
/// A sum that contains a smaller one (all its parts but the last) never ends worse than the
/// smaller one's optimum: the smaller one is fitted first (so, in turn, its own), and the sum
/// is fitted again from that optimum with the last part's amplitude neutral
/// ([`ConfiguredModel::started_from`]: the smaller model's residual, to within a millionth
/// of the term's default contribution); of the fit from the entry's starts and this one, the lower RMS is
/// kept. (From its defaults alone `viscous + yield + maxwell` was seen to end at 32.4 N on a
/// damper record where `viscous + yield` reached 26.5 N.)
pub fn fit_model(
    exp: &Experiment,
    data: &FitData,
    configured: Option<&ConfiguredModel>,
    progress: &dyn Job,
) -> Result<ModelFit> {
    let fit = fit_from_starts(exp, data, configured, progress)?;
    let Some((c, (base, amp))) = configured.and_then(|c| Some((c, c.base()?))) else {
        return Ok(fit);
    };
    let base_fit = fit_model(exp, data, Some(&base), progress)?;
    let nested = c.started_from(&base_fit.model_values(), amp);
    let from_base = fit_from_starts(exp, data, Some(&nested), progress)?;
    Ok(if from_base.result.rms < fit.result.rms {
        ModelFit {
            configured: Some(c.clone()),
            ..from_base
        }
    } else {
        fit
    })
}

/// [`fit_model`] from the starts `configured` gives, once.
fn fit_from_starts(
    exp: &Experiment,
    data: &FitData,
    configured: Option<&ConfiguredModel>,
    progress: &dyn Job,
) -> Result<ModelFit> {
    let (unit, scale) = data.shown();
    let observer = |p: stf_core::fit::FitProgress| progress.message(&fit_message(&p, unit, scale));
    let label = configured.map_or("none".to_string(), |c| c.model.name().to_string());
    let predictor = Predictor::build(exp, data, configured)?;
    let result = predictor
        .fit(data, &observer)
        .with_context(|| format!("fitting `{label}`"))?;
    let params = predictor.params();
    let values: Vec<f64> = params
        .iter()
        .map(|p| result.value(&p.name).unwrap_or(p.value))
        .collect();
    let fitted = predictor
        .predict(data, &values)
        .with_context(|| format!("predicting with the fitted `{label}`"))?;
    let floor = predictor
        .noise_floor(exp, data, &values)
        .with_context(|| format!("the noise floor of `{label}`"))?;
    let mut system = exp.system;
    if let Predictor::Trajectory(_) = predictor {
        for &param in &exp.fit.system_free {
            if let Some(v) = result.value(param.name()) {
                system[param] = v;
            }
        }
    }
    Ok(ModelFit {
        configured: configured.cloned(),
        warnings: fit_warnings(&result, &params, floor.as_ref()),
        result,
        fitted,
        system,
        label,
        floor,
        predictor,
        values,
        validation: None,
    })
}

/// A progress observer.
type FitObserver<'a> = dyn Fn(stf_core::fit::FitProgress) + Sync + 'a;

impl Predictor {
    /// The fit of `configured` (or the bare oscillator) at `data`'s level: the model's
    /// parameters and the offset `f_off` (force level; a model is needed), or the model's free
    /// parameters, the oscillator's of `[fit] system`, the offset `x_off` and the initial
    /// state (trajectory level, the oscillator as [`oscillator_fit`] builds it).
    fn build(
        exp: &Experiment,
        data: &FitData,
        configured: Option<&ConfiguredModel>,
    ) -> Result<Predictor> {
        if data.level == FitLevel::Force {
            let c = configured.ok_or_else(|| anyhow!("a force-level fit needs a model"))?;
            let k = &data.kinematics;
            let noise = (!data.v_measured).then(|| FilterNoise::new(k.motion_filter, k.sigma_x));
            let fit = ForceFit::new(c.model.clone())
                .settings(exp.fit.settings.clone())
                .filter_noise(noise);
            let mut fit = c.params.iter().cloned().fold(fit, ForceFit::param);
            if exp.fit.offset {
                fit = fit.offset(offset_param(FORCE_OFFSET, data.target(), 0.0));
            }
            return Ok(Predictor::Force(fit));
        }
        let k = &data.kinematics;
        let mut fit = oscillator_fit(exp, exp.system, k).settings(exp.fit.settings.clone());
        let mut free: Vec<FitParam> = Vec::new();
        if let Some(c) = configured {
            fit = fit.model(c.model.clone(), c.values());
            free.extend(c.params.iter().filter(|p| !p.fixed).cloned());
        }
        for &param in &exp.fit.system_free {
            free.push(system_param(param, &exp.system, k));
        }
        if exp.fit.offset {
            free.push(offset_param(DISPLACEMENT_OFFSET, &data.record.x, 0.0));
        }
        if exp.fit.fit_initial {
            free.extend(k.initial_state_params());
        }
        Ok(Predictor::Trajectory(
            free.into_iter().fold(fit, TrajectoryFit::free),
        ))
    }

    /// The parameters fitted (or held), in the order of the fit's values.
    fn params(&self) -> Vec<FitParam> {
        match self {
            Predictor::Force(f) => f.params(),
            Predictor::Trajectory(f) => f.free_params().to_vec(),
        }
    }

    /// Run the fit on `data`'s target signal.
    fn fit(&self, data: &FitData, observer: &FitObserver) -> Result<FitResult, FitError> {
        match self {
            Predictor::Force(f) => f.fit(&data.force_data(), Some(observer)),
            Predictor::Trajectory(f) => f.fit(&data.trajectory_data(), Some(observer)),
        }
    }

    /// The target signal predicted with `values`.
    fn predict(&self, data: &FitData, values: &[f64]) -> Result<Vec<f64>, FitError> {
        match self {
            Predictor::Force(f) => f.predict(&data.force_data(), values),
            Predictor::Trajectory(f) => f.predict(&data.trajectory_data(), values),
        }
    }

    /// The record's noise floor for the fit at `values`: the force sensor's (`[regimes]
    /// noise_sigma` or estimated) with the kinematics' propagated through the model at force
    /// level, none if the sensor's could not be estimated; the displacement noise at
    /// trajectory level; shown in the record's own unit ([`FitData::shown`]).
    fn noise_floor(
        &self,
        exp: &Experiment,
        data: &FitData,
        values: &[f64],
    ) -> Result<Option<NoiseFloor>, FitError> {
        let k = &data.kinematics;
        let (unit, scale) = data.shown();
        let shown = ShownIn::new(unit, scale);
        let Predictor::Force(fit) = self else {
            return Ok(Some(NoiseFloor::displacement(k.sigma_x).shown_in(shown)));
        };
        let fd = data.force_data();
        let sensor = exp
            .regimes
            .noise_sigma
            .or_else(|| stf_core::regimes::noise_floor(fd.f).ok());
        let floor = sensor
            .map(|s| fit.noise_floor(&fd, values, s, k.motion_noise()))
            .transpose()?;
        Ok(floor.map(|f| f.shown_in(shown)))
    }
}

/// The oscillator `system` of a trajectory-level fit, discovery or identification stage,
/// driven as in the record of kinematics `k`, from its initial state, simulated with the
/// experiment's integrator.
pub fn oscillator_fit(exp: &Experiment, system: OscillatorParams, k: &Kinematics) -> TrajectoryFit {
    let (x0, v0) = k.initial_state();
    TrajectoryFit::new(system, Arc::new(k.excitation()))
        .sim_settings(exp.integrator.clone())
        .initial(x0, v0)
}

/// Why the kinematics of the record `file` cannot be derived, with the fix where there is
/// one: a time column that is not uniform names the `[data] rate` that would replace it.
pub fn kinematics_error(e: &stf_core::numerics::derivative::FilterError, file: &str) -> String {
    use crate::digits::brief;
    use stf_core::numerics::derivative::FilterError;
    match e {
        FilterError::NonUniform {
            index,
            time,
            step,
            mean,
        } => format!(
            "the times of {file} are not uniform: the step from sample {index} (t = {} s) is \
             {} s against a mean of {} s (more than 0.1 % off); if the record was sampled at \
             a fixed rate, give it in [data]: `rate = {}` (samples/s; the times are then t0 \
             + i/rate, and the t column is not read), or resample the record uniformly",
            brief(*time),
            brief(*step),
            brief(*mean),
            brief(1.0 / mean)
        ),
        e => format!("cannot derive the kinematics of {file}: {e}"),
    }
}

/// Configure and fit every model of the experiment, in parallel (bounds widened where the
/// record needs it: [`FitData::scales`]).
pub fn fit_all(exp: &Experiment, data: &FitData, progress: &dyn Observer) -> Result<Vec<ModelFit>> {
    let scales = data.scales(&exp.system);
    let configured: Vec<Option<ConfiguredModel>> = if exp.models.is_empty() {
        if data.level == FitLevel::Force {
            bail!("{}: no [[models]] to fit", exp.path.display());
        }
        if exp.fit.system_free.is_empty() {
            bail!(
                "{}: nothing to fit: no [[models]] and no `fit.system` parameters",
                exp.path.display()
            );
        }
        vec![None]
    } else {
        // Every entry's mistakes at once, as the file's own.
        let (ok, errors): (Vec<_>, Vec<_>) = exp
            .models
            .iter()
            .map(|m| {
                let entry = std::slice::from_ref(m);
                configure_for(
                    entry,
                    &exp.path,
                    &exp.dir,
                    &exp.scripts,
                    Some(&scales),
                    &data.channels,
                )
            })
            .partition(Result::is_ok);
        if !errors.is_empty() {
            let errors = errors.into_iter().filter_map(Result::err).collect();
            return Err(crate::experiment::Mistakes::of(&exp.path, errors));
        }
        ok.into_iter().map(|c| c.ok()).collect()
    };
    let calls = crate::script_plan::fit_calls(&configured, data.record.len(), data.level);
    crate::script_plan::check(exp, calls, "this fit", progress)?;
    let overall = progress.job(&format!("fitting {} model(s)", configured.len()));
    overall.message(&jobs_message(0, configured.len(), 0.0));
    let (started, done) = (
        std::time::Instant::now(),
        std::sync::atomic::AtomicUsize::new(0),
    );
    let bars: Vec<_> = configured
        .iter()
        .map(|c| progress.job(c.as_ref().map_or("oscillator", |c| c.model.name())))
        .collect();
    let mut fits: Vec<ModelFit> = configured
        .par_iter()
        .zip(bars.par_iter())
        .map(|(c, bar)| {
            if progress.cancelled() {
                return Err(crate::error::Interrupted.into());
            }
            let r = fit_model(exp, data, c.as_ref(), bar.as_ref());
            bar.finish();
            let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            let elapsed = started.elapsed().as_secs_f64();
            overall.message(&jobs_message(n, configured.len(), elapsed));
            if r.is_ok() {
                let name = c.as_ref().map_or("the oscillator", |c| c.model.name());
                progress.finished(&format!("the fit of `{name}`"));
            }
            r
        })
        .collect::<Result<_>>()?;
    overall.finish();
    let names: Vec<String> = fits.iter().map(|f| f.label.replace(' ', "")).collect();
    for (i, f) in fits.iter_mut().enumerate() {
        let same = names[..i].iter().filter(|n| **n == names[i]).count();
        f.label = if same > 0 {
            format!("{}#{}", names[i], same + 1)
        } else {
            names[i].clone()
        };
    }
    Ok(fits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_units_and_calibration_are_applied() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("rig.csv"),
            "time_ms,angle_deg,disp_mm,gauge_V\n0,0,1.5,2.0\n10,90,2.5,-1.0\n",
        )
        .unwrap();
        let exp = Experiment::parse(
            &dir.path().join("exp.toml"),
            r#"
[data]
file = "rig.csv"
columns = { t = "time_ms", phi = "angle_deg", x = "disp_mm", f_stf = "gauge_V" }
units = { t = "ms", phi = "deg", x = "mm" }
calibration = { a = 0.2942906, b = 0.0044168 }
"#,
        )
        .unwrap();
        let r = read_record(&exp, exp.data_file.as_ref().unwrap()).unwrap();
        assert_eq!(r.t, [0.0, 0.01]);
        assert!((r.phi.as_ref().unwrap()[1] - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert!((r.x[0] - 1.5e-3).abs() < 1e-15);
        let f = r.f_stf.as_ref().unwrap();
        assert!((f[0] - (0.2942906 * 2.0 + 0.0044168)).abs() < 1e-12);
    }

    #[test]
    fn an_unknown_unit_names_the_key() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("r.csv"), "t,phi,x\n0,0,0\n").unwrap();
        let err = Experiment::parse(
            &dir.path().join("exp.toml"),
            "[data]\nfile = \"r.csv\"\nunits = { x = \"furlong\" }\n",
        )
        .unwrap_err();
        let msg = format!("{err:#}");
        assert!(
            msg.contains("exp.toml:3") && msg.contains("data.units.x"),
            "{msg}"
        );
        assert!(msg.contains("known: m, cm, mm, um"), "{msg}");
    }
}
