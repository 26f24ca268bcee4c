//! A fit's results folder, written from the study's typed result ([`Fitted`], or an
//! [`Identification`] for the stages of `[[identify]]`): `fit.json` (for each model: `name`,
//! `params`, `rms`, standard errors, AIC/BIC, convergence, the noise floor, `warnings` …; with
//! `[validate]`, `validation_rms` and `validation`, its error on the second record,
//! [`crate::validation`]), `params.csv`, `fitted.csv` (the measured signal and each model's
//! fit) and the report. The summary on the terminal prints each model's warnings under its
//! line ([`stf_core::fit::fit_warnings`]: not converged, residual above the noise floor, a
//! parameter on a bound or not determined, two parameters not told apart).
use std::path::Path;

use anyhow::Result;
use stf_core::fit::{FitResult, FitWarning};
use stf_study::fit::Fitted;
use stf_study::identify::Identification;

use crate::documents::identify_report::{system_line, write_identification_report};
use crate::documents::results_table::results_section;
use crate::experiment::{Experiment, FitLevel, StageSpec};
use crate::fitting::{FitData, ModelFit};
use crate::outputs::identification_json::IdentificationJson;
use crate::param_table::{params_csv, rows_of, rows_of_fits, ParamRow};
use crate::results::shown::values_line;
use crate::say;
use crate::validation::ValidationRecord;
use crate::writing::{write_atomic, write_json};
use stf_core::regimes::Regime;
use stf_study::shown_units::ShownUnits;

/// Write the fit's results into `out` (fit.json, params.csv, fitted.csv and, with
/// `[output] report`, the report) and print its summary.
pub fn write(exp: &Experiment, fitted: &Fitted, out: &Path) -> Result<()> {
    let (data, fits) = (&fitted.data, &fitted.fits);
    write_json(&out.join("fit.json"), &fitted.json(exp))?;
    let params = out.join("params.csv");
    write_atomic(&params, &params_csv(&params, &fitted.param_rows())?)?;
    let csv = fitted.fitted_columns().to_csv()?;
    write_atomic(&out.join("fitted.csv"), &csv)?;

    say!("{}", fitted.verdict().text);
    print_summary(data, fits);
    if let Some(rec) = &fitted.validation {
        print_validation(rec, fits);
    }
    if exp.output.report {
        write_fit_report(exp, fitted, out)?;
    }
    Ok(())
}

/// The fit's report (report.html, report.md, figures/) in `out`.
fn write_fit_report(exp: &Experiment, fitted: &Fitted, out: &Path) -> Result<()> {
    let (data, fits) = (&fitted.data, fitted.fits.as_slice());
    let validation = fitted.validation.as_ref();
    let level = data.level;
    let results: Vec<(&str, &FitResult)> =
        fits.iter().map(|f| (f.label.as_str(), &f.result)).collect();
    let equations = equations_of(fits);
    let rows = fitted.param_rows();
    let mut sections = vec![results_section("Results", &equations, &rows, &results)];
    if let Some(rec) = validation {
        sections.push(crate::documents::standard_report::validation_section(
            rec, fits, out,
        )?);
    }
    let curves: Vec<(&str, &[f64])> = fits
        .iter()
        .map(|f| (f.label.as_str(), f.fitted.as_slice()))
        .collect();
    let (forces, simulated) = match level {
        FitLevel::Force => (curves, Vec::new()),
        FitLevel::Trajectory => (Vec::new(), curves),
    };
    // The frequency response, the record's figures and the regime windows are independent
    // files: drawn in parallel, joined in the report's order.
    let (swept, (record, regimes)) = rayon::join(
        || frequency_response(exp, data, fits, out),
        || {
            rayon::join(
                || crate::documents::standard_report::record_sections(data, fits, out),
                || {
                    crate::documents::regime_figures::regime_section(
                        exp, data, &forces, &simulated, out,
                    )
                },
            )
        },
    );
    sections.extend(swept?);
    sections.extend(record?);
    sections.extend(regimes?);
    let mut intro = vec![
        fitted.verdict().text,
        format!(
            "stf-lab fitted {} model(s) of {} to {}.",
            fits.len(),
            exp.path.display(),
            data.record.source
        ),
    ];
    if let Some(rec) = validation {
        intro.push(crate::documents::standard_report::validation_intro(
            rec, fits,
        ));
    }
    let warned = fits.iter().filter(|f| !f.warnings.is_empty()).count();
    if warned > 0 {
        intro.push(format!(
            "⚠ {warned} of the {} fits carry warnings: see the box under Fits.",
            fits.len()
        ));
    }
    crate::documents::standard_report::write_report(
        &format!("Fit: {}", exp.path.display()),
        intro,
        sections,
        out,
    )?;
    Ok(())
}

/// The frequency response of a swept record with each fitted model's: at trajectory level the
/// fitted displacement itself, at force level the oscillator simulated with the model.
fn frequency_response(
    exp: &Experiment,
    data: &FitData,
    fits: &[ModelFit],
    out: &Path,
) -> Result<Option<crate::report::Section>> {
    use crate::documents::frequency_figure::{response_of, swept_section};
    if data.kinematics.omega.is_none() {
        return Ok(None);
    }
    let models = fits
        .iter()
        .filter_map(|f| match data.level {
            FitLevel::Trajectory => response_of(data, &f.label, &f.fitted),
            FitLevel::Force => stf_study::compare::simulated_response(exp, data, Some(f))
                .ok()
                .map(|r| r.0),
        })
        .collect();
    swept_section(exp, data, models, out)
}

/// Each fit's label with its force as an equation (fit.json's `equation`; none for the bare
/// oscillator).
pub fn equations_of(fits: &[ModelFit]) -> Vec<(&str, String)> {
    fits.iter()
        .filter_map(|f| Some((f.label.as_str(), f.equation()?)))
        .collect()
}

/// The terminal summary: one line per model, its equation and warnings under it.
fn print_summary(data: &FitData, fits: &[ModelFit]) {
    let (unit, scale) = data.shown();
    say!(
        "fitted {} model(s) at {} level on {} samples of {}",
        fits.len(),
        data.level.name(),
        data.record.len(),
        data.record.source
    );
    if let Some(drive) = &data.kinematics.drive {
        say!("  {drive}");
    }
    for f in fits {
        let rows = rows_of_fits(std::slice::from_ref(f), &data.units);
        say!(
            "  {:<24} rms {:.4} {unit}  AIC {:.1}  {}{}",
            f.label,
            f.result.rms * scale,
            f.result.aic,
            values_line(&rows),
            if f.result.convergence.converged() {
                ""
            } else {
                "  (did not converge)"
            }
        );
        if let Some(eq) = f.equation() {
            say!("      {eq}");
        }
        print_warnings(&f.warnings);
    }
}

/// The validation block: each model's error on the `[validate]` record, per regime where
/// the record has them.
fn print_validation(rec: &ValidationRecord, fits: &[ModelFit]) {
    let (unit, scale) = rec.data.shown();
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

/// The terminal line of identification stage `i`, each value with its unit in the record's
/// units, its warnings under it.
fn print_stage(
    i: usize,
    stage: &StageSpec,
    result: &FitResult,
    warnings: &[FitWarning],
    units: &ShownUnits,
) {
    let rows = rows_of(&format!("stage {}", i + 1), result, None, warnings, units);
    say!(
        "stage {} ({}): S(μ) = {:.4} {}, {}{}",
        i + 1,
        stage.data.display(),
        result.s_mm2.unwrap_or(f64::NAN),
        units.x_squared,
        values_line(&rows),
        if result.convergence.converged() {
            ""
        } else {
            " (did not converge)"
        }
    );
    print_warnings(warnings);
}

/// Write the identification's fit.json, params.csv and report into `out`, and print each
/// stage and the oscillator found.
pub fn write_identification(exp: &Experiment, out: &Path, found: &Identification) -> Result<()> {
    let (system, outcomes) = (&found.system, &found.stages);
    let units = ShownUnits::of(&exp.data_layout, FitLevel::Trajectory);
    for (i, (stage, o)) in exp.identify.iter().zip(outcomes).enumerate() {
        print_stage(i, stage, &o.result, &o.warnings, &units);
    }
    let doc = IdentificationJson::new(&exp.path, &exp.identify, outcomes, *system, &units);
    write_json(&out.join("fit.json"), &doc)?;
    let rows: Vec<ParamRow> = outcomes
        .iter()
        .enumerate()
        .flat_map(|(i, o)| {
            let label = format!("stage {}", i + 1);
            rows_of(&label, &o.result, None, &o.warnings, &units)
        })
        .collect();
    let params = out.join("params.csv");
    write_atomic(&params, &params_csv(&params, &rows)?)?;
    say!("identified system: {}", system_line(system, &units));
    if exp.output.report {
        write_identification_report(&exp.path, outcomes, system, &units, out)?;
    }
    Ok(())
}
