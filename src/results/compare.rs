//! A comparison's results folder, written from the study's typed result
//! ([`CompareResult`]; `stf-lab compare EXP.toml --out DIR` and campaign units).
//!
//! The measured record is cut into rotor cycles and each cycle labelled pre-resonance,
//! resonance or post-resonance (`stf_core::regimes`). Each fitted model's force, on the same
//! kinematics, is scored per regime (force RMS error, energy per cycle, on–off duty, peak
//! force, label agreement, boundary error), and the oscillator with the model plugged in is
//! simulated against the record for the resonance peak. Writes `compare.json`, `compare.md`
//! and `compare.csv` (models × regimes; [`crate::outputs::compare_json`],
//! [`crate::outputs::compare_csv`], [`crate::documents::compare_markdown`]). With `[validate]`, each
//! model's `fit` in compare.json carries its error on the second record, as in fit.json.

use std::path::Path;

use anyhow::Result;
use stf_core::regimes::{Comparison, Regime, RegimeMetrics};
use stf_study::compare::{response, simulated_response, CompareResult, Compared};

use crate::documents::compare_markdown::{compare_markdown, duty_meaning};
use crate::documents::standard_report::{frequency_section, record_sections, write_report};
use crate::experiment::Experiment;
use crate::fitting::FitData;
use crate::outputs::compare_csv;
use crate::report::{regime_errors, FigureRef, FrfCurve, FrfRole, RegimeChange, Section, Table};
use crate::say;
use crate::writing::{write_atomic, write_json};

/// Write the comparison's results into `out` (compare.json, compare.csv, cycles.csv,
/// compare.md and, with `[output] report`, the report) and print compare.md.
pub fn write(exp: &Experiment, result: &CompareResult, out: &Path) -> Result<()> {
    let (data, c) = (&result.data, &result.compared);
    write_json(&out.join("compare.json"), &result.json(exp))?;
    let labels = c.labels();
    let rows = compare_csv::rows(&labels, &c.comparisons);
    let csv = out.join("compare.csv");
    write_atomic(&csv, &compare_csv::csv_text(&csv, &rows)?)?;
    crate::documents::compare_loops::write_cycles_csv(
        &out.join("cycles.csv"),
        &c.measured,
        &labels,
        &c.comparisons,
    )?;
    let md = compare_markdown(exp, data, c);
    write_atomic(
        &out.join("compare.md"),
        crate::report::md_text(&md).as_bytes(),
    )?;
    if exp.output.report {
        write_compare_report(exp, data, c, &md, out)?;
    }
    print_summary(result);
    Ok(())
}

/// The terminal summary: the verdict, then each model's relative force RMS error per regime
/// and its fitted values, its warnings under it (compare.md holds the whole comparison).
fn print_summary(result: &CompareResult) {
    let (data, c) = (&result.data, &result.compared);
    say!("{}", crate::verdict::compare_verdict(c));
    say!(
        "compared {} model(s) on {} cycles of {} (noise floor σ = {:.4} N); relative force RMS \
         error per regime, lower is better:",
        c.fits.len(),
        c.measured.labels.len(),
        data.record.source,
        c.measured.noise_sigma
    );
    let name_width = c
        .fits
        .iter()
        .map(|f| f.label.chars().count())
        .max()
        .unwrap_or(5);
    say!(
        "  {:<name_width$}  {:>9} {:>9} {:>9} {:>9}  fitted values",
        "model",
        "pre-res.",
        "resonance",
        "post-res.",
        "mean"
    );
    let cell = |m: Option<&RegimeMetrics>| {
        m.map_or("—".to_string(), |m| {
            format!("{:.3}", m.relative_rms_error)
        })
    };
    for ((label, mut cells), f) in per_regime(c, cell).into_iter().zip(&c.fits) {
        cells.push(mean_cell(c, label));
        let rows = crate::param_table::rows_of_fits(std::slice::from_ref(f));
        say!(
            "  {label:<name_width$}  {:>9} {:>9} {:>9} {:>9}  {}",
            cells[0],
            cells[1],
            cells[2],
            cells[3],
            crate::results::shown::values_line(&rows)
        );
        for w in &f.warnings {
            say!("      warning: {w}");
        }
    }
}

/// The report: regimes table, frequency response, the record and the fits.
fn write_compare_report(
    exp: &Experiment,
    data: &FitData,
    c: &Compared,
    md: &str,
    out: &Path,
) -> Result<()> {
    let mut curves = vec![response(
        "measured",
        &data.record.t,
        &data.record.x,
        data.kinematics.omega.as_deref(),
    )];
    if let Ok((curve, _)) = simulated_response(exp, data, None) {
        curves.push(curve);
    }
    curves.extend(c.responses.iter().flatten().map(|r| r.0.clone()));
    let curves: Vec<FrfCurve> = curves.into_iter().map(frf_curve).collect();
    let change = |b: Option<stf_core::regimes::Boundary>| {
        b.map(|b| RegimeChange {
            omega: b.omega,
            uncertainty: b.uncertainty,
        })
    };
    let changes = [
        change(c.measured.boundaries.pre_resonance),
        change(c.measured.boundaries.resonance_post),
    ];
    let frequency = frequency_section(&curves, changes, out)?;
    let fits: Vec<(&str, &stf_core::fit::FitResult)> = c
        .fits
        .iter()
        .map(|f| (f.label.as_str(), &f.result))
        .collect();
    let rows = crate::param_table::rows_of_fits(&c.fits);
    let equations = crate::results::fit::equations_of(&c.fits);
    let results =
        crate::documents::results_table::results_section("Results", &equations, &rows, &fits);
    let mut sections = vec![results, regimes_section(c, md, out)?, frequency];
    sections.extend(record_sections(data, &c.fits, out)?);
    let forces: Vec<(&str, &[f64])> = c
        .fits
        .iter()
        .map(|f| (f.label.as_str(), f.fitted.as_slice()))
        .collect();
    sections.extend(crate::documents::regime_figures::regime_section(
        exp, data, &forces, out,
    )?);
    let verdict = crate::verdict::compare_verdict(c);
    let record = format!(
        "{} cycles of {}; noise floor σ = {:.4} N.",
        c.measured.labels.len(),
        data.record.source,
        c.measured.noise_sigma
    );
    write_report(
        &format!("Comparison: {}", exp.path.display()),
        vec![verdict, record],
        sections,
        out,
    )
}

/// The report's "Models regime by regime": compare.md's bullets, the error and energy
/// tables and the error of each model in each regime as bars.
fn regimes_section(c: &Compared, md: &str, out: &Path) -> Result<Section> {
    let mut regimes = Section::new("Models regime by regime");
    regimes.paragraphs = md
        .lines()
        .filter(|l| l.starts_with("- "))
        .map(|l| l.trim_start_matches("- ").replace("**", ""))
        .collect();
    regimes
        .paragraphs
        .push(duty_meaning(c.measured.on_threshold));
    regimes.tables.push(errors_table(c));
    regimes
        .paragraphs
        .push(crate::documents::compare_loops::DUTY_EXPLAINED.into());
    regimes
        .tables
        .push(crate::documents::compare_loops::energy_table(
            &c.labels(),
            &c.comparisons,
        ));
    let mut bars = per_regime(c, |m| m.map_or(f64::NAN, |m| m.relative_rms_error));
    for (label, values) in &mut bars {
        values.push(c.mean_error(label).unwrap_or(f64::NAN));
    }
    let fig = regime_errors(
        &out.join("figures"),
        "regime_errors",
        &[
            "pre-resonance",
            "resonance",
            "post-resonance",
            "mean over regimes",
        ],
        &bars,
        "relative force RMS error",
    )?;
    regimes.figures.push(FigureRef::new(
        fig,
        "Relative force RMS error of each model in each regime of the record (lower is better).",
    ));
    Ok(regimes)
}

/// The relative force RMS error (duty error) of each model per regime and overall.
fn errors_table(c: &Compared) -> Table {
    let cell = |m: &RegimeMetrics| format!("{:.3} ({:.2})", m.relative_rms_error, m.duty_error);
    let caption = "Relative force RMS error per regime (on–off duty error in brackets) and its \
                   mean over the regimes, the score the models are ranked by; lower is better.";
    let columns = [
        "model",
        "pre-resonance",
        "resonance",
        "post-resonance",
        "mean over regimes",
    ];
    let rows = per_regime(c, |m| m.map_or("—".to_string(), cell));
    let rows = rows
        .into_iter()
        .map(|(label, cells)| [vec![label.to_string()], cells, vec![mean_cell(c, label)]].concat());
    Table::new(caption, &columns).with_rows(rows.collect())
}

/// The score `label` is ranked by over the regimes ([`Compared::mean_error`]), to 3 decimals.
fn mean_cell(c: &Compared, label: &str) -> String {
    c.mean_error(label)
        .map_or("—".to_string(), |s| format!("{s:.3}"))
}

/// Each model's label with `value` of its metrics in each regime (`None`: no cycle there).
fn per_regime<T>(c: &Compared, value: impl Fn(Option<&RegimeMetrics>) -> T) -> Vec<(&str, Vec<T>)> {
    let values = |cmp: &Comparison| {
        Regime::ALL
            .iter()
            .map(|&r| value(cmp.per_regime.get(r)))
            .collect()
    };
    let models = c.fits.iter().zip(&c.comparisons);
    models
        .map(|(f, cmp)| (f.label.as_str(), values(cmp)))
        .collect()
}

/// A frequency response as the figure draws it: the measured record's, the oscillator's
/// without STF (dashed) or a model's.
fn frf_curve(r: stf_study::compare::Response) -> FrfCurve {
    let role = match r.label.as_str() {
        "measured" => FrfRole::Measured,
        "without STF" => FrfRole::Reference,
        _ => FrfRole::Model,
    };
    FrfCurve {
        label: r.label,
        omega: r.omega,
        x_peak: r.x_peak,
        role,
    }
}
