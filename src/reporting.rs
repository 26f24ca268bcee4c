//! The standard report of a command's results: the figures of the source study (time
//! histories of x, v, a against F_STF; hysteresis loops against x, v and a; measured against
//! fitted; the frequency response), a table per command, `report.html` (self-contained) and
//! `report.md`, with a CSV of every plotted series under `DIR/figures/`.

use std::path::Path;

use anyhow::{Context, Result};

use stf_core::fit::{CORRELATION_LIMIT, NEAR_BOUND, RESIDUAL_OVER_FLOOR};

use crate::experiment::FitLevel;
use crate::fitting::{FitData, ModelFit};
use crate::report::{
    frequency_response, hysteresis, measured_vs_fitted, time_history, write_html, write_markdown,
    FigureRef, FrfCurve, Motion, Report, Section, Smoothing, Table,
};

/// A section of the figures of a record and its fits.
pub fn record_sections(data: &FitData, fits: &[ModelFit], out: &Path) -> Result<Vec<Section>> {
    let dir = out.join("figures");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let k = &data.kinematics;
    let mut sections = Vec::new();

    if let Some(f) = data.record.f_stf.as_deref() {
        let mut s = Section::new("The record");
        s.paragraphs.push(format!(
            "{} samples of {}; v and a from a polynomial filter of order {} over {} samples \
             (acceleration noise ≈ {:.3} m/s²).",
            data.record.len(),
            data.record.source,
            k.motion_filter.order(),
            k.motion_filter.window(),
            k.sigma_a
        ));

        let motion = Motion {
            t: &k.t,
            x: &k.x,
            v: &k.v,
            a: &k.a,
        };
        let th = time_history(&dir, "time_history", &motion, f)?;
        s.figures.push(FigureRef::new(
            th,
            "Displacement, velocity and acceleration against the STF force; extrema of F_STF marked.",
        ));
        for (name, label, series) in [
            ("hysteresis_x", "displacement x, m", &k.x),
            ("hysteresis_v", "velocity v, m/s", &k.v),
            ("hysteresis_a", "acceleration a, m/s²", &k.a),
        ] {
            let fig = hysteresis(&dir, name, (label, series), f, &k.t)?;
            s.figures.push(FigureRef::new(
                fig,
                format!("Hysteresis loop of F_STF against {label}, coloured by time."),
            ));
        }
        sections.push(s);
    }

    if !fits.is_empty() {
        let (unit, scale, what) = match data.level {
            FitLevel::Force => ("N", 1.0, "STF force"),
            FitLevel::Trajectory => ("mm", 1e3, "displacement"),
        };
        let mut s = Section::new("Fits");
        s.paragraphs.push(format!(
            "Each model fitted to the measured {what} ({} level).",
            if data.level == FitLevel::Force {
                "force"
            } else {
                "trajectory"
            }
        ));
        if let Some(drive) = &k.drive {
            s.paragraphs.push(format!("Drive: {drive}."));
        }
        s.paragraphs.push(warning_rules(fits));
        let mut table = Table {
            caption: "Fitted parameters (± standard error), RMS residual and information criteria."
                .into(),
            columns: [
                "model",
                "parameters",
                &format!("RMS, {unit}"),
                "AIC",
                "BIC",
                "converged",
                "warnings",
            ]
            .iter()
            .map(|c| c.to_string())
            .collect(),
            rows: Vec::new(),
        };
        for f in fits {
            let params: Vec<String> = f
                .result
                .params
                .iter()
                .map(|p| {
                    if p.fixed {
                        format!("{} = {:.5} (fixed)", p.name, p.value)
                    } else {
                        format!("{} = {:.5} ± {:.2e}", p.name, p.value, p.std_error)
                    }
                })
                .collect();
            table.rows.push(vec![
                f.label.clone(),
                params.join(", "),
                format!("{:.4}", f.result.rms * scale),
                format!("{:.1}", f.result.aic),
                format!("{:.1}", f.result.bic),
                if f.result.convergence.converged() {
                    "yes".into()
                } else {
                    "no".into()
                },
                match f.warnings.len() {
                    0 => "none".into(),
                    n => format!("⚠ {n} (above)"),
                },
            ]);
        }
        s.tables.push(table);
        s.warnings = fits
            .iter()
            .flat_map(|f| f.warnings.iter().map(move |w| format!("{}: {w}", f.label)))
            .collect();
        let fitted: Vec<(&str, &[f64])> = fits
            .iter()
            .map(|f| (f.label.as_str(), f.fitted.as_slice()))
            .collect();
        let fig = measured_vs_fitted(
            &dir,
            "measured_vs_fitted",
            &data.record.t,
            data.target(),
            &fitted,
        )?;
        s.figures.push(FigureRef::new(
            fig,
            format!("Measured {what} against each fitted model."),
        ));
        sections.push(s);
    }
    Ok(sections)
}

/// What the warnings check, with each fit's noise floor.
fn warning_rules(fits: &[ModelFit]) -> String {
    let floors: Vec<String> = fits
        .iter()
        .filter_map(|f| {
            f.floor
                .map(|n| format!("{} {}", f.label, n.quantity.show(n.sigma)))
        })
        .collect();
    format!(
        "A fit is flagged when it did not converge, when its RMS residual exceeds {}× the \
         record's noise floor (measurement noise, with the kinematics' noise propagated through \
         the model at force level; here {}), when a free parameter ends within {} % of its size \
         (or of its box, if narrower) from a bound, when a standard error exceeds its |value| or \
         is not finite, or when two free parameters correlate beyond {} in magnitude.",
        RESIDUAL_OVER_FLOOR,
        if floors.is_empty() {
            "not estimated".to_string()
        } else {
            floors.join(", ")
        },
        NEAR_BOUND * 100.0,
        CORRELATION_LIMIT
    )
}

/// A section with the frequency response (local maxima of x against ω) of several runs.
pub fn frequency_section(curves: &[FrfCurve], out: &Path) -> Result<Section> {
    let dir = out.join("figures");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut s = Section::new("Frequency response");
    s.paragraphs.push(
        "Local maxima of the displacement against the rotor speed, with the smoothed trend \
         (outliers replaced by the mean of their neighbours, then a moving average)."
            .into(),
    );
    let fig = frequency_response(&dir, "frequency_response", curves, &Smoothing::default())?;
    s.figures.push(FigureRef::new(
        fig,
        "Frequency response of the record and of the oscillator with each fitted model.",
    ));
    Ok(s)
}

/// Write `report.html` and `report.md` into `out`.
pub fn write_report(
    title: &str,
    intro: Vec<String>,
    sections: Vec<Section>,
    out: &Path,
) -> Result<()> {
    let mut report = Report::new(title);
    report.intro = intro;
    report.sections = sections;
    write_html(&report, &out.join("report.html"))?;
    write_markdown(&report, &out.join("report.md"))?;
    Ok(())
}
