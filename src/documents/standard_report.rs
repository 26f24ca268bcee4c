//! The standard report of a command's results: the figures of the source study (time
//! histories of x, v, a against F_STF; hysteresis loops against x, v and a; measured against
//! fitted; the frequency response), a table per command, `report.html` (self-contained) and
//! `report.md`, with a CSV of every plotted series under `DIR/figures/`. With a `[validate]`
//! record, its section comes first ([`validation_section`]). The figures and documents
//! themselves are [`crate::report`]'s; this module puts a command's together.

use std::path::Path;

use anyhow::Result;

use stf_core::fit::{CORRELATION_LIMIT, NEAR_BOUND, RESIDUAL_OVER_FLOOR};

use crate::experiment::FitLevel;
use crate::fitting::{FitData, ModelFit};
use crate::report::{
    frequency_response, hysteresis, measured_vs_model, milli, time_history, write_html,
    write_markdown, FigureRef, FrfCurve, Motion, MotionLabels, RegimeChange, Report, Section,
    Smoothing, Table, DISPLACEMENT_MM, DISPLACEMENT_VALIDATION_MM, STF_FORCE, STF_FORCE_VALIDATION,
};
use crate::validation::ValidationRecord;
use rayon::prelude::*;
use stf_core::regimes::Regime;

/// A section of the figures of a record and its fits. The STF force is drawn where the work
/// reads it, at force level: at trajectory level (a rig without a force sensor, or one whose
/// force is not used) the record is its motion alone.
pub fn record_sections(data: &FitData, fits: &[ModelFit], out: &Path) -> Result<Vec<Section>> {
    let dir = out.join("figures");
    crate::writing::atomic::ensure_dir(&dir)?;
    let force = match data.level {
        FitLevel::Force => data.record.f_stf.as_deref(),
        FitLevel::Trajectory => None,
    };
    let mut sections = vec![record_section(data, force, &dir)?];
    if !fits.is_empty() {
        sections.push(fits_section(data, fits, &dir)?);
    }
    Ok(sections)
}

/// "The record": its time history and, with the STF force `f`, its hysteresis loops.
fn record_section(data: &FitData, f: Option<&[f64]>, dir: &Path) -> Result<Section> {
    let k = &data.kinematics;
    let mut s = Section::new("The record");
    s.paragraphs.push(format!(
        "{} samples of {}; v and a from a polynomial filter of order {} over {} samples \
         (acceleration noise ≈ {:.3} {}).",
        data.record.len(),
        data.record.source,
        k.motion_filter.order(),
        k.motion_filter.window(),
        k.sigma_a,
        MotionLabels::of(&data.units).a_unit
    ));
    let motion = Motion {
        t: &k.t,
        x: &k.x,
        v: &k.v,
        a: &k.a,
    };
    let labels = MotionLabels::of(&data.units);
    let history = || time_history(dir, "time_history", &motion, f, &labels);
    // The loops are independent files: drawn in parallel with the time history.
    let loops = || match f {
        None => Ok(Vec::new()),
        Some(f) => [
            ("hysteresis_x", labels.x, milli(&k.x)),
            ("hysteresis_v", labels.v, milli(&k.v)),
            ("hysteresis_a", labels.a, k.a.clone()),
        ]
        .into_par_iter()
        .map(|(name, label, series)| {
            let fig = hysteresis(dir, name, (label, &series), (labels.force, f), &k.t)?;
            Ok(FigureRef::new(
                fig,
                format!("Hysteresis loop of F_STF against {label}, coloured by time."),
            ))
        })
        .collect::<Result<Vec<_>>>(),
    };
    let (th, loops) = rayon::join(history, loops);
    let caption = if f.is_some() {
        "Displacement, velocity, acceleration and the STF force over time, a panel each; extrema of F_STF marked."
    } else {
        "Displacement, velocity and acceleration over time, a panel each (no STF force is read at trajectory level)."
    };
    s.figures.push(FigureRef::new(th?, caption).zoomable());
    s.figures.extend(loops?);
    Ok(s)
}

/// "Fits": the fitted parameters, the warnings, and the measured signal against each model.
fn fits_section(data: &FitData, fits: &[ModelFit], dir: &Path) -> Result<Section> {
    let (unit, scale) = data.shown();
    let what = data.level.signal().what;
    let mut s = Section::new("Fits");
    s.paragraphs.push(format!(
        "Each model fitted to the measured {what} ({} level).",
        data.level.name()
    ));
    if let Some(drive) = &data.kinematics.drive {
        s.paragraphs.push(format!("Drive: {drive}."));
    }
    s.paragraphs.push(warning_rules(fits, (unit, scale)));
    let rms = format!("RMS, {unit}");
    let columns = [
        "model",
        "parameters",
        &rms,
        "AIC",
        "BIC",
        "converged",
        "warnings",
    ];
    let caption = "Fitted parameters (± standard error), RMS residual and information criteria.";
    let rows = fits.iter().map(|f| fit_row(f, scale)).collect();
    s.tables.push(Table::new(caption, &columns).with_rows(rows));
    s.warnings = fits
        .iter()
        .flat_map(|f| f.warnings.iter().map(move |w| format!("{}: {w}", f.label)))
        .collect();
    let scaled = |s: &[f64]| s.iter().map(|v| v * scale).collect::<Vec<f64>>();
    let fitted: Vec<(&str, Vec<f64>)> = fits
        .iter()
        .map(|f| (f.label.as_str(), scaled(&f.fitted)))
        .collect();
    let quantity = match data.level {
        FitLevel::Force => STF_FORCE.in_units(&data.units),
        FitLevel::Trajectory => DISPLACEMENT_MM.in_units(&data.units),
    };
    let fig = measured_vs_model(
        dir,
        "measured_vs_fitted",
        quantity,
        &data.record.t,
        &scaled(data.target()),
        &fitted,
    )?;
    s.figures.push(
        FigureRef::new(fig, format!("Measured {what} against each fitted model.")).zoomable(),
    );
    Ok(s)
}

/// A model's row of the fits table: its parameters (± standard error), RMS (`scale` from
/// SI), information criteria, convergence and warnings.
fn fit_row(f: &ModelFit, scale: f64) -> Vec<String> {
    let params: Vec<String> = f
        .result
        .params
        .iter()
        .map(|p| {
            if p.fixed {
                format!("{} = {:.5} (fixed)", p.name, p.value)
            } else {
                crate::digits::param_with_error(p)
            }
        })
        .collect();
    vec![
        f.label.clone(),
        params.join(", "),
        format!("{:.4}", f.result.rms * scale),
        format!("{:.1}", f.result.aic),
        format!("{:.1}", f.result.bic),
        yes_no(f.result.convergence.converged()),
        match f.warnings.len() {
            0 => "none".into(),
            n => format!("⚠ {n} (above)"),
        },
    ]
}

/// `yes` or `no`, a table's cell of a flag.
pub fn yes_no(flag: bool) -> String {
    if flag { "yes" } else { "no" }.into()
}

/// The sentence of the report's intro on the validation record: the best model there.
pub fn validation_intro(rec: &ValidationRecord, fits: &[ModelFit]) -> String {
    let (unit, scale) = rec.data.shown();
    let best = fits
        .iter()
        .filter_map(|f| Some((f, f.validation.as_ref()?.score.as_ref()?)))
        .min_by(|a, b| a.1.rms.total_cmp(&b.1.rms));
    match best {
        Some((f, s)) => format!(
            "Validated on a second record, {}: the smallest error there is `{}`'s, RMS {:.4} \
             {unit} ({:.3} of the measured RMS); see Validation.",
            rec.spec.given,
            f.label,
            s.rms * scale,
            s.normalised
        ),
        None => format!(
            "Validated on a second record, {}: no model could be scored there.",
            rec.spec.given
        ),
    }
}

/// The section of the validation record: each model's error there (overall, against the
/// measured RMS, and per regime) beside its error on the estimation record, and the figure of
/// the record against each model's prediction.
pub fn validation_section(
    rec: &ValidationRecord,
    fits: &[ModelFit],
    out: &Path,
) -> Result<Section> {
    let dir = out.join("figures");
    crate::writing::atomic::ensure_dir(&dir)?;
    let (unit, scale) = rec.data.shown();
    let mut s = Section::new("Validation on a second record");
    s.paragraphs.push(format!(
        "Every model scored on {} ({} samples; the estimation record's column mapping, filters \
         and drive reconstruction) with the parameters fitted on the estimation record{}.",
        rec.spec.given,
        rec.data.record.len(),
        match rec.data.level {
            FitLevel::Force => ": the STF force predicted from its kinematics",
            FitLevel::Trajectory =>
                ": the fitted oscillator and model driven by its drive, from its own initial \
                 state (fitted on it when the fit fits x0, v0)",
        }
    ));
    s.tables.push(validation_table(fits, unit, scale));
    s.warnings = fits
        .iter()
        .filter_map(|f| f.validation.as_ref()?.error.clone())
        .collect();
    let predicted: Vec<(&str, Vec<f64>)> = fits
        .iter()
        .filter_map(|f| {
            let score = f.validation.as_ref()?.score.as_ref()?;
            Some((
                f.label.as_str(),
                score.predicted.iter().map(|x| x * scale).collect(),
            ))
        })
        .collect();
    if !predicted.is_empty() {
        let quantity = match rec.data.level {
            FitLevel::Force => STF_FORCE_VALIDATION.in_units(&rec.data.units),
            FitLevel::Trajectory => DISPLACEMENT_VALIDATION_MM.in_units(&rec.data.units),
        };
        let measured: Vec<f64> = rec.data.target().iter().map(|x| x * scale).collect();
        let fig = measured_vs_model(
            &dir,
            "validation",
            quantity,
            &rec.data.record.t,
            &measured,
            &predicted,
        )?;
        s.figures.push(
            FigureRef::new(
                fig,
                "The validation record against each model's prediction with its fitted parameters.",
            )
            .zoomable(),
        );
    }
    Ok(s)
}

/// The table of each model's error on the validation record: overall, against the measured
/// RMS, per regime, and its RMS on the estimation record (in `unit`, `scale` from SI).
fn validation_table(fits: &[ModelFit], unit: &str, scale: f64) -> Table {
    let mut columns = vec![
        "model".to_string(),
        format!("validation RMS, {unit}"),
        "of the measured RMS".into(),
    ];
    columns.extend(Regime::ALL.iter().map(|r| format!("{}, {unit}", r.name())));
    columns.push(format!("estimation RMS, {unit}"));
    let cell = |x: Option<f64>, digits: usize| x.map_or("—".into(), |x| format!("{x:.digits$}"));
    let rows = fits
        .iter()
        .map(|f| {
            let v = f.validation.as_ref();
            let score = v.and_then(|v| v.score.as_ref());
            let mut row = vec![
                f.label.clone(),
                cell(score.map(|s| s.rms * scale), 4),
                cell(score.map(|s| s.normalised), 3),
            ];
            for r in Regime::ALL {
                let e = v.and_then(|v| v.per_regime.as_ref()).and_then(|p| p.get(r));
                row.push(cell(e.map(|e| e.rms * scale), 4));
            }
            row.push(format!("{:.4}", f.result.rms * scale));
            row
        })
        .collect();
    Table {
        caption: "Error on the validation record (fitted parameters held).".into(),
        columns,
        rows,
    }
}

/// What the warnings check, with each fit's noise floor.
fn warning_rules(fits: &[ModelFit], (unit, scale): (&str, f64)) -> String {
    let floors: Vec<String> = fits
        .iter()
        .filter_map(|f| {
            f.floor
                .map(|n| format!("{} {:.4} {unit}", f.label, n.sigma * scale))
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

/// A section with the frequency response (local maxima of x against ω) of several runs, its
/// figure written as `figures/NAME.*`.
/// `changes` are the record's changes of regime (pre-resonance → resonance, resonance →
/// post-resonance), shaded with their uncertainty.
/// The maxima are in `x_unit` (the record's: `mm`, or `mV` for x in volts).
pub fn frequency_section(
    name: &str,
    curves: &[FrfCurve],
    changes: [Option<RegimeChange>; 2],
    x_unit: &str,
    out: &Path,
) -> Result<Section> {
    let dir = out.join("figures");
    crate::writing::atomic::ensure_dir(&dir)?;
    let mut s = Section::new("Frequency response");
    s.paragraphs.push(
        "Local maxima of the displacement against the rotor speed, with the smoothed trend \
         (outliers replaced by the mean of their neighbours, then a moving average). The \
         resonance regime of the record is shaded, each change of regime's uncertainty darker; \
         the oscillator without STF is the dashed black line."
            .into(),
    );
    let fig = frequency_response(&dir, name, curves, changes, &Smoothing::default(), x_unit)?;
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
