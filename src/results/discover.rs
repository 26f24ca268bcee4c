//! A discovery's results folder, written from the study's typed result ([`Discovered`];
//! `stf-lab discover EXP.toml --out DIR` and campaign units): where the base model and the
//! measurement disagree, the effects named and added, and the gap shrinking.
//!
//! Candidates are the effects of docs/ARCHITECTURE.md §5 (the built-ins `viscous`, `power_law`,
//! `added_mass`, `yield`, `wall_impact`, `cubic_stiffness`, `maxwell`, `jamming_on_off`,
//! `bouc_wen`, `linear_spring`) not already in the base, plus any scripts `[discover]
//! candidates` lists. Writes
//! `DIR/discovery.json` (`effects`, `gap_before`, `gap_after`, the steps with every candidate's
//! scores, and the final model as an experiment entry), a report and figures. A record
//! without `f_stf` (or `[discover] level = "trajectory"`) is discovered at trajectory level,
//! along the same path: what differs is the core level ([`discover_force`] or
//! [`discover_trajectory`] with the refitted oscillator), the signal and unit
//! ([`FitLevel::shown`]), the oscillator's entry and the figures ([`Drawn`]).

use std::path::Path;

use anyhow::Result;
use rayon::prelude::*;
use stf_core::discovery::Discovery;
use stf_study::discover::Discovered;

use crate::documents::frequency_figure::{response_of, swept_section};
use crate::documents::standard_report::{record_sections, write_report};
use crate::experiment::{DiscoverSpec, Experiment, FitLevel};
use crate::fitting::FitData;
use crate::param_table::rows_of;
use crate::report::{
    measured_vs_model, FigureRef, Quantity, Section, Table, DISPLACEMENT_MM,
    DISPLACEMENT_RESIDUAL_MM, STF_FORCE, STF_FORCE_RESIDUAL,
};
use crate::say;
use crate::validation::DiscoveryScore;
use crate::writing::{write_atomic, write_json};

/// Write the discovery's results into `out` (discovery.json, discovered.csv and, with
/// `[output] report`, the report) and print its summary.
pub fn write(exp: &Experiment, found: &Discovered, out: &Path) -> Result<()> {
    let (doc, entries) = found.json(exp)?;
    write_json(&out.join("discovery.json"), &doc)?;
    // The record-long CSV and the report are independent files: written in parallel.
    let csv = || write_atomic(&out.join("discovered.csv"), &found.discovered_csv()?);
    let drawn = || match exp.output.report {
        true => report(exp, found, out),
        false => Ok(()),
    };
    let (csv, drawn) = rayon::join(csv, drawn);
    csv?;
    drawn?;
    say!("{}", found.verdict().text);
    print_summary(
        &found.spec,
        &found.data,
        &found.found,
        found.score.as_ref(),
        (&entries, found.wall_s),
    );
    Ok(())
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
    let (unit, scale) = data.shown();
    let effects = if found.effects.is_empty() {
        "none".to_string()
    } else {
        found.effects.join(", ")
    };
    let summary = match &found.trajectory {
        None => {
            say!(
                "base `{}`: gap {:.4} {unit}; {}",
                spec.base_text(),
                found.gap_before * scale,
                found.where_before.summary
            );
            format!(
                "effects: {effects}; gap {:.4} {unit} → {:.4} {unit} (noise floor {:.4} {unit}) \
                 in {wall:.1} s",
                found.gap_before * scale,
                found.gap_after * scale,
                found.noise_floor * scale,
            )
        }
        Some(tf) => format!(
            "effects: {effects}; S {:.4} → {:.4} {} (noise floor {:.4} {unit}) in {wall:.1} s",
            tf.s_before_mm2,
            tf.s_after_mm2,
            data.units.x_squared,
            found.noise_floor * scale,
        ),
    };
    let held_out = held_out_and_validation(
        (found.holdout_cycles, data.words().cycles),
        score,
        unit,
        scale,
    );
    for step in &found.steps {
        say!("  {}", step.verdict);
    }
    say!("{summary}");
    say!("  {held_out}");
    let rows = rows_of(
        "final",
        &found.final_fit,
        Some(found.final_model.as_ref()),
        &[],
        &data.units,
    );
    say!(
        "final model `{}`: {}",
        found.final_model_name,
        crate::results::shown::values_line(&rows)
    );
    if let Some(eq) = final_equation(found) {
        say!("  {eq}");
    }
    say!(
        "final model, as an experiment entry:\n{}{}",
        entries.0,
        entries.1
    );
}

/// The final force as an equation (discovery.json's `final_model.equation`).
fn final_equation(found: &Discovery) -> Option<String> {
    crate::equation::force_equation(&*found.final_model, &found.final_params)
}

/// The held-out cycles every step was scored on and, with `[validate]`, the base's and the
/// final model's errors on the validation record, in one sentence (errors shown in `unit`,
/// `scale` from SI).
fn held_out_and_validation(
    (holdout_cycles, cycles): (usize, &str),
    score: Option<&DiscoveryScore>,
    unit: &str,
    scale: f64,
) -> String {
    let held_out = format!("held out: {holdout_cycles} {cycles} of the record");
    match score {
        Some(score) => format!("{held_out}; {}", score.summary(unit, scale)),
        None => held_out,
    }
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
        "Residual (measured − model) of the base (grey) and of the final model.",
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
        "Displacement residual (measured − simulated) of the base (grey) and of the \
         final model.",
    ),
};

/// The report of a discovery: its notes, the steps' tables (force level), the measured
/// signal against the base and the final model and their residuals (in the level's unit),
/// the regime windows (force level) and the record's sections.
fn report(exp: &Experiment, discovered: &Discovered, out: &Path) -> Result<()> {
    let (data, found) = (&discovered.data, &discovered.found);
    let score = discovered.score.as_ref();
    let dir = out.join("figures");
    crate::writing::atomic::ensure_dir(&dir)?;
    let (unit, scale) = data.shown();
    let drawn = match data.level {
        FitLevel::Force => &FORCE_DRAWN,
        FitLevel::Trajectory => &TRAJECTORY_DRAWN,
    };
    let shown = |v: &[f64]| v.iter().map(|v| v * scale).collect::<Vec<f64>>();
    let target = data.target();
    let (before, after) = discovered.modelled();
    let mut s = Section::new(drawn.title);
    // The notes are the base's gap, each step's verdict and the final gap, in order.
    s.paragraphs.extend(found.notes.iter().cloned());
    s.paragraphs.push(format!(
        "{}.",
        held_out_and_validation(
            (found.holdout_cycles, data.words().cycles),
            score,
            unit,
            scale
        )
    ));
    let tables = found
        .steps
        .iter()
        .enumerate()
        .map(|(i, step)| step_table(i, step, (unit, scale)));
    s.tables.extend(tables);
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
    // Drawn in parallel (each its own file, joined in order): drawing and compressing a
    // figure of the whole record is about a tenth of a short discovery.
    let drawn_figures = figures
        .into_par_iter()
        .map(|((name, quantity, caption), measured, curves)| {
            let quantity = quantity.in_units(&data.units);
            let fig = measured_vs_model(&dir, name, quantity, &data.record.t, &measured, &curves)?;
            Ok(FigureRef::new(fig, caption).zoomable())
        })
        .collect::<Result<Vec<_>>>()?;
    s.figures.extend(drawn_figures);
    let rows = rows_of(
        "final",
        &found.final_fit,
        Some(found.final_model.as_ref()),
        &[],
        &data.units,
    );
    let title = format!("Final model: {}", found.final_model_name);
    let fits = [("final", &found.final_fit)];
    let equations: Vec<(&str, String)> = final_equation(found)
        .map(|eq| ("final", eq))
        .into_iter()
        .collect();
    let results =
        crate::documents::results_table::results_section(&title, &equations, &rows, &fits);
    let mut sections = vec![results, s];
    // The regime windows, the frequency response and the record's figures are independent
    // files: drawn in parallel, joined in the report's order.
    let regimes = || match data.level {
        FitLevel::Force => {
            let curves = [("base", before.as_slice()), ("final", after.as_slice())];
            crate::documents::regime_figures::regime_section(exp, data, &curves, &[], out)
        }
        FitLevel::Trajectory => Ok(None),
    };
    let swept = || {
        let final_response = match data.level {
            FitLevel::Trajectory => response_of(data, "final", &after),
            FitLevel::Force => None,
        };
        swept_section(exp, data, final_response.into_iter().collect(), out)
    };
    let ((regimes, swept), record) = rayon::join(
        || rayon::join(regimes, swept),
        || record_sections(data, &[], out),
    );
    sections.extend(regimes?);
    sections.extend(swept?);
    sections.extend(record?);
    let mut intro = vec![discovered.verdict().text];
    intro.extend(score.map(|v| {
        format!(
            "Beside the held-out {}, {}.",
            data.words().cycles,
            v.summary(unit, scale)
        )
    }));
    write_report(
        &format!("Discovery: {}", exp.path.display()),
        intro,
        sections,
        out,
    )
}

/// The table of step `i`'s candidates, RMS in `unit` (`scale` from SI).
fn step_table(i: usize, step: &stf_core::discovery::Step, (unit, scale): (&str, f64)) -> Table {
    let caption = format!("Step {}: candidates added to `{}`", i + 1, step.current);
    let rms = format!("held-out RMS, {unit}");
    let columns = [
        "candidate",
        rms.as_str(),
        "ΔBIC",
        "paired z (units)",
        "explains of the excess",
        "significant",
    ];
    let rows = step.candidates.iter().map(|c| {
        vec![
            c.name.clone(),
            format!("{:.5}", c.holdout_rms * scale),
            format!("{:.1}", c.delta_bic),
            format!("{:.1} ({})", c.gain_z, c.effective_n),
            format!("{} %", crate::digits::fixed(100.0 * c.explained_share, 0)),
            crate::documents::standard_report::yes_no(c.significant),
        ]
    });
    Table::new(caption, &columns).with_rows(rows.collect())
}
