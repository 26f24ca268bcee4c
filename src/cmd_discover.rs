//! `stf-lab discover EXP.toml --out DIR`: find where the base model and the measurement
//! disagree, name the missing effect, add it, repeat, and show the gap shrink.
//!
//! Candidates are the effects of docs/ARCHITECTURE.md §5 (the built-ins `viscous`, `power_law`,
//! `added_mass`, `yield`, `wall_impact`, `cubic_stiffness`, `maxwell`, `jamming_on_off`) not
//! already in the base, plus any scripts `[discover] candidates` lists. Writes
//! `DIR/discovery.json` (`effects`, `gap_before`, `gap_after`, the steps with every candidate's
//! scores, and the final model as an experiment entry), a report and figures. A record
//! without `f_stf` (or `[discover] level = "trajectory"`) is discovered at trajectory level
//! (`run_trajectory`).

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use stf_core::data::record_bounds::widened;
use stf_core::discovery::{
    discover_force, discover_trajectory, Candidate, Discovery, DiscoverySettings, TrajectoryPart,
    TrajectorySetup,
};
use stf_core::fit::{FitSettings, FittedParam, TrajectoryData};
use stf_core::physics::force_model::ForceModel;
use stf_core::physics::model_sum::ModelSum;
use stf_core::physics::oscillator_params::OscParam;
use stf_plugins::ScriptRun;

use crate::experiment::{DiscoverSpec, Experiment, FitLevel};
use crate::fitting::{estimate_line, load_data_at, system_param, FitData};
use crate::model_config::resolve;
use crate::output::write_json;
use crate::outputs::discovery_json::{Common, DiscoveryJson};
use crate::outputs::models_entry::{ModelsEntry, SystemEntry};
use crate::progress::{discovery_observer, Progress};
use crate::report::{
    measured_vs_fitted, measured_vs_model, FigureRef, Section, Table, DISPLACEMENT_MM,
    DISPLACEMENT_RESIDUAL_MM, STF_FORCE_RESIDUAL,
};
use crate::results_dir::{wrote_line, ResultsDir};
use crate::standard_report::{record_sections, write_report};
use crate::validation::{DiscoveryScore, ValidationRecord};
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

/// The final `model` with the values of `params` as an experiment's `[[models]]` entry that
/// `fit` and `compare` accept as it is (TOML).
fn models_entry<'a>(
    model: &dyn ForceModel,
    params: impl Iterator<Item = &'a FittedParam>,
) -> Result<String> {
    ModelsEntry::new(&model.terms(), params)
        .to_toml()
        .context("cannot write the final model as an experiment entry")
}

/// The terminal's account of a discovery: each step's verdict, the `summary` line and the
/// `held_out` line (the held-out cycles and the validation record).
fn print_steps(found: &Discovery, summary: &str, held_out: &str) {
    for step in &found.steps {
        say!("  {}", step.verdict);
    }
    say!("{summary}");
    say!("  {held_out}");
}

/// The effects named, or `none`.
fn named(effects: &[String]) -> String {
    if effects.is_empty() {
        "none".to_string()
    } else {
        effects.join(", ")
    }
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

/// Run `stf-lab discover`.
/// The results are built in a staging folder and swapped in as a whole ([`ResultsDir`]).
pub fn run(exp_path: &Path, out_arg: &Path, force: bool, quiet: bool) -> Result<()> {
    run_experiment(Experiment::load(exp_path)?, out_arg, force, quiet)
}

/// [`run`] on an experiment already loaded (a campaign's unit: its record set with
/// [`Experiment::with_data_file`]).
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
    let out = results.path();
    let (base, candidates) = models_of(&exp, spec, &data)?;
    let cycles = crate::fitting::cycles_of(&data)?;
    let mut settings = settings_of(&exp, spec, data.level);
    let started = Instant::now();
    let progress = Progress::new(quiet);
    let bar = progress.job("discover");
    let (unit, scale) = data.level.shown();
    settings.observer = discovery_observer(bar.clone(), unit, scale);
    if data.level == FitLevel::Trajectory {
        run_trajectory(
            &exp,
            &data,
            base,
            &candidates,
            &cycles,
            &settings,
            (out, validation.as_ref()),
            (quiet, &bar),
        )?;
        results.commit()?;
        say!(
            "{}",
            wrote_line(
                out_arg,
                &["discovery.json", "discovered.csv"],
                exp.output.report
            )
        );
        return Ok(());
    }
    if !quiet {
        tell!(
            "discovering from `{}` over {} candidates on {} cycles…",
            spec.base_text(),
            candidates.len(),
            cycles.len()
        );
    }
    // The record's kinematics noise enters the floor, its filter the test's blocks.
    let settings = settings.kinematics(&data.kinematics);
    let found = discover_force(base, &candidates, &data.force_data(), &cycles, &settings);
    bar.finish_and_clear();
    let found = found?;
    let wall = started.elapsed().as_secs_f64();
    let score = validation
        .as_ref()
        .map(|rec| crate::validation::score_force_discovery(&found, rec));
    let toml_entry = models_entry(
        found.final_model.as_ref(),
        found.final_params.iter().filter(|p| p.name != "f_off"),
    )?;
    write_force_results(&exp, &data, &found, score.as_ref(), &toml_entry, out)?;
    if exp.output.report {
        force_report(&exp, &data, &found, score.as_ref(), out)?;
    }

    results.commit()?;
    print_force(spec, &found, score.as_ref(), (&toml_entry, wall));
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
    let mut settings = DiscoverySettings::default()
        .fit(fit)
        .fit_offset(exp.fit.offset);
    if let Some(n) = spec.max_effects {
        settings = settings.max_effects(n);
    }
    if let Some(n) = spec.holdout_every {
        settings = settings.holdout_every(n);
    }
    if let Some(n) = spec.scout_from {
        settings = settings.scout_from(n);
    }
    settings
}

/// The terminal summary of a force-level discovery.
fn print_force(
    spec: &DiscoverSpec,
    found: &Discovery,
    score: Option<&DiscoveryScore>,
    (toml_entry, wall): (&str, f64),
) {
    say!(
        "base `{}`: gap {:.4} N; {}",
        spec.base_text(),
        found.gap_before,
        found.where_before.summary
    );
    let summary = format!(
        "effects: {}; gap {:.4} N → {:.4} N (noise floor {:.4} N) in {:.1} s",
        named(&found.effects),
        found.gap_before,
        found.gap_after,
        found.noise_floor,
        wall
    );
    print_steps(
        found,
        &summary,
        &held_out_and_validation(found.holdout_cycles, score, "N", 1.0),
    );
    for note in &found.notes {
        say!("  note: {note}");
    }
    say!("final model, as an experiment entry:\n{toml_entry}");
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

/// `discovery.json` and `discovered.csv` of a force-level discovery.
fn write_force_results(
    exp: &Experiment,
    data: &FitData,
    found: &Discovery,
    score: Option<&DiscoveryScore>,
    toml_entry: &str,
    out: &Path,
) -> Result<()> {
    let all: Vec<&FittedParam> = found.final_params.iter().collect();
    let doc = DiscoveryJson::new(
        Common {
            exp,
            data,
            found,
            score,
        },
        &all,
        toml_entry.to_string(),
        crate::discovery_curves::force_curves(found, exp.system),
    );
    write_json(&out.join("discovery.json"), &doc)?;
    let f = data.record.f_stf.as_deref().unwrap_or(&[]);
    let (before, after) = (
        minus(f, &found.residual_before),
        minus(f, &found.residual_after),
    );
    crate::discovery_curves::write_curves(out, "f_stf", &data.record.t, f, (&before, &after))
}

/// `measured − residual`, sample by sample: the modelled curve.
fn minus(measured: &[f64], residual: &[f64]) -> Vec<f64> {
    measured.iter().zip(residual).map(|(m, r)| m - r).collect()
}

/// The report of a force-level discovery.
fn force_report(
    exp: &Experiment,
    data: &FitData,
    found: &Discovery,
    score: Option<&DiscoveryScore>,
    out: &Path,
) -> Result<()> {
    let dir = out.join("figures");
    std::fs::create_dir_all(&dir)?;
    let f = data.record.f_stf.as_deref().unwrap_or(&[]);
    let (before, after) = (
        minus(f, &found.residual_before),
        minus(f, &found.residual_after),
    );
    let mut s = Section::new("Discovery");
    // The notes are the base's gap, each step's verdict and the final gap, in order.
    s.paragraphs.extend(found.notes.iter().cloned());
    s.paragraphs.push(format!(
        "{}.",
        held_out_and_validation(found.holdout_cycles, score, "N", 1.0)
    ));
    s.tables.extend(
        found
            .steps
            .iter()
            .enumerate()
            .map(|(i, step)| step_table(i, step)),
    );
    let fig = measured_vs_fitted(
        &dir,
        "discovery_force",
        &data.record.t,
        f,
        &[("base", &before), ("final", &after)],
    )?;
    s.figures.push(FigureRef::new(
        fig,
        "Measured STF force against the base and the final model.",
    ));
    let fig = measured_vs_model(
        &dir,
        "discovery_residual",
        STF_FORCE_RESIDUAL,
        &data.record.t,
        &found.residual_before,
        &[("final", &found.residual_after)],
    )?;
    s.figures.push(FigureRef::new(
        fig,
        "Residual (measured − model) of the base (grey band) and of the final model.",
    ));
    let mut sections = vec![s];
    let curves = [("base", before.as_slice()), ("final", after.as_slice())];
    sections.extend(crate::regime_figures::regime_section(
        exp, data, &curves, out,
    )?);
    sections.extend(record_sections(data, &[], out)?);
    let mut intro = vec![crate::verdict::discover_verdict(
        &found.effects,
        found.gap_before,
        found.gap_after,
        found.noise_floor,
        "N",
    )];
    intro.extend(score.map(|v| format!("Beside the held-out cycles, {}.", v.summary("N", 1.0))));
    write_report(
        &format!("Discovery: {}", exp.path.display()),
        intro,
        sections,
        out,
    )
}

/// The table of step `i`'s candidates (force level).
fn step_table(i: usize, step: &stf_core::discovery::Step) -> Table {
    Table {
        caption: format!("Step {}: candidates added to `{}`", i + 1, step.current),
        columns: [
            "candidate",
            "held-out RMS, N",
            "ΔBIC",
            "paired z (units)",
            "explains of the excess",
            "significant",
        ]
        .iter()
        .map(|c| c.to_string())
        .collect(),
        rows: step
            .candidates
            .iter()
            .map(|c| {
                vec![
                    c.name.clone(),
                    format!("{:.5}", c.holdout_rms),
                    format!("{:.1}", c.delta_bic),
                    format!("{:.1} ({})", c.gain_z, c.effective_n),
                    format!("{} %", crate::digits::fixed(100.0 * c.explained_share, 0)),
                    if c.significant {
                        "yes".into()
                    } else {
                        "no".into()
                    },
                ]
            })
            .collect(),
    }
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

/// `discover` at trajectory level: the simulated oscillator against the measured x.
#[allow(clippy::too_many_arguments)]
fn run_trajectory(
    exp: &Experiment,
    data: &FitData,
    base: Arc<dyn ForceModel>,
    candidates: &[Candidate],
    cycles: &[stf_core::regimes::Cycle],
    settings: &DiscoverySettings,
    (out, validation): (&Path, Option<&ValidationRecord>),
    (quiet, bar): (bool, &indicatif::ProgressBar),
) -> Result<()> {
    let Some(spec) = &exp.discover else {
        bail!("{}: has no [discover] section", exp.path.display());
    };
    let params = refitted(exp, data, base.as_ref(), quiet);
    let names: Vec<String> = params.iter().map(OscParam::to_string).collect();
    let setup = trajectory_setup(exp, data, &params);
    let settings = settings.clone();
    let started = Instant::now();
    if !quiet {
        tell!(
            "discovering from `{}` at trajectory level (refitting {}) over {} candidates on {} \
             cycles…",
            spec.base_text(),
            names.join(", "),
            candidates.len(),
            cycles.len()
        );
    }
    let td = TrajectoryData {
        t: &data.record.t,
        x: &data.record.x,
    };
    let found = discover_trajectory(base, candidates, &td, cycles, &setup, &settings);
    bar.finish_and_clear();
    let found = found?;
    let tf = found
        .trajectory
        .as_ref()
        .context("a trajectory-level discovery without its oscillator")?;
    let wall = started.elapsed().as_secs_f64();
    let score =
        validation.map(|rec| crate::validation::score_trajectory_discovery(exp, &found, rec));
    let (toml_entry, system_entry) =
        write_trajectory_results(exp, data, (&found, tf), &names, score.as_ref(), (out, wall))?;
    if exp.output.report {
        trajectory_report(exp, data, (&found, tf), score.as_ref(), out)?;
    }
    let found = &found;
    let summary = format!(
        "effects: {}; S {:.4} → {:.4} mm² (noise floor {:.4} mm) in {:.1} s",
        named(&found.effects),
        tf.s_before_mm2,
        tf.s_after_mm2,
        found.noise_floor * 1e3,
        wall
    );
    let held_out = held_out_and_validation(found.holdout_cycles, score.as_ref(), "mm", 1e3);
    print_steps(found, &summary, &held_out);
    say!("final model, as an experiment entry:\n{toml_entry}{system_entry}");
    Ok(())
}

/// The oscillator side of a trajectory-level discovery: the record's drive and initial
/// state, the parameters `names` refitted with every model (and `x0`, `v0` unless
/// `[fit] initial = "record"`), the force recovered from the kinematics as a hint.
fn trajectory_setup(exp: &Experiment, data: &FitData, names: &[OscParam]) -> TrajectorySetup {
    let k = &data.kinematics;
    let (x0, v0) = k.initial_state();
    let mut setup = TrajectorySetup::new(exp.system, Arc::new(k.excitation()))
        .sim_settings(exp.integrator.clone())
        .initial(x0, v0);
    for &param in names {
        setup = setup.refit(system_param(param, &exp.system, k));
    }
    setup = setup.force_hint(stf_core::discovery::ForceHint {
        v: k.v.clone(),
        a: k.a.clone(),
        f: k.recovered_force(&exp.system),
    });
    if exp.fit.fit_initial {
        for p in k.initial_state_params() {
            setup = setup.refit(p);
        }
    }
    setup
}

/// `discovery.json` and `discovered.csv` of a trajectory-level discovery; returns the final
/// model's `[[models]]` and `[system]` entries.
fn write_trajectory_results(
    exp: &Experiment,
    data: &FitData,
    (found, tf): (&Discovery, &TrajectoryPart),
    names: &[String],
    score: Option<&DiscoveryScore>,
    (out, wall): (&Path, f64),
) -> Result<(String, String)> {
    let model_params: Vec<&FittedParam> = found
        .final_params
        .iter()
        .filter(|p| {
            !names.contains(&p.name)
                && p.name != "x_off"
                && !stf_core::fit::INITIAL_STATE.contains(&p.name.as_str())
        })
        .collect();
    let toml_entry = models_entry(found.final_model.as_ref(), model_params.iter().copied())?;
    let system_entry = SystemEntry {
        system: names
            .iter()
            .filter_map(|n| tf.system_after.get(n).map(|v| (n.clone(), v)))
            .collect(),
    }
    .to_toml()
    .context("cannot write the refitted oscillator as a [system] entry")?;
    let doc = DiscoveryJson::new(
        Common {
            exp,
            data,
            found,
            score,
        },
        &model_params,
        toml_entry.clone(),
        crate::discovery_curves::trajectory_curves(found, tf),
    )
    .with_trajectory(tf, names, system_entry.clone(), wall, data.system_estimate);
    write_json(&out.join("discovery.json"), &doc)?;
    let x = &data.record.x;
    let curves = (tf.x_before.as_slice(), tf.x_after.as_slice());
    crate::discovery_curves::write_curves(out, "x", &data.record.t, x, curves)?;
    Ok((toml_entry, system_entry))
}

/// The report of a trajectory-level discovery.
fn trajectory_report(
    exp: &Experiment,
    data: &FitData,
    (found, tf): (&Discovery, &TrajectoryPart),
    score: Option<&DiscoveryScore>,
    out: &Path,
) -> Result<()> {
    let dir = out.join("figures");
    std::fs::create_dir_all(&dir)?;
    let mut s = Section::new("Discovery (trajectory level)");
    s.paragraphs.extend(found.notes.iter().cloned());
    s.paragraphs.push(format!(
        "{}.",
        held_out_and_validation(found.holdout_cycles, score, "mm", 1e3)
    ));
    let mm = |x: &[f64]| x.iter().map(|v| v * 1e3).collect::<Vec<f64>>();
    let fig = measured_vs_model(
        &dir,
        "discovery_x",
        DISPLACEMENT_MM,
        &data.record.t,
        &mm(&data.record.x),
        &[("base", &mm(&tf.x_before)), ("final", &mm(&tf.x_after))],
    )?;
    s.figures.push(FigureRef::new(
        fig,
        "Measured displacement against the simulated base and final model.",
    ));
    let residual = |sim: &[f64]| mm(&minus(&data.record.x, sim));
    let fig = measured_vs_model(
        &dir,
        "discovery_x_residual",
        DISPLACEMENT_RESIDUAL_MM,
        &data.record.t,
        &residual(&tf.x_before),
        &[("final", &residual(&tf.x_after))],
    )?;
    s.figures.push(FigureRef::new(
        fig,
        "Displacement residual (measured − simulated) of the base (grey band) and of the \
         final model.",
    ));
    let mut sections = vec![s];
    sections.extend(record_sections(data, &[], out)?);
    let mut intro = vec![format!(
        "{} S(μ) {:.4} → {:.4} mm².",
        crate::verdict::discover_verdict(
            &found.effects,
            found.gap_before * 1e3,
            found.gap_after * 1e3,
            found.noise_floor * 1e3,
            "mm",
        ),
        tf.s_before_mm2,
        tf.s_after_mm2,
    )];
    intro.extend(score.map(|v| format!("Beside the held-out cycles, {}.", v.summary("mm", 1e3))));
    write_report(
        &format!("Discovery: {}", exp.path.display()),
        intro,
        sections,
        out,
    )
}
