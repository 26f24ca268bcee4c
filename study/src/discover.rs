//! The discover workflow: find where the base model and the measurement disagree, name the
//! missing effect, add it, repeat, and show the gap shrink.
//!
//! Candidates are the effects of docs/ARCHITECTURE.md §5 (the built-ins) not already in the
//! base, plus any scripts `[discover] candidates` lists, their bounds widened where the record
//! needs it. A record without `f_stf` (or `[discover] level = "trajectory"`) is discovered at
//! trajectory level along the same path: the core level ([`discover_force`] or
//! [`discover_trajectory`] with the refitted oscillator) is what differs. [`Discovered`] is
//! what `discovery.json`, `discovered.csv`, the terminal and the report are rendered from.

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use stf_core::data::record_bounds::widened;
use stf_core::discovery::{
    discover_force, discover_trajectory, Candidate, Discovery, DiscoveryError, DiscoverySettings,
    TrajectorySetup,
};
use stf_core::fit::{
    FitSettings, FittedParam, TrajectoryFit, DISPLACEMENT_OFFSET, FORCE_OFFSET, INITIAL_STATE,
};
use stf_core::physics::channel_law::{ChannelLaw, Law};
use stf_core::physics::force_model::ForceModel;
use stf_core::physics::model_sum::ModelSum;
use stf_core::physics::oscillator_params::OscParam;
use stf_core::regimes::Cycle;
use stf_plugins::ScriptRun;

use crate::experiment::{DiscoverSpec, Experiment, FitLevel};
use crate::fitting::{load_data_at, oscillator_fit, system_param, FitData};
use crate::model_config::resolve;
use crate::observer::{discovery_observer, Observer};
use crate::outputs::discovery_json::{DiscoveryJson, FinalSystemJson};
use crate::outputs::models_entry::SystemEntry;
use crate::validation::{DiscoveryScore, ValidationRecord};
use crate::verdict::{discover_verdict, DiscoverVerdict};

/// The inputs of a discovery: its settings, the record at its level and the `[validate]`
/// record, read and checked.
pub struct DiscoverInputs {
    /// `[discover]`.
    pub spec: DiscoverSpec,
    /// The record discovered on, with its kinematics and level.
    pub data: FitData,
    /// The second record the base and final models are scored on.
    pub validation: Option<ValidationRecord>,
}

/// A discovery with the record it was made on.
pub struct Discovered {
    /// `[discover]`.
    pub spec: DiscoverSpec,
    /// The record discovered on.
    pub data: FitData,
    /// What was found: effects, steps, gaps, the final model.
    pub found: Discovery,
    /// The oscillator parameters refitted with every model (trajectory level; else empty).
    pub refitted: Vec<String>,
    /// The base's and the final model's errors on the `[validate]` record.
    pub score: Option<DiscoveryScore>,
    /// The rotor cycles (or stretches) the record was cut into.
    pub cycles: usize,
    /// How long the search took, s.
    pub wall_s: f64,
    /// Each script model's name with its path as `[discover]` gives it: what the printed
    /// entry names it by, so that it loads as it is.
    pub script_paths: Vec<(String, String)>,
}

/// Discover what the base of `exp`'s `[discover]` misses on its record.
pub fn discover(exp: &mut Experiment, observer: &dyn Observer) -> Result<Discovered> {
    load(exp, observer)?.discover(exp, observer)
}

/// Read and check the records of a discovery at the level `[discover]` asks for.
pub fn load(exp: &mut Experiment, observer: &dyn Observer) -> Result<DiscoverInputs> {
    let Some(spec) = exp.discover.clone() else {
        bail!(
            "{}: has no [discover] section (base = \"…\")",
            exp.path.display()
        );
    };
    let data = load_data_at(exp, spec.level).with_context(|| match spec.level {
        Some(FitLevel::Force) => "`discover.level = \"force\"` needs an `f_stf` column".to_string(),
        _ => "reading the record to discover on".to_string(),
    })?;
    crate::fit::warn_about(&data, observer);
    let validation = crate::validation::load(exp, &data)?;
    if let Some(rec) = &validation {
        crate::fit::warn_about(&rec.data, observer);
    }
    Ok(DiscoverInputs {
        spec,
        data,
        validation,
    })
}

impl DiscoverInputs {
    /// Run the discovery; `observer` is told the base, each candidate and each score.
    pub fn discover(self, exp: &Experiment, observer: &dyn Observer) -> Result<Discovered> {
        let (spec, data) = (&self.spec, &self.data);
        let (base, candidates) = models_of(exp, spec, data)?;
        let script_paths = script_paths(exp, spec)?;
        let cycles = crate::fitting::cycles_of(data)?;
        let mut settings = settings_of(exp, spec, data.level);
        let job = observer.job("discover");
        let (unit, scale) = data.shown();
        settings.observer = discovery_observer(job.clone(), unit, scale);
        // The oscillator refitted with every model, at trajectory level.
        let refit = (data.level == FitLevel::Trajectory).then(|| {
            let params = refitted(exp, data, base.as_ref(), observer);
            let setup = trajectory_setup(exp, data, &params);
            let names: Vec<String> = params.iter().map(OscParam::to_string).collect();
            (names, setup)
        });
        let refitting = refit.as_ref().map_or(String::new(), |(names, _)| {
            format!(" at trajectory level (refitting {})", names.join(", "))
        });
        observer.note(&format!(
            "discovering from `{}`{refitting} over {} candidates on {} {}…",
            spec.base_text(),
            candidates.len(),
            cycles.len(),
            data.words().cycles
        ));
        let started = Instant::now();
        let setup = refit.as_ref().map(|(_, setup)| setup);
        let found = discover_at(data, setup, (base, &candidates, &cycles), settings);
        job.finish();
        let found = found.map_err(|e| match e {
            DiscoveryError::NoHoldout { .. } => anyhow::Error::new(e).context(format!(
                "{}:{}: `discover.holdout_every`",
                exp.path.display(),
                self.spec.line
            )),
            e => e.into(),
        })?;
        let wall_s = started.elapsed().as_secs_f64();
        let score = self
            .validation
            .as_ref()
            .map(|rec| crate::validation::score_discovery(exp, &found, rec));
        Ok(Discovered {
            refitted: refit.map(|(names, _)| names).unwrap_or_default(),
            spec: self.spec,
            data: self.data,
            found,
            score,
            cycles: cycles.len(),
            wall_s,
            script_paths,
        })
    }
}

impl Discovered {
    /// `discovery.json` of `exp`, with the final model's `[[models]]` entry and, at trajectory
    /// level, the refitted oscillator's `[system]` entry (else empty), as TOML.
    pub fn json<'a>(
        &'a self,
        exp: &'a Experiment,
    ) -> Result<(DiscoveryJson<'a>, (String, String))> {
        results(
            exp,
            &self.data,
            (&self.found, &self.refitted),
            &self.script_paths,
            self.score.as_ref(),
            self.wall_s,
        )
    }

    /// The verdict: what was named, the gap before and after against the noise floor (in the
    /// level's unit), the share of the excess explained; at trajectory level S(μ) before and
    /// after.
    pub fn verdict(&self) -> DiscoverVerdict {
        let (unit, scale) = self.data.shown();
        let f = &self.found;
        let mut verdict = discover_verdict(
            &f.effects,
            f.gap_before * scale,
            f.gap_after * scale,
            f.noise_floor * scale,
            unit,
        );
        if let Some(tf) = &f.trajectory {
            verdict.text = format!(
                "{} S(μ) {:.4} → {:.4} {}.",
                verdict.text, tf.s_before_mm2, tf.s_after_mm2, self.data.units.x_squared
            );
        }
        verdict
    }

    /// The base's and the final model's curves of the measured signal.
    pub fn modelled(&self) -> (Vec<f64>, Vec<f64>) {
        modelled(self.data.target(), &self.found)
    }

    /// The text of `discovered.csv`.
    pub fn discovered_csv(&self) -> Result<Vec<u8>> {
        let (before, after) = self.modelled();
        let signal = self.data.level.signal().column;
        let (t, target) = (&self.data.record.t, self.data.target());
        crate::discovery_curves::discovered_csv(signal, t, target, (&before, &after))
    }
}

/// The base's and the final model's curves of the measured signal `target`: `target −
/// residual`, sample by sample.
fn modelled(target: &[f64], found: &Discovery) -> (Vec<f64>, Vec<f64>) {
    let minus = |r: &[f64]| -> Vec<f64> { target.iter().zip(r).map(|(m, r)| m - r).collect() };
    (minus(&found.residual_before), minus(&found.residual_after))
}

/// The sum of `terms` (names or script paths; `none` is the zero force).
fn model_from(terms: &[String], dir: &Path, run: &ScriptRun) -> Result<Arc<dyn ForceModel>> {
    let parts = terms
        .iter()
        .filter(|s| *s != "none")
        .map(|s| resolve(s, dir, run))
        .collect::<Result<Vec<_>>>()?;
    Ok(Arc::new(ModelSum::new(parts)?))
}

/// The fit settings of force-level discovery: discovery's own stopping rule
/// ([`DiscoverySettings::default`]: at most 200 iterations a stage, relative cost change
/// 1e-7, far below what moves a BIC by its threshold), with the solver and seed of `[fit]`,
/// and its `max_iters` when the experiment sets one. (The plain fit's 1e-9 made candidates
/// that explain nothing creep for hundreds of iterations on a 150 000-sample record.)
fn force_fit_settings(from: &FitSettings) -> FitSettings {
    let mut fit = DiscoverySettings::default().fit;
    fit.solver = from.solver;
    fit.seed = from.seed;
    if from.max_iters != FitSettings::default().max_iters {
        fit.max_iters = from.max_iters;
    }
    fit
}

/// Discover at `data`'s level: along the record's kinematics (their noise enters the floor,
/// their filter the test's blocks), or simulating the oscillator of `setup`.
fn discover_at(
    data: &FitData,
    setup: Option<&TrajectorySetup>,
    (base, candidates, cycles): (Arc<dyn ForceModel>, &[Candidate], &[Cycle]),
    settings: DiscoverySettings,
) -> Result<Discovery, DiscoveryError> {
    match setup {
        None => {
            let mut settings = settings.kinematics(&data.kinematics);
            let k = &data.kinematics;
            settings.regimes = k.phi.is_some() || k.omega.is_some();
            settings.pieces = data.words().cycles;
            discover_force(base, candidates, &data.force_data(), cycles, &settings)
        }
        Some(setup) => {
            let td = data.trajectory_data();
            let mut settings = settings;
            settings.x_unit = data.units.x;
            settings.pieces = data.words().cycles;
            discover_trajectory(base, candidates, &td, cycles, setup, &settings)
        }
    }
}

/// The base model and the candidates of `[discover]`: the vocabulary of
/// docs/ARCHITECTURE.md §5, or the list given, less what the base holds.
fn models_of(
    exp: &Experiment,
    spec: &DiscoverSpec,
    data: &FitData,
) -> Result<(Arc<dyn ForceModel>, Vec<Candidate>)> {
    let scales = data.scales(&exp.system);
    let base = model_from(&spec.base, &exp.dir, &exp.scripts)
        .with_context(|| format!("{}: `discover.base`", exp.path.display()))?;
    let base = widened(base, &scales);
    let mut candidates = Vec::new();
    let names: Vec<String> = match &spec.candidates {
        Some(list) => list.clone(),
        // Every built-in model is a default candidate (docs/ARCHITECTURE.md §5).
        None => stf_models::names().into_iter().map(String::from).collect(),
    };
    for name in names.iter().filter(|n| !spec.base.contains(n)) {
        let model = resolve(name, &exp.dir, &exp.scripts)
            .with_context(|| format!("{}: `discover.candidates`", exp.path.display()))?;
        candidates.push(Candidate::new(
            model.name().to_string(),
            widened(model, &scales),
        ));
    }
    candidates.extend(law_candidates(exp, spec, data, &scales)?);
    Ok((base, candidates))
}

/// "P follows channel c" for the record's channels (`[data] channels`): for each part of
/// the base and each channel, the part again with its amplitude (its first parameter, by the
/// models' convention) a linear law of the channel, P_gain·c, started at 0 — added to the
/// base's constant P it is the affine law P + P_gain·c (exactly so for a part linear in its
/// amplitude: `viscous`, `yield`, …). Named `part.P~channel`; scored and accepted as any
/// effect.
fn law_candidates(
    exp: &Experiment,
    spec: &DiscoverSpec,
    data: &FitData,
    scales: &stf_core::data::record_bounds::DataScales,
) -> Result<Vec<Candidate>> {
    let mut out = Vec::new();
    for part in spec.base.iter().filter(|s| *s != "none") {
        let model = widened(resolve(part, &exp.dir, &exp.scripts)?, scales);
        let Some(p) = model.params().first().map(|s| s.name.clone()) else {
            continue;
        };
        for c in data.channels.names() {
            let Some(channel) = data.channels.get(c) else {
                continue;
            };
            let name = format!("{}.{p}~{c}", model.name());
            let law = ChannelLaw::new(model.clone(), &p, Law::Linear, channel.clone())?;
            out.push(Candidate::new(name.clone(), Arc::new(law.named(name))));
        }
    }
    Ok(out)
}

/// The name of every script of `[discover]`'s base and candidates, with its path as given
/// there (relative to the experiment, as an entry pasted into it reads it).
fn script_paths(exp: &Experiment, spec: &DiscoverSpec) -> Result<Vec<(String, String)>> {
    let given = spec.base.iter().chain(spec.candidates.iter().flatten());
    given
        .filter(|s| s.trim().ends_with(".rhai"))
        .map(|s| {
            let model = resolve(s, &exp.dir, &exp.scripts)
                .with_context(|| format!("{}: `discover`: {s}", exp.path.display()))?;
            Ok((model.name().to_string(), s.clone()))
        })
        .collect()
}

/// Discovery's settings from `[fit]` and `[discover]` at `level`.
fn settings_of(exp: &Experiment, spec: &DiscoverSpec, level: FitLevel) -> DiscoverySettings {
    let fit = match level {
        FitLevel::Force => force_fit_settings(&exp.fit.settings),
        FitLevel::Trajectory => exp.fit.settings.clone(),
    };
    let d = DiscoverySettings::default();
    DiscoverySettings {
        max_effects: spec.max_effects.unwrap_or(d.max_effects),
        holdout_every: spec.holdout_every.unwrap_or(d.holdout_every),
        scout_from: spec.scout_from.unwrap_or(d.scout_from),
        recheck: spec.recheck,
        polish: spec.polish,
        fit,
        fit_offset: exp.fit.offset,
        ..d
    }
}

/// `discovery.json` with the final model's `[[models]]` entry and,
/// at trajectory level, the refitted oscillator's `[system]` entry (`names`; else empty).
/// At force level the final parameters in the JSON hold the offset `f_off` too.
fn results<'a>(
    exp: &'a Experiment,
    data: &'a FitData,
    (found, names): (&'a Discovery, &'a [String]),
    script_paths: &[(String, String)],
    score: Option<&'a DiscoveryScore>,
    wall: f64,
) -> Result<(DiscoveryJson<'a>, (String, String))> {
    let own = |p: &FittedParam| {
        names.contains(&p.name)
            || [FORCE_OFFSET, DISPLACEMENT_OFFSET].contains(&p.name.as_str())
            || INITIAL_STATE.contains(&p.name.as_str())
    };
    let model_params: Vec<&FittedParam> = found.final_params.iter().filter(|p| !own(p)).collect();
    // The final model as an experiment's `[[models]]` entry that `fit` and `compare` accept
    // as it is (TOML): scripts by their paths, a channel law in the law's syntax.
    let terms = found.final_model.terms();
    let toml_entry =
        crate::discovered_entry::final_entry(exp, &terms, &model_params, script_paths)?
            .to_toml()
            .context("cannot write the final model as an experiment entry")?;
    let (doc, system_entry) = match &found.trajectory {
        None => {
            let all: Vec<&FittedParam> = found.final_params.iter().collect();
            let curves = crate::discovery_curves::force_curves(found, exp.system);
            let doc = DiscoveryJson::new(
                (exp, data),
                (found, score),
                &all,
                toml_entry.clone(),
                curves,
            );
            (doc, String::new())
        }
        Some(tf) => {
            let refitted = SystemEntry {
                system: names
                    .iter()
                    .filter_map(|n| {
                        let v = tf.system_after.get(n)?;
                        Some((n.clone(), crate::digits::carried(v)))
                    })
                    .collect(),
            };
            let system_entry = refitted
                .to_toml()
                .context("cannot write the refitted oscillator as a [system] entry")?;
            let system = FinalSystemJson {
                refitted,
                system_entry: system_entry.clone(),
            };
            let curves = crate::discovery_curves::trajectory_curves(found, tf);
            let doc = DiscoveryJson::new(
                (exp, data),
                (found, score),
                &model_params,
                toml_entry.clone(),
                curves,
            )
            .with_trajectory(
                tf,
                names,
                system,
                wall,
                data.system_estimate,
                data.units.x_si,
            );
            (doc, system_entry)
        }
    };
    Ok((doc, (toml_entry, system_entry)))
}

/// The oscillator parameters refitted with every model at trajectory level: `[fit] system`,
/// or by default `m`, `k`, `c` for a rig driven by a measured force `u`, `k`, `c`, `T` for the
/// rotor — less those the base repeats (a `viscous` base carries the linear damping, so `c`
/// stays as set), said on the terminal.
fn refitted(
    exp: &Experiment,
    data: &FitData,
    base: &dyn ForceModel,
    observer: &dyn Observer,
) -> Vec<OscParam> {
    if !exp.fit.system_free.is_empty() {
        return exp.fit.system_free.clone();
    }
    let k = &data.kinematics;
    let rotor = k.phi.is_some() || k.omega.is_some();
    let names = if rotor {
        [OscParam::K, OscParam::C, OscParam::T]
    } else {
        [OscParam::M, OscParam::K, OscParam::C]
    };
    let repeated: Vec<(&str, &str)> = base
        .params()
        .iter()
        .filter_map(|s| s.same_as.map(|o| (s.name.as_str(), o)))
        .collect();
    let mut kept = Vec::new();
    for name in names {
        match repeated.iter().find(|(_, o)| *o == name.name()) {
            Some((p, _)) => observer.note(&format!(
                "`{name}` is not refitted: the base's `{p}` is the same term (give `[fit] system` \
                 to choose)"
            )),
            None => kept.push(name),
        }
    }
    kept
}

/// The oscillator side of a trajectory-level discovery: the oscillator of
/// [`oscillator_fit`], the parameters `names` refitted with every model (and `x0`, `v0`
/// unless `[fit] initial = "record"`), the force recovered from the kinematics as a hint.
fn trajectory_setup(exp: &Experiment, data: &FitData, names: &[OscParam]) -> TrajectorySetup {
    let k = &data.kinematics;
    let params = names
        .iter()
        .map(|&param| system_param(param, &exp.system, k));
    let mut fit = params.fold(oscillator_fit(exp, exp.system, k), TrajectoryFit::free);
    if exp.fit.fit_initial {
        fit = k
            .initial_state_params()
            .into_iter()
            .fold(fit, TrajectoryFit::free);
    }
    TrajectorySetup::new(fit).force_hint(stf_core::discovery::ForceHint {
        v: k.v.clone(),
        a: k.a.clone(),
        f: k.recovered_force(&exp.system),
    })
}
