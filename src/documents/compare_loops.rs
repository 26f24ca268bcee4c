//! What `compare` says about regime boundaries and hysteresis loops, beside the force errors:
//! which rule placed each boundary, the per-regime energy and loop metrics of the measurement
//! and of every model, the rankings on those metrics with the test behind each, and the
//! per-cycle table `cycles.csv` (one row per cycle and source: the measurement, then each
//! model's force on the measured kinematics).
//!
//! The on-fraction (duty) is explained where it is shown: the share of the cycle in which the
//! force is *on*, |F| above the on-threshold (3 σ of the force noise, at least 0.05 N), with lone
//! noise samples ignored and gaps shorter than 5 % of the cycle bridged — 1 for a damper, small
//! for impact spikes with zero force between them.

use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;
use stf_core::regimes::{Classification, Comparison, CycleFeatures, MetricRanking, Regime};

use crate::digits::{csv_number, csv_optional, fixed};
use crate::report::Table;
use crate::verdict::{not_tested, tested};
use crate::writing::write_atomic;
use stf_study::param_units::in_record_units;
use stf_study::shown_units::ShownUnits;

/// The on-fraction in words, for reports.
pub const DUTY_EXPLAINED: &str = "On-fraction (duty): the share of each cycle in which the force is on, |F| above the on-threshold (3 σ of the force noise, at least 0.05 N), lone noise samples ignored and gaps under 5 % of the cycle bridged; 1 for a damper, small for spikes with zero force between them.";

pub use stf_study::compare::{boundary_notes, BoundaryNote};

/// One line per boundary for compare.md and the report (and one saying a boundary is absent).
pub fn boundary_lines(c: &Classification) -> Vec<String> {
    let mut lines: Vec<String> = boundary_notes(c)
        .iter()
        .map(|n| {
            let what = if n.boundary == "pre_resonance" {
                "pre-resonance → resonance"
            } else {
                "resonance → post-resonance"
            };
            format!(
                "{what} at ω = {:.2} ± {:.2} rad/s, placed by `{}`: {}",
                n.omega,
                n.uncertainty,
                serde_json::to_value(n.rule)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_string))
                    .unwrap_or_default(),
                n.explanation
            )
        })
        .collect();
    if !c.no_stf && c.boundaries.resonance_post.is_none() {
        lines.push("no resonance → post-resonance boundary: after the resonance the force never becomes on–off (zero for at least the stated share of a cycle) nor falls back to negligible".into());
    }
    lines
}

/// The units of the energy per cycle (a thousandth of force × x), of c_eq (force per
/// velocity) and of the peak force on a record shown in `units`: mJ, N·s/m and N for the
/// trolley; on a record in volts, the record's own (mN·V, N·s/V and N for x in volts).
fn loop_units(units: &ShownUnits) -> (String, String, &'static str) {
    let energy = if units.x_si == "m" && units.force_si == "N" {
        "mJ".to_string()
    } else {
        format!("m{}", in_record_units("N·m", units))
    };
    (energy, in_record_units("N·s/m", units), units.force_si)
}

/// Per-regime energy and loop metrics: measured, then each model (`labels` with
/// `comparisons`), in the record's units (`units`).
pub fn energy_table(labels: &[&str], comparisons: &[Comparison], units: &ShownUnits) -> Table {
    let (energy, c_eq, force) = loop_units(units);
    let cell = |c: &Comparison, r: Regime, model: bool| {
        c.per_regime.get(r).map_or("—".to_string(), |m| {
            let pick = |measured: f64, modelled: f64| if model { modelled } else { measured };
            let px = pick(m.measured_phase_x, m.model_phase_x);
            let phase = if px.is_finite() {
                format!("{px:.0}°")
            } else {
                "no phase".to_string()
            };
            format!(
                "{} {energy} · c_eq {} · {phase} · duty {} · {} {force}",
                fixed(pick(m.measured_energy, m.model_energy) * 1e3, 2),
                fixed(pick(m.measured_c_eq, m.model_c_eq), 1),
                fixed(pick(m.measured_duty, m.model_duty), 2),
                fixed(pick(m.measured_peak_force, m.model_peak_force), 2)
            )
        })
    };
    let row = |label: &str, c: &Comparison, model: bool| {
        let cells = Regime::ALL.iter().map(|&r| cell(c, r, model));
        std::iter::once(label.to_string()).chain(cells).collect()
    };
    let measured = comparisons.first().map(|c| row("measured", c, false));
    let models = labels.iter().zip(comparisons).map(|(l, c)| row(l, c, true));
    let rows = measured.into_iter().chain(models).collect();
    let columns = ["source", "pre-resonance", "resonance", "post-resonance"];
    let caption = format!(
        "Per regime, the mean per cycle of: energy dissipated ∮F dx (the F–x loop's area) in \
         {energy}, equivalent viscous damping c_eq = ∮F dx/(π·ω·X²) in {c_eq}, the phase of the \
         force's fundamental against x (90°: a damper, 0°: a spring), on-fraction and peak \
         force in {force}."
    );
    Table::new(caption, &columns).with_rows(rows)
}

/// One line per loop metric: the best model overall and in each regime, with the test.
pub fn ranking_lines(rankings: &[MetricRanking]) -> Vec<String> {
    rankings
        .iter()
        .map(|m| {
            let mut line = format!(
                "by {} ({}): best over the regimes {}",
                m.metric.name(),
                m.criterion,
                m.overall.first().map_or("—", |s| s.model.as_str())
            );
            for r in Regime::ALL {
                if let Some(rank) = m.per_regime.get(r) {
                    let best = rank.scores.first().map_or("—", |s| s.model.as_str());
                    let regime = r.name().replace('_', "-");
                    match &rank.test {
                        Some(t) if !tested(t) => {
                            line.push_str(&format!("; {regime} {}", not_tested(t.cycles)));
                        }
                        Some(t) => line.push_str(&format!(
                            "; {regime} {best}, paired z {:.1} against {} over {} cycles",
                            t.z, t.runner_up, t.cycles
                        )),
                        None => line.push_str(&format!("; {regime} {best}")),
                    }
                }
            }
            line
        })
        .collect()
}

/// The loop rankings (bullets) and the per-regime energy table, for compare.md.
pub fn write_markdown(md: &mut String, rankings: &[MetricRanking], energy: &Table) {
    for line in ranking_lines(rankings) {
        md.push_str(&format!("- {line}\n"));
    }
    md.push_str(&format!("\n{}\n\n{DUTY_EXPLAINED}\n\n", energy.caption));
    md.push_str(&format!(
        "| {} |\n|---|---|---|---|\n",
        energy.columns.join(" | ")
    ));
    for row in &energy.rows {
        md.push_str(&format!("| {} |\n", row.join(" | ")));
    }
    md.push('\n');
}

/// A row of `cycles.csv`.
#[derive(Serialize)]
struct CycleRow<'a> {
    source: &'a str,
    cycle: usize,
    regime: &'static str,
    #[serde(serialize_with = "csv_number")]
    t_mid_s: f64,
    #[serde(serialize_with = "csv_number")]
    omega_rad_s: f64,
    #[serde(serialize_with = "csv_number")]
    amplitude_m: f64,
    #[serde(serialize_with = "csv_number")]
    energy_j: f64,
    #[serde(serialize_with = "csv_number")]
    c_eq_ns_m: f64,
    #[serde(serialize_with = "csv_number")]
    phase_x_deg: f64,
    #[serde(serialize_with = "csv_number")]
    phase_v_deg: f64,
    #[serde(serialize_with = "csv_number")]
    duty: f64,
    #[serde(serialize_with = "csv_number")]
    peak_force_n: f64,
    #[serde(serialize_with = "csv_number")]
    rms_force_n: f64,
    #[serde(serialize_with = "csv_optional")]
    force_rms_error_n: Option<f64>,
}

fn row<'a>(
    source: &'a str,
    i: usize,
    regime: Regime,
    f: &CycleFeatures,
    err: Option<f64>,
) -> CycleRow<'a> {
    CycleRow {
        source,
        cycle: i,
        regime: regime.name(),
        t_mid_s: f.t_mid,
        omega_rad_s: f.omega,
        amplitude_m: f.amplitude,
        energy_j: f.energy,
        c_eq_ns_m: f.c_eq,
        phase_x_deg: f.phase_x,
        phase_v_deg: f.phase_v,
        duty: f.duty,
        peak_force_n: f.f_peak,
        rms_force_n: f.f_rms,
        force_rms_error_n: err,
    }
}

/// Write `cycles.csv` (the measured regime of each cycle on every row) atomically.
pub fn write_cycles_csv(
    path: &Path,
    measured: &Classification,
    labels: &[&str],
    comparisons: &[Comparison],
) -> Result<()> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for (i, f) in measured.features.iter().enumerate() {
        w.serialize(row("measured", i, measured.labels[i], f, None))?;
    }
    for (label, c) in labels.iter().zip(comparisons) {
        for (i, f) in c.model_features.iter().enumerate() {
            w.serialize(row(
                label,
                i,
                measured.labels[i],
                f,
                c.cycle_force_rms_error.get(i).copied(),
            ))?;
        }
    }
    let bytes = w.into_inner().context("cannot build cycles.csv")?;
    write_atomic(path, &bytes)
}
