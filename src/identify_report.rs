//! The report of the source study's identification (`[[identify]]` stages): a verdict
//! paragraph (the identified oscillator, each stage's S(μ) against its noise floor, every
//! warning), the identified parameters with their units, each stage's table, and each stage's
//! measured displacement against the oscillator simulated with the stage's values.

use std::path::Path;

use anyhow::Result;
use stf_core::physics::oscillator_params::{OscParam, OscillatorParams};

use crate::report::{measured_vs_model, milli, FigureRef, Section, Table, DISPLACEMENT_MM};
use crate::standard_report::write_report;

pub use stf_study::identify::StageOutcome;

/// `x` with `digits` significant digits, trailing zeros dropped (`269.935`, `0.0461989`).
fn significant(x: f64, digits: i32) -> String {
    if x == 0.0 || !x.is_finite() {
        return x.to_string();
    }
    let decimals = (digits - 1 - x.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The oscillator's parameters as a readable line: `m 7.65 kg, k 267.9 N/m, …`.
pub fn system_line(system: &OscillatorParams) -> String {
    OscParam::ALL
        .into_iter()
        .filter(|p| !p.is_offset() || system[*p] != 0.0)
        .map(|p| format!("{p} {} {}", significant(system[p], 6), p.unit()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The verdict: what was identified, how close each stage came to its noise floor, and
/// whether any warning stands.
fn verdict(stages: &[StageOutcome], system: &OscillatorParams) -> String {
    let fits: Vec<String> = stages
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let floor_mm2 = (s.floor.sigma * 1e3).powi(2);
            format!(
                "stage {} ({}) S(μ) = {:.4} mm² against the position noise's {:.4} mm² ({:.1}×)",
                i + 1,
                s.record,
                s.result.s_mm2.unwrap_or(f64::NAN),
                floor_mm2,
                s.result.s_mm2.unwrap_or(f64::NAN) / floor_mm2
            )
        })
        .collect();
    let warned: usize = stages.iter().map(|s| s.warnings.len()).sum();
    format!(
        "Identified oscillator: {}. {}. {}",
        system_line(system),
        fits.join("; "),
        if warned == 0 {
            "No stage carries a warning: every stage converged, its free parameters determined, \
             none on a bound and none indistinguishable from another."
                .to_string()
        } else {
            format!("⚠ {warned} warning(s): see each stage's box below before using these values.")
        }
    )
}

fn stage_section(i: usize, s: &StageOutcome, dir: &Path) -> Result<Section> {
    let mut section = Section::new(format!("Stage {}: {}", i + 1, s.record));
    let caption = format!(
        "Stage {} values (± standard error); S(μ) = {:.4} mm², {} evaluations, {}.",
        i + 1,
        s.result.s_mm2.unwrap_or(f64::NAN),
        s.result.evaluations,
        if s.result.convergence.converged() {
            "converged"
        } else {
            "did not converge"
        }
    );
    let rows = s.result.params.iter().map(|p| {
        vec![
            p.name.clone(),
            format!("{:.6}", p.value),
            format!("{:.2e}", p.std_error),
        ]
    });
    let columns = ["parameter", "value", "standard error"];
    section
        .tables
        .push(Table::new(caption, &columns).with_rows(rows.collect()));
    section.warnings = s.warnings.iter().map(|w| w.to_string()).collect();
    if s.simulated.len() == s.x.len() {
        let simulated = milli(&s.simulated);
        let fig = measured_vs_model(
            dir,
            &format!("stage_{}", i + 1),
            DISPLACEMENT_MM,
            &s.t,
            &milli(&s.x),
            &[("identified", &simulated)],
        )?;
        section.figures.push(FigureRef::new(
            fig,
            format!(
                "Stage {}: measured displacement against the oscillator simulated with the \
                 stage's identified values.",
                i + 1
            ),
        ));
    }
    Ok(section)
}

/// Write `report.html`, `report.md` and the stages' figures into `out`.
pub fn write_identification_report(
    experiment: &Path,
    stages: &[StageOutcome],
    system: &OscillatorParams,
    out: &Path,
) -> Result<()> {
    let dir = out.join("figures");
    std::fs::create_dir_all(&dir)?;
    let sections = stages
        .iter()
        .enumerate()
        .map(|(i, s)| stage_section(i, s, &dir))
        .collect::<Result<Vec<_>>>()?;
    write_report(
        &format!("Identification: {}", experiment.display()),
        vec![verdict(stages, system)],
        sections,
        out,
    )
}
