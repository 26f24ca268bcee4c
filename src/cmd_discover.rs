//! `stf-lab discover EXP.toml --out DIR`: find where the base model and the measurement
//! disagree, name the missing effect, add it, repeat, and show the gap shrink.
//!
//! Candidates are the effects of docs/ARCHITECTURE.md §5 (the built-ins `viscous`, `power_law`,
//! `added_mass`, `yield`, `wall_impact`, `cubic_stiffness`, `maxwell`, `jamming_on_off`) not
//! already in the base, plus any scripts `[discover] candidates` lists. Writes
//! `DIR/discovery.json` (`effects`, `gap_before`, `gap_after`, the steps with every candidate's
//! scores, and the final model as an experiment entry), a report and figures. A record
//! without `f_stf` (or `[discover] level = "trajectory"`) is discovered at trajectory level,
//! along the same path: what differs is the core level ([`discover_force`] or
//! [`discover_trajectory`] with the refitted oscillator), the signal and unit
//! ([`FitLevel::shown`]), the oscillator's entry and the figures ([`Drawn`]).

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
use stf_core::physics::force_model::ForceModel;
use stf_core::physics::model_sum::ModelSum;
use stf_core::physics::oscillator_params::OscParam;
use stf_core::regimes::Cycle;
use stf_plugins::ScriptRun;

use crate::experiment::{DiscoverSpec, Experiment, FitLevel};
use crate::fitting::{estimate_line, load_data_at, oscillator_fit, system_param, FitData};
use crate::model_config::resolve;
use crate::outputs::discovery_json::{DiscoveryJson, FinalSystemJson};
use crate::outputs::models_entry::{ModelsEntry, SystemEntry};
use crate::progress::{discovery_observer, Progress};
use crate::report::{
    measured_vs_model, FigureRef, Quantity, Section, Table, DISPLACEMENT_MM,
    DISPLACEMENT_RESIDUAL_MM, STF_FORCE, STF_FORCE_RESIDUAL,
};
use crate::standard_report::{record_sections, write_report};
use crate::validation::DiscoveryScore;
use crate::writing::results_dir::{wrote_line, ResultsDir};
use crate::writing::write_json;
use crate::{say, tell};

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

/// Run `stf-lab discover` on an experiment loaded (from its file, or a campaign's unit: its
/// record set with [`Experiment::with_data_file`]): the results are built in a staging
/// folder and swapped in as a whole ([`ResultsDir`]).
pub fn run_experiment(mut exp: Experiment, out_arg: &Path, force: bool, quiet: bool) -> Result<()> {
    let Some(spec) = exp.discover.clone() else {
        bail!(
            "{}: has no [discover] section (base = \"…\")",
            exp.path.display()
        );
    };
    let data = load_data_at(&mut exp, spec.level).with_context(|| match spec.level {
        Some(FitLevel::Force) => "`discover.level = \"force\"` needs an `f_stf` column".to_string(),
        _ => "reading the record to discover on".to_string(),
    })?;
    let spec = &spec;
    if let Some(line) = estimate_line(&data) {
        say!("{line}");
    }
    let validation = crate::validation::load(&exp, &data)?;
    let results = ResultsDir::begin(out_arg, force)?;
    let (base, candidates) = models_of(&exp, spec, &data)?;
    let cycles = crate::fitting::cycles_of(&data)?;
    let mut settings = settings_of(&exp, spec, data.level);
    let progress = Progress::new(quiet);
    let bar = progress.job("discover");
    let (unit, scale) = data.level.shown();
    settings.observer = discovery_observer(bar.clone(), unit, scale);
    // The oscillator refitted with every model, at trajectory level.
    let refit = (data.level == FitLevel::Trajectory).then(|| {
        let params = refitted(&exp, &data, base.as_ref(), quiet);
        let setup = trajectory_setup(&exp, &data, &params);
        let names: Vec<String> = params.iter().map(OscParam::to_string).collect();
        (names, setup)
    });
    if !quiet {
        let refitting = refit.as_ref().map_or(String::new(), |(names, _)| {
            format!(" at trajectory level (refitting {})", names.join(", "))
        });
        tell!(
            "discovering from `{}`{refitting} over {} candidates on {} cycles…",
            spec.base_text(),
            candidates.len(),
            cycles.len()
        );
    }
    let started = Instant::now();
    let setup = refit.as_ref().map(|(_, setup)| setup);
    let found = discover_at(&data, setup, (base, &candidates, &cycles), settings);
    bar.finish_and_clear();
    let found = found?;
    let wall = started.elapsed().as_secs_f64();
    let score = validation
        .as_ref()
        .map(|rec| crate::validation::score_discovery(&exp, &found, rec));
    let names = refit
        .as_ref()
        .map_or(&[][..], |(names, _)| names.as_slice());
    let entries = write_results(
        &exp,
        &data,
        (&found, names),
        score.as_ref(),
        (results.path(), wall),
    )?;
    if exp.output.report {
        report(&exp, &data, &found, score.as_ref(), results.path())?;
    }
    results.commit()?;
    print_summary(spec, &data, &found, score.as_ref(), (&entries, wall));
    say!(
        "{}",
        wrote_line(
            out_arg,
            &["discovery.json", "discovered.csv"],
            exp.output.report
        )
    );
    Ok(())
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
            let settings = settings.kinematics(&data.kinematics);
            discover_force(base, candidates, &data.force_data(), cycles, &settings)
        }
        Some(setup) => {
            let td = data.trajectory_data();
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
    Ok((base, candidates))
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

/// The terminal summary of a discovery; `entries` are the final model's `[[models]]` and
/// (trajectory level) `[system]` entries.
fn print_summary(
    spec: &DiscoverSpec,
    data: &FitData,
    found: &Discovery,
    score: Option<&DiscoveryScore>,
    (entries, wall): (&(String, String), f64),
) {
    let (unit, scale) = data.level.shown();
    let effects = if found.effects.is_empty() {
        "none".to_string()
    } else {
        found.effects.join(", ")
    };
    let summary = match &found.trajectory {
        None => {
            say!(
                "base `{}`: gap {:.4} N; {}",
                spec.base_text(),
                found.gap_before,
                found.where_before.summary
            );
            format!(
                "effects: {effects}; gap {:.4} N → {:.4} N (noise floor {:.4} N) in {wall:.1} s",
                found.gap_before, found.gap_after, found.noise_floor,
            )
        }
        Some(tf) => format!(
            "effects: {effects}; S {:.4} → {:.4} mm² (noise floor {:.4} mm) in {wall:.1} s",
            tf.s_before_mm2,
            tf.s_after_mm2,
            found.noise_floor * 1e3,
        ),
    };
    let held_out = held_out_and_validation(found.holdout_cycles, score, unit, scale);
    for step in &found.steps {
        say!("  {}", step.verdict);
    }
    say!("{summary}");
    say!("  {held_out}");
    if found.trajectory.is_none() {
        for note in &found.notes {
            say!("  note: {note}");
        }
    }
    say!(
        "final model, as an experiment entry:\n{}{}",
        entries.0,
        entries.1
    );
}

/// The held-out cycles every step was scored on and, with `[validate]`, the base's and the
/// final model's errors on the validation record, in one sentence (errors shown in `unit`,
/// `scale` from SI).
fn held_out_and_validation(
    holdout_cycles: usize,
    score: Option<&DiscoveryScore>,
    unit: &str,
    scale: f64,
) -> String {
    let held_out = format!("held out: {holdout_cycles} cycles of the record");
    match score {
        Some(score) => format!("{held_out}; {}", score.summary(unit, scale)),
        None => held_out,
    }
}

/// `discovery.json` and `discovered.csv`; returns the final model's `[[models]]` entry and,
/// at trajectory level, the refitted oscillator's `[system]` entry (`names`; else empty).
/// At force level the final parameters in the JSON hold the offset `f_off` too.
fn write_results(
    exp: &Experiment,
    data: &FitData,
    (found, names): (&Discovery, &[String]),
    score: Option<&DiscoveryScore>,
    (out, wall): (&Path, f64),
) -> Result<(String, String)> {
    let own = |p: &FittedParam| {
        names.contains(&p.name)
            || [FORCE_OFFSET, DISPLACEMENT_OFFSET].contains(&p.name.as_str())
            || INITIAL_STATE.contains(&p.name.as_str())
    };
    let model_params: Vec<&FittedParam> = found.final_params.iter().filter(|p| !own(p)).collect();
    // The final model as an experiment's `[[models]]` entry that `fit` and `compare` accept
    // as it is (TOML).
    let toml_entry = ModelsEntry::new(&found.final_model.terms(), model_params.iter().copied())
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
                    .filter_map(|n| tf.system_after.get(n).map(|v| (n.clone(), v)))
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
            .with_trajectory(tf, names, system, wall, data.system_estimate);
            (doc, system_entry)
        }
    };
    write_json(&out.join("discovery.json"), &doc)?;
    let target = data.target();
    let (before, after) = modelled(target, found);
    let signal = data.level.signal().column;
    crate::discovery_curves::write_curves(out, signal, &data.record.t, target, (&before, &after))?;
    Ok((toml_entry, system_entry))
}

/// The base's and the final model's curves of the measured signal `target`: `target −
/// residual`, sample by sample.
fn modelled(target: &[f64], found: &Discovery) -> (Vec<f64>, Vec<f64>) {
    let minus = |r: &[f64]| -> Vec<f64> { target.iter().zip(r).map(|(m, r)| m - r).collect() };
    (minus(&found.residual_before), minus(&found.residual_after))
}

/// What a discovery's report draws at one level: the section's title, the measured signal
/// against the base and the final model, and their residuals (figure names, quantities,
/// captions).
struct Drawn {
    title: &'static str,
    signal: (&'static str, Quantity, &'static str),
    residual: (&'static str, Quantity, &'static str),
}

/// [`Drawn`] at force level.
const FORCE_DRAWN: Drawn = Drawn {
    title: "Discovery",
    signal: (
        "discovery_force",
        STF_FORCE,
        "Measured STF force against the base and the final model.",
    ),
    residual: (
        "discovery_residual",
        STF_FORCE_RESIDUAL,
        "Residual (measured − model) of the base (grey band) and of the final model.",
    ),
};

/// [`Drawn`] at trajectory level.
const TRAJECTORY_DRAWN: Drawn = Drawn {
    title: "Discovery (trajectory level)",
    signal: (
        "discovery_x",
        DISPLACEMENT_MM,
        "Measured displacement against the simulated base and final model.",
    ),
    residual: (
        "discovery_x_residual",
        DISPLACEMENT_RESIDUAL_MM,
        "Displacement residual (measured − simulated) of the base (grey band) and of the \
         final model.",
    ),
};

/// The report of a discovery: its notes, the steps' tables (force level), the measured
/// signal against the base and the final model and their residuals (in the level's unit),
/// the regime windows (force level) and the record's sections.
fn report(
    exp: &Experiment,
    data: &FitData,
    found: &Discovery,
    score: Option<&DiscoveryScore>,
    out: &Path,
) -> Result<()> {
    let dir = out.join("figures");
    std::fs::create_dir_all(&dir)?;
    let (unit, scale) = data.level.shown();
    let drawn = match data.level {
        FitLevel::Force => &FORCE_DRAWN,
        FitLevel::Trajectory => &TRAJECTORY_DRAWN,
    };
    let shown = |v: &[f64]| v.iter().map(|v| v * scale).collect::<Vec<f64>>();
    let target = data.target();
    let (before, after) = modelled(target, found);
    let mut s = Section::new(drawn.title);
    // The notes are the base's gap, each step's verdict and the final gap, in order.
    s.paragraphs.extend(found.notes.iter().cloned());
    s.paragraphs.push(format!(
        "{}.",
        held_out_and_validation(found.holdout_cycles, score, unit, scale)
    ));
    if data.level == FitLevel::Force {
        let tables = found
            .steps
            .iter()
            .enumerate()
            .map(|(i, step)| step_table(i, step));
        s.tables.extend(tables);
    }
    let (b, a, r_after) = (shown(&before), shown(&after), shown(&found.residual_after));
    let figures = [
        (
            drawn.signal,
            shown(target),
            vec![("base", &b[..]), ("final", &a[..])],
        ),
        (
            drawn.residual,
            shown(&found.residual_before),
            vec![("final", &r_after[..])],
        ),
    ];
    for ((name, quantity, caption), measured, curves) in figures {
        let fig = measured_vs_model(&dir, name, quantity, &data.record.t, &measured, &curves)?;
        s.figures.push(FigureRef::new(fig, caption));
    }
    let mut sections = vec![s];
    if data.level == FitLevel::Force {
        let curves = [("base", before.as_slice()), ("final", after.as_slice())];
        sections.extend(crate::regime_figures::regime_section(
            exp, data, &curves, out,
        )?);
    }
    sections.extend(record_sections(data, &[], out)?);
    let verdict = crate::verdict::discover_verdict(
        &found.effects,
        found.gap_before * scale,
        found.gap_after * scale,
        found.noise_floor * scale,
        unit,
    );
    let mut intro = vec![match &found.trajectory {
        None => verdict,
        Some(tf) => format!(
            "{verdict} S(μ) {:.4} → {:.4} mm².",
            tf.s_before_mm2, tf.s_after_mm2
        ),
    }];
    intro.extend(score.map(|v| format!("Beside the held-out cycles, {}.", v.summary(unit, scale))));
    write_report(
        &format!("Discovery: {}", exp.path.display()),
        intro,
        sections,
        out,
    )
}

/// The table of step `i`'s candidates (force level).
fn step_table(i: usize, step: &stf_core::discovery::Step) -> Table {
    let caption = format!("Step {}: candidates added to `{}`", i + 1, step.current);
    let columns = [
        "candidate",
        "held-out RMS, N",
        "ΔBIC",
        "paired z (units)",
        "explains of the excess",
        "significant",
    ];
    let rows = step.candidates.iter().map(|c| {
        vec![
            c.name.clone(),
            format!("{:.5}", c.holdout_rms),
            format!("{:.1}", c.delta_bic),
            format!("{:.1} ({})", c.gain_z, c.effective_n),
            format!("{} %", crate::digits::fixed(100.0 * c.explained_share, 0)),
            crate::standard_report::yes_no(c.significant),
        ]
    });
    Table::new(caption, &columns).with_rows(rows.collect())
}

/// The oscillator parameters refitted with every model at trajectory level: `[fit] system`,
/// or by default `m`, `k`, `c` for a rig driven by a measured force `u`, `k`, `c`, `T` for the
/// rotor — less those the base repeats (a `viscous` base carries the linear damping, so `c`
/// stays as set), said on the terminal.
fn refitted(exp: &Experiment, data: &FitData, base: &dyn ForceModel, quiet: bool) -> Vec<OscParam> {
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
            Some((p, _)) if !quiet => tell!(
                "`{name}` is not refitted: the base's `{p}` is the same term (give `[fit] system` \
                 to choose)"
            ),
            Some(_) => {}
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
