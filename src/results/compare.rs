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
use stf_study::rig_words::RigWords;
use stf_study::shown_units::ShownUnits;

use crate::documents::compare_markdown::{compare_markdown, duty_meaning};
use crate::documents::frequency_figure::{frf_curve, regime_changes};
use crate::documents::standard_report::{frequency_section, record_sections, write_report};
use crate::experiment::Experiment;
use crate::fitting::FitData;
use crate::outputs::compare_csv;
use crate::report::{regime_errors, FigureRef, FrfCurve, Section, Table};
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
    let words = data.words();
    say!("{}", crate::verdict::compare_verdict(c, data.words()));
    say!(
        "compared {} model(s) on {} {} of {} (noise floor σ = {:.4} {}); relative force RMS \
         error {}, lower is better:",
        c.fits.len(),
        c.measured.labels.len(),
        words.cycles,
        data.record.source,
        c.measured.noise_sigma,
        data.units.force_si,
        if words.regimes {
            "per regime"
        } else {
            "over the whole record"
        }
    );
    let name_width = c
        .fits
        .iter()
        .map(|f| f.label.chars().count())
        .max()
        .unwrap_or(5);
    let heads = ["pre-res.", "resonance", "post-res.", "mean"];
    let shown = |cells: &[String]| -> String {
        if words.regimes {
            cells
                .iter()
                .map(|c| format!("{c:>9}"))
                .collect::<Vec<_>>()
                .join(" ")
        } else {
            format!("{:>12}", cells[3])
        }
    };
    let heads: Vec<String> = if words.regimes {
        heads.iter().map(|h| h.to_string()).collect()
    } else {
        vec![
            String::new(),
            String::new(),
            String::new(),
            words.all.to_string(),
        ]
    };
    say!(
        "  {:<name_width$}  {}  fitted values",
        "model",
        shown(&heads)
    );
    let cell = |m: Option<&RegimeMetrics>| {
        m.map_or("—".to_string(), |m| {
            format!("{:.3}", m.relative_rms_error)
        })
    };
    let rows = per_regime(c, cell)
        .into_iter()
        .zip(&c.fits)
        .zip(&c.comparisons);
    for (((label, mut cells), f), cmp) in rows {
        // Ranked by the mean over the regimes; a record without regimes by the whole record.
        cells.push(if words.regimes {
            mean_cell(c, label)
        } else {
            format!("{:.3}", cmp.overall.relative_rms_error)
        });
        let rows = crate::param_table::rows_of_fits(std::slice::from_ref(f), &data.units);
        say!(
            "  {label:<name_width$}  {}  {}",
            shown(&cells),
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
    let changes = regime_changes(&c.measured.boundaries);
    // A record without a rotor speed (a shaker) has no frequency response to draw.
    let frequency = match data.kinematics.omega {
        Some(_) => Some(frequency_section(
            "frequency_response",
            &curves,
            changes,
            data.units.x,
            out,
        )?),
        None => None,
    };
    let fits: Vec<(&str, &stf_core::fit::FitResult)> = c
        .fits
        .iter()
        .map(|f| (f.label.as_str(), &f.result))
        .collect();
    let rows = crate::param_table::rows_of_fits(&c.fits, &data.units);
    let equations = crate::results::fit::equations_of(&c.fits);
    let results =
        crate::documents::results_table::results_section("Results", &equations, &rows, &fits);
    let models = if data.words().regimes {
        regimes_section(c, md, &data.units, out)?
    } else {
        whole_record_section(c, md, &data.units)
    };
    let mut sections = vec![results, models];
    sections.extend(frequency);
    let forces: Vec<(&str, &[f64])> = c
        .fits
        .iter()
        .map(|f| (f.label.as_str(), f.fitted.as_slice()))
        .collect();
    // The record's figures and the regime windows are independent files: drawn in parallel.
    let (record, regimes) = rayon::join(
        || record_sections(data, &c.fits, out),
        || crate::documents::regime_figures::regime_section(exp, data, &forces, &[], out),
    );
    sections.extend(record?);
    sections.extend(regimes?);
    let verdict = crate::verdict::compare_verdict(c, data.words());
    let record = format!(
        "{} {} of {}; noise floor σ = {:.4} {}.",
        c.measured.labels.len(),
        data.words().cycles,
        data.record.source,
        c.measured.noise_sigma,
        data.units.force_si
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
fn regimes_section(c: &Compared, md: &str, units: &ShownUnits, out: &Path) -> Result<Section> {
    let mut regimes = Section::new("Models regime by regime");
    regimes.paragraphs = md
        .lines()
        .filter(|l| l.starts_with("- "))
        .map(|l| l.trim_start_matches("- ").replace("**", ""))
        .collect();
    regimes.paragraphs.push(duty_meaning(
        c.measured.on_threshold,
        RigWords::ROTOR,
        units.force_si,
    ));
    regimes.tables.push(errors_table(c));
    regimes
        .paragraphs
        .push(crate::documents::compare_loops::DUTY_EXPLAINED.into());
    regimes
        .tables
        .push(crate::documents::compare_loops::energy_table(
            &c.labels(),
            &c.comparisons,
            units,
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

/// The report's "Models over the whole record" of a record without a rotor: compare.md's
/// bullets and each model's relative force RMS error (duty error) over the whole record.
fn whole_record_section(c: &Compared, md: &str, units: &ShownUnits) -> Section {
    let mut s = Section::new("Models over the whole record");
    s.paragraphs = md
        .lines()
        .filter(|l| l.starts_with("- "))
        .map(|l| l.trim_start_matches("- ").replace("**", ""))
        .collect();
    s.paragraphs.push(duty_meaning(
        c.measured.on_threshold,
        RigWords::ROTORLESS,
        units.force_si,
    ));
    let rows = c
        .fits
        .iter()
        .zip(&c.comparisons)
        .map(|(f, cmp)| {
            let o = &cmp.overall;
            vec![
                f.label.clone(),
                format!("{:.3} ({:.2})", o.relative_rms_error, o.duty_error),
            ]
        })
        .collect();
    let caption = "Relative force RMS error over the whole record (on–off duty error in \
                   brackets); lower is better.";
    s.tables
        .push(Table::new(caption, &["model", "whole record"]).with_rows(rows));
    s
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
