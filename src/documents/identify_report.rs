//! The report of the source study's identification (`[[identify]]` stages): a verdict
//! paragraph (the identified oscillator, each stage's S(μ) against its noise floor, every
//! warning), the identified parameters with their units, each stage's table, and each stage's
//! measured displacement against the oscillator simulated with the stage's values (over time,
//! and, for a swept stage, as a frequency response).

use std::path::Path;

use anyhow::Result;
use stf_core::physics::oscillator_params::OscillatorParams;

use crate::documents::standard_report::write_report;
use crate::report::{
    frequency_response, measured_vs_model, milli, FigureRef, FrfCurve, FrfRole, Section, Smoothing,
    Table, DISPLACEMENT_MM,
};
use stf_study::compare::response;
use stf_study::param_table::rows_of;
use stf_study::shown_units::ShownUnits;

pub use stf_study::identify::StageOutcome;
use stf_study::verdict::identify_verdict as verdict;
pub use stf_study::verdict::system_line;

fn stage_section(i: usize, s: &StageOutcome, units: &ShownUnits, dir: &Path) -> Result<Section> {
    let mut section = Section::new(format!("Stage {}: {}", i + 1, s.record));
    let caption = format!(
        "Stage {} values (± standard error); S(μ) = {:.4} {}, {} evaluations, {}.",
        i + 1,
        s.result.s_mm2.unwrap_or(f64::NAN),
        units.x_squared,
        s.result.evaluations,
        if s.result.convergence.converged() {
            "converged"
        } else {
            "did not converge"
        }
    );
    let label = format!("stage {}", i + 1);
    let units_of = rows_of(&label, &s.result, None, &s.warnings, units);
    let rows = s.result.params.iter().zip(&units_of).map(|(p, row)| {
        let value = if p.fixed {
            format!("{} (held)", p.shown_value())
        } else {
            stf_study::digits::with_error(p.value, p.std_error)
        };
        vec![p.name.clone(), value, row.unit.clone()]
    });
    let columns = ["parameter", "value ± standard error", "unit"];
    section
        .tables
        .push(Table::new(caption, &columns).with_rows(rows.collect()));
    section.warnings = s.warnings.iter().map(|w| w.to_string()).collect();
    if s.simulated.len() == s.x.len() {
        let simulated = milli(&s.simulated);
        let fig = measured_vs_model(
            dir,
            &format!("stage_{}", i + 1),
            DISPLACEMENT_MM.in_units(units),
            &s.t,
            &milli(&s.x),
            &[("identified", &simulated)],
        )?;
        section.figures.push(
            FigureRef::new(
                fig,
                format!(
                    "Stage {}: measured displacement against the oscillator simulated with the \
                 stage's identified values.",
                    i + 1
                ),
            )
            .zoomable(),
        );
    }
    if let Some(fig) = stage_frequency_response(i, s, units.x, dir)? {
        section.figures.push(fig);
    }
    Ok(section)
}

/// A swept stage's frequency response: the local maxima of the measured displacement and of
/// the oscillator simulated with the stage's values against the rotor speed.
fn stage_frequency_response(
    i: usize,
    s: &StageOutcome,
    x_unit: &str,
    dir: &Path,
) -> Result<Option<FigureRef>> {
    let Some(omega) = s.omega.as_deref() else {
        return Ok(None);
    };
    let mut curves = vec![("measured", &s.x, FrfRole::Measured)];
    if s.simulated.len() == s.x.len() {
        curves.push(("identified", &s.simulated, FrfRole::Model));
    }
    let curves: Vec<FrfCurve> = curves
        .into_iter()
        .map(|(label, x, role)| {
            let r = response(label, &s.t, x, Some(omega));
            FrfCurve {
                label: r.label,
                omega: r.omega,
                x_peak: r.x_peak,
                role,
            }
        })
        .collect();
    let name = format!("frequency_response_stage_{}", i + 1);
    let smoothing = Smoothing::default();
    let fig = frequency_response(dir, &name, &curves, [None, None], &smoothing, x_unit)?;
    Ok(Some(FigureRef::new(
        fig,
        format!(
            "Stage {}: frequency response, the local maxima of the measured displacement and of \
             the oscillator simulated with the stage's values against the rotor speed, with \
             their smoothed trends.",
            i + 1
        ),
    )))
}

/// Write `report.html`, `report.md` and the stages' figures into `out`.
pub fn write_identification_report(
    experiment: &Path,
    stages: &[StageOutcome],
    system: &OscillatorParams,
    units: &ShownUnits,
    out: &Path,
) -> Result<()> {
    let dir = out.join("figures");
    crate::writing::atomic::ensure_dir(&dir)?;
    let sections = stages
        .iter()
        .enumerate()
        .map(|(i, s)| stage_section(i, s, units, &dir))
        .collect::<Result<Vec<_>>>()?;
    write_report(
        &format!("Identification: {}", experiment.display()),
        vec![verdict(stages, system, units)],
        sections,
        out,
    )
}
