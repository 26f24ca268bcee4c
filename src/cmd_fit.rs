//! `stf-lab fit EXP.toml --out DIR`: calibrate every model of the experiment, or run the
//! oscillator identification stages of `[[identify]]`.
//!
//! Writes `DIR/fit.json` (for each model: `name`, `params`, `rms`, standard errors, AIC/BIC,
//! convergence, the noise floor, `warnings` …; with `[validate]`, `validation_rms` and
//! `validation`, its error on the second record, [`crate::validation`]) and `DIR/fitted.csv` (the measured signal and
//! each model's fit). The summary on the terminal prints each model's warnings under its line
//! ([`stf_core::fit::fit_warnings`]: not converged, residual above the noise floor, a
//! parameter on a bound or not determined, two parameters not told apart).

use std::path::Path;

use anyhow::{Context, Result};
use stf_core::data::kinematics::Kinematics;
use stf_core::fit::{
    fit_warnings, FitResult, FitWarning, NoiseFloor, TrajectoryData, TrajectoryFit,
};

use crate::experiment::{Experiment, FitLevel, StageSpec};
use crate::fitting::{
    estimate_line, fit_all, load_data, oscillator_fit, system_param, FitData, ModelFit,
};
use crate::identify_report::{system_line, write_identification_report, StageOutcome};
use crate::outputs::columns_csv::Columns;
use crate::outputs::fit_json::FitJson;
use crate::outputs::identification_json::IdentificationJson;
use crate::param_table::{rows_of, rows_of_fits, write_params_csv, ParamRow};
use crate::progress::{fit_message, Progress};
use crate::say;
use crate::validation::ValidationRecord;
use crate::writing::results_dir::{wrote_line, ResultsDir};
use crate::writing::write_json;
use stf_core::physics::oscillator_params::{OscParam, OscillatorParams};
use stf_core::regimes::Regime;

/// Run `stf-lab fit` on an experiment loaded (from its file, or a campaign's unit: its
/// record set with [`Experiment::with_data_file`]): the results are built in a staging
/// folder and swapped in as a whole ([`ResultsDir`]).
pub fn run_experiment(mut exp: Experiment, out: &Path, force: bool, quiet: bool) -> Result<()> {
    let progress = Progress::new(quiet);
    let mut files = vec!["fit.json", "params.csv"];
    let results = if !exp.identify.is_empty() {
        if let Some(spec) = &exp.validate {
            let msg = "scores the fits of `[[models]]`; `[[identify]]` stages are not scored";
            return Err(spec.error("validate", msg));
        }
        let results = ResultsDir::begin(out, force)?;
        identify(&exp, results.path(), &progress)?;
        results
    } else {
        let data = load_data(&mut exp)?;
        let validation = crate::validation::load(&exp, &data)?;
        let results = ResultsDir::begin(out, force)?;
        write_fits(&exp, &data, validation.as_ref(), results.path(), &progress)?;
        files.push("fitted.csv");
        results
    };
    results.commit()?;
    say!("{}", wrote_line(out, &files, exp.output.report));
    Ok(())
}

/// Fit every model of `exp` to `data`, print the summary and write the results into `out`.
fn write_fits(
    exp: &Experiment,
    data: &FitData,
    validation: Option<&ValidationRecord>,
    out: &Path,
    progress: &Progress,
) -> Result<()> {
    if let Some(line) = estimate_line(data) {
        say!("{line}");
    }
    let mut fits = fit_all(exp, data, progress)?;
    if let Some(rec) = validation {
        crate::validation::score_fits(&mut fits, rec);
    }

    write_json(&out.join("fit.json"), &FitJson::new(&exp.path, data, &fits))?;
    write_params_csv(&out.join("params.csv"), &rows_of_fits(&fits))?;
    fitted_columns(data, &fits).write(&out.join("fitted.csv"))?;

    print_summary(data, &fits);
    if let Some(rec) = validation {
        print_validation(rec, &fits);
    }
    if exp.output.report {
        write_fit_report(exp, data, validation, &fits, out)?;
    }
    Ok(())
}

/// `fitted.csv`: t, the measured signal (`f_stf` or `x`) and each model's fit of it
/// (`f_stf_<label>` or `x_<label>`).
fn fitted_columns<'a>(data: &'a FitData, fits: &'a [ModelFit]) -> Columns<'a> {
    let measured = data.level.signal().column;
    let columns = Columns::new()
        .with("t", &data.record.t)
        .with(measured, data.target());
    fits.iter().fold(columns, |c, f| {
        c.with(format!("{measured}_{}", f.label), &f.fitted)
    })
}

/// The fit's report (report.html, report.md, figures/) in `out`.
fn write_fit_report(
    exp: &Experiment,
    data: &FitData,
    validation: Option<&ValidationRecord>,
    fits: &[ModelFit],
    out: &Path,
) -> Result<()> {
    let level = data.level;
    let mut sections = Vec::new();
    if let Some(rec) = validation {
        sections.push(crate::standard_report::validation_section(rec, fits, out)?);
    }
    sections.extend(crate::standard_report::record_sections(data, fits, out)?);
    let forces: Vec<(&str, &[f64])> = match level {
        FitLevel::Force => fits
            .iter()
            .map(|f| (f.label.as_str(), f.fitted.as_slice()))
            .collect(),
        FitLevel::Trajectory => Vec::new(),
    };
    sections.extend(crate::regime_figures::regime_section(
        exp, data, &forces, out,
    )?);
    let mut intro = vec![
        crate::verdict::fit_verdict(fits, level),
        format!(
            "stf-lab fitted {} model(s) of {} to {}.",
            fits.len(),
            exp.path.display(),
            data.record.source
        ),
    ];
    if let Some(rec) = validation {
        intro.push(crate::standard_report::validation_intro(rec, fits));
    }
    let warned = fits.iter().filter(|f| !f.warnings.is_empty()).count();
    if warned > 0 {
        intro.push(format!(
            "⚠ {warned} of the {} fits carry warnings: see the box under Fits.",
            fits.len()
        ));
    }
    crate::standard_report::write_report(
        &format!("Fit: {}", exp.path.display()),
        intro,
        sections,
        out,
    )?;
    Ok(())
}

/// The terminal summary: one line per model, its warnings under it.
fn print_summary(data: &FitData, fits: &[ModelFit]) {
    let (unit, scale) = data.level.shown();
    say!(
        "fitted {} model(s) at {} level on {} samples of {}",
        fits.len(),
        crate::outputs::level_name(data.level),
        data.record.len(),
        data.record.source
    );
    if let Some(drive) = &data.kinematics.drive {
        say!("  {drive}");
    }
    for f in fits {
        let params: Vec<String> = f
            .result
            .params
            .iter()
            .filter(|p| !p.fixed)
            .map(crate::digits::param_with_error)
            .collect();
        say!(
            "  {:<24} rms {:.4} {unit}  AIC {:.1}  {}{}",
            f.label,
            f.result.rms * scale,
            f.result.aic,
            params.join(", "),
            if f.result.convergence.converged() {
                ""
            } else {
                "  (did not converge)"
            }
        );
        print_warnings(&f.warnings);
    }
}

/// The validation block: each model's error on the `[validate]` record, per regime where
/// the record has them.
fn print_validation(rec: &ValidationRecord, fits: &[ModelFit]) {
    let (unit, scale) = rec.data.level.shown();
    say!(
        "validation on {} ({} samples), fitted parameters held{}:",
        rec.spec.given,
        rec.data.record.len(),
        if rec.data.level == FitLevel::Trajectory {
            ", initial state as in the fit"
        } else {
            ""
        }
    );
    for f in fits {
        let Some(v) = &f.validation else { continue };
        let Some(score) = &v.score else {
            say!(
                "  {:<24} not scored: {}",
                f.label,
                v.error.as_deref().unwrap_or("?")
            );
            continue;
        };
        let regimes: Vec<String> = v
            .per_regime
            .iter()
            .flat_map(|p| Regime::ALL.map(|r| p.get(r).map(|e| (r, e.rms))))
            .flatten()
            .map(|(r, rms)| format!("{} {:.4}", r.name(), rms * scale))
            .collect();
        say!(
            "  {:<24} rms {:.4} {unit} ({:.3} of the measured RMS){}",
            f.label,
            score.rms * scale,
            score.normalised,
            if regimes.is_empty() {
                String::new()
            } else {
                format!("; {}", regimes.join(", "))
            }
        );
    }
}

/// Each warning on its own line, indented under the model's line.
fn print_warnings(warnings: &[FitWarning]) {
    for w in warnings {
        say!("      warning: {w}");
    }
}

/// The terminal line of identification stage `i`, its warnings under it.
fn print_stage(i: usize, stage: &StageSpec, result: &FitResult, warnings: &[FitWarning]) {
    say!(
        "stage {} ({}): S(μ) = {:.4} mm², {}{}",
        i + 1,
        stage.data.display(),
        result.s_mm2.unwrap_or(f64::NAN),
        result
            .params
            .iter()
            .map(crate::digits::param_with_error)
            .collect::<Vec<_>>()
            .join(", "),
        if result.convergence.converged() {
            ""
        } else {
            " (did not converge)"
        }
    );
    print_warnings(warnings);
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
fn identify(exp: &Experiment, out: &Path, progress: &Progress) -> Result<()> {
    let mut system = exp.system;
    let mut outcomes = Vec::new();
    for (i, stage) in exp.identify.iter().enumerate() {
        stage_start(exp, i, &mut system);
        let record = crate::fitting::read_record(exp, &stage.data)?;
        let k = Kinematics::from_record(&record, &exp.kinematics)
            .with_context(|| format!("cannot derive the kinematics of {}", stage.data.display()))?;
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
        let observer = |p: stf_core::fit::FitProgress| bar.set_message(fit_message(&p, "mm", 1e3));
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
        bar.finish_and_clear();
        crate::interrupt::finished_step(format!("identification stage {}", i + 1));
        for &param in &stage.free {
            if let Some(v) = result.value(param.name()) {
                system[param] = v;
            }
        }
        let floor = NoiseFloor::displacement(k.sigma_x);
        let warnings = fit_warnings(&result, &free, Some(&floor));
        print_stage(i, stage, &result, &warnings);
        let values: Vec<f64> = result.params.iter().map(|p| p.value).collect();
        outcomes.push(StageOutcome {
            record: stage.data.display().to_string(),
            simulated: fit.predict(&data, &values).unwrap_or_default(),
            t: record.t.clone(),
            x: record.x.clone(),
            result,
            floor,
            warnings,
        });
    }
    finish_identification(exp, out, &system, &outcomes)
}

/// Write the identification's fit.json, params.csv and report into `out`.
fn finish_identification(
    exp: &Experiment,
    out: &Path,
    system: &OscillatorParams,
    outcomes: &[StageOutcome],
) -> Result<()> {
    let doc = IdentificationJson::new(&exp.path, &exp.identify, outcomes, *system);
    write_json(&out.join("fit.json"), &doc)?;
    let rows: Vec<ParamRow> = outcomes
        .iter()
        .enumerate()
        .flat_map(|(i, o)| rows_of(&format!("stage {}", i + 1), &o.result, None, &o.warnings))
        .collect();
    write_params_csv(&out.join("params.csv"), &rows)?;
    say!("identified system: {}", system_line(system));
    if exp.output.report {
        write_identification_report(&exp.path, outcomes, system, out)?;
    }
    Ok(())
}
