//! `stf-lab compare EXP.toml --out DIR`: fit every model, then compare them regime by regime.
//!
//! The measured record is cut into rotor cycles and each cycle labelled pre-resonance,
//! resonance or post-resonance (`stf_core::regimes`). Each fitted model's force, on the same
//! kinematics, is scored per regime (force RMS error, energy per cycle, on–off duty, peak
//! force, label agreement, boundary error), and the oscillator with the model plugged in is
//! simulated against the record for the resonance peak. Writes `compare.json`, `compare.md`
//! and `compare.csv` (models × regimes). With `[validate]`, each model's `fit` in
//! compare.json carries its error on the second record, as in fit.json.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{bail, Context, Result};
use serde_json::{json, Value};
use stf_core::data::response::{local_maxima, peak};
use stf_core::physics::oscillator::Oscillator;
use stf_core::regimes::{
    classify, compare, rank_models, rank_on_loops, Classification, Comparison, Regime, Signals,
};
use stf_core::simulate::Simulation;

use crate::experiment::{Experiment, FitLevel};
use crate::fitting::{finite_or_null, fit_all, load_data, FitData, ModelFit};
use crate::output::{write_atomic, write_json};
use crate::progress::Progress;
use crate::report::{regime_errors, FigureRef, FrfCurve, FrfRole, RegimeChange, Section, Table};
use crate::reporting::{frequency_section, record_sections, write_report};
use crate::results_dir::{wrote_line, ResultsDir};
use crate::say;

/// The measured record's regimes.
pub fn measured_regimes(exp: &Experiment, data: &FitData) -> Result<Classification> {
    let k = &data.kinematics;
    let f = data
        .record
        .f_stf
        .as_deref()
        .context("comparing models needs the record's `f_stf` column")?;
    let sig = Signals {
        t: &k.t,
        x: &k.x,
        v: &k.v,
        a: &k.a,
        f,
    };
    let cycles = crate::fitting::cycles_of(data)?;
    Ok(classify(&sig, cycles, &exp.regimes)?)
}

fn signals<'a>(data: &'a FitData) -> Signals<'a> {
    let k = &data.kinematics;
    Signals {
        t: &k.t,
        x: &k.x,
        v: &k.v,
        a: &k.a,
        f: data.record.f_stf.as_deref().unwrap_or(&[]),
    }
}

/// The oscillator with the fitted model (or none), driven as in the record: its local maxima
/// of x against ω and its resonance peak (|x|, ω).
fn simulated_response(
    exp: &Experiment,
    data: &FitData,
    fit: Option<&ModelFit>,
) -> Result<(FrfCurve, (f64, f64))> {
    let k = &data.kinematics;
    let system = fit.map_or(exp.system, |f| f.system);
    let mut osc = Oscillator::new(system, k.excitation());
    if let Some(f) = fit {
        if let Some(c) = &f.configured {
            osc = osc.with_model(c.model.clone(), f.model_values())?;
        }
    }
    let (x0, v0) = k.initial_state();
    let run = Simulation::new(&osc)
        .settings(exp.integrator.clone())
        .initial(x0, v0)
        .run_at(&k.t)?;
    let p = peak(&run.t, &run.x, k.omega.as_deref()).context("empty simulation")?;
    Ok((
        frf(
            fit.map_or("without STF", |f| f.label.as_str()),
            &run.t,
            &run.x,
            k.omega.as_deref(),
        ),
        (p.amplitude, p.omega),
    ))
}

fn frf(label: &str, t: &[f64], x: &[f64], omega: Option<&[f64]>) -> FrfCurve {
    let zeros = vec![0.0; t.len()];
    let maxima = local_maxima(t, x, omega.unwrap_or(&zeros));
    FrfCurve {
        label: label.to_string(),
        omega: maxima.iter().map(|m| m.omega).collect(),
        x_peak: maxima.iter().map(|m| m.x).collect(),
        role: match label {
            "measured" => FrfRole::Measured,
            "without STF" => FrfRole::Reference,
            _ => FrfRole::Model,
        },
    }
}

/// What the duty and its error are, with the record's on-threshold.
fn duty_meaning(on_threshold: f64) -> String {
    format!(
        "The duty of a cycle is the fraction of it in which the STF force is on (|F_STF| above \
         {on_threshold:.3} N, the record's on-threshold): 1 for a force that only passes through \
         zero, below 1 for on–off spikes with rest between them; the duty error is the mean over \
         a regime's cycles of |model duty − measured duty|."
    )
}

fn regime_json(c: &Comparison) -> Value {
    let mut m = serde_json::Map::new();
    for r in Regime::ALL {
        m.insert(
            r.name().into(),
            serde_json::to_value(c.per_regime.get(r)).unwrap_or(Value::Null),
        );
    }
    Value::Object(m)
}

/// Run `stf-lab compare`: the results are built in a staging folder and swapped in as a
/// whole ([`ResultsDir`]).
pub fn run(exp_path: &Path, out_arg: &Path, force: bool, quiet: bool) -> Result<()> {
    let mut exp = Experiment::load(exp_path)?;
    let data = load_data(&mut exp)?;
    if data.level != FitLevel::Force {
        bail!(
            "{}: compare scores models on the measured STF force; the record needs `f_stf`",
            exp_path.display()
        );
    }
    let validation = crate::validation::load(&exp, &data)?;
    let results = ResultsDir::begin(out_arg, force)?;
    let out = results.path();
    let measured = measured_regimes(&exp, &data)?;
    let mut fits = fit_all(&exp, &data, &Progress::new(quiet))?;
    if let Some(rec) = &validation {
        crate::validation::score_fits(&mut fits, rec);
    }
    let sig = signals(&data);
    let comparisons: Vec<Comparison> = fits
        .iter()
        .map(|f| compare(&measured, &sig, &f.fitted, &exp.regimes))
        .collect::<std::result::Result<_, _>>()?;
    let measured_peak = peak(
        &data.record.t,
        &data.record.x,
        data.kinematics.omega.as_deref(),
    )
    .context("empty record")?;
    let responses: Vec<Option<(FrfCurve, (f64, f64))>> = fits
        .iter()
        .map(|f| simulated_response(&exp, &data, Some(f)).ok())
        .collect();
    let peaks: Vec<Option<(f64, f64)>> =
        responses.iter().map(|r| r.as_ref().map(|r| r.1)).collect();
    let labels: Vec<&str> = fits.iter().map(|f| f.label.as_str()).collect();
    let pairs: Vec<(&str, &Comparison)> = labels.iter().copied().zip(comparisons.iter()).collect();
    let ranking = rank_models(&pairs);
    let loop_rankings = rank_on_loops(&measured, &pairs);

    let count = |r: Regime| measured.labels.iter().filter(|l| **l == r).count();
    let models: Vec<Value> = fits
        .iter()
        .zip(&comparisons)
        .zip(&peaks)
        .map(|((f, c), p)| {
            json!({
                "name": f.name(),
                "label": f.label,
                "fit": f.to_json(data.level),
                "regimes": regime_json(c),
                "overall": c.overall,
                "boundary_errors": c.boundary_errors,
                "model_boundaries": c.model_boundaries,
                "resonance": p.map(|(x, w)| json!({
                    "peak_x_m": x,
                    "peak_omega_rad_s": finite_or_null(w),
                    "peak_x_error_m": x - measured_peak.amplitude,
                    "peak_omega_error_rad_s": finite_or_null(w - measured_peak.omega),
                })),
            })
        })
        .collect();
    let best: serde_json::Map<String, Value> = Regime::ALL
        .iter()
        .map(|&r| (r.name().to_string(), json!(ranking.best_in(r))))
        .chain(std::iter::once((
            "overall".to_string(),
            json!(ranking.best_overall()),
        )))
        .collect();
    let doc = json!({
        "experiment": exp.path.display().to_string(),
        "record": data.record.source,
        "measured": {
            "noise_sigma": measured.noise_sigma,
            "on_threshold": measured.on_threshold,
            "no_stf": measured.no_stf,
            "cycles": measured.labels.len(),
            "cycles_per_regime": Regime::ALL.iter().map(|&r| (r.name().to_string(), json!(count(r)))).collect::<serde_json::Map<_, _>>(),
            "boundaries": measured.boundaries,
            "boundary_notes": crate::compare_loops::boundary_notes(&measured),
            "resonance": { "peak_x_m": measured_peak.amplitude, "peak_omega_rad_s": finite_or_null(measured_peak.omega) },
        },
        "thresholds": exp.regimes,
        "models": models,
        "ranking": ranking,
        "loop_rankings": loop_rankings,
        "best": best,
        "cycles_csv": "cycles.csv",
    });
    write_json(&out.join("compare.json"), &doc)?;

    // models × regimes: relative force RMS error and duty error.
    let mut csv = String::from("model,regime,cycles,force_rms_error_N,relative_rms_error,energy_error_J,duty_error,peak_force_error_N,label_agreement,measured_energy_J,model_energy_J,measured_c_eq_Ns_m,model_c_eq_Ns_m,phase_x_error_deg,phase_v_error_deg\n");
    let mut md = String::new();
    let _ = writeln!(md, "# Model comparison: {}\n", exp.path.display());
    let _ = writeln!(
        md,
        "Record `{}`: {} cycles; noise floor σ = {:.4} N{}.\n",
        data.record.source,
        measured.labels.len(),
        measured.noise_sigma,
        if measured.no_stf {
            "; the STF force is negligible everywhere (no regimes)"
        } else {
            ""
        }
    );
    for line in crate::compare_loops::boundary_lines(&measured) {
        let _ = writeln!(md, "- {line}");
    }
    let _ = writeln!(
        md,
        "\nRelative force RMS error (duty error) per regime; lower is better. {}\n",
        duty_meaning(measured.on_threshold)
    );
    let _ = writeln!(
        md,
        "| model | pre-resonance | resonance | post-resonance | overall | peak x (mm) at ω |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|");
    for ((f, c), p) in fits.iter().zip(&comparisons).zip(&peaks) {
        let mut row = format!("| {} ", f.label);
        for r in Regime::ALL {
            match c.per_regime.get(r) {
                Some(m) => {
                    let _ = write!(row, "| {:.3} ({:.2}) ", m.relative_rms_error, m.duty_error);
                    let _ = writeln!(
                        csv,
                        "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
                        f.label,
                        r.name(),
                        m.cycles,
                        m.force_rms_error,
                        m.relative_rms_error,
                        m.energy_error,
                        m.duty_error,
                        m.peak_force_error,
                        m.label_agreement,
                        m.measured_energy,
                        m.model_energy,
                        m.measured_c_eq,
                        m.model_c_eq,
                        m.phase_x_error,
                        m.phase_v_error
                    );
                }
                None => row.push_str("| — "),
            }
        }
        let o = &c.overall;
        let _ = write!(row, "| {:.3} ({:.2}) ", o.relative_rms_error, o.duty_error);
        match p {
            Some((x, w)) => {
                let _ = write!(row, "| {:.2} at {:.2} |", x * 1e3, w);
            }
            None => row.push_str("| simulation failed |"),
        }
        let _ = writeln!(md, "{row}");
    }
    let _ = writeln!(
        md,
        "| *measured* | | | | | {:.2} at {:.2} |\n",
        measured_peak.amplitude * 1e3,
        measured_peak.omega
    );
    for r in Regime::ALL {
        if let Some(b) = ranking.best_in(r) {
            let _ = writeln!(md, "- best in {}: **{b}**", r.name().replace('_', "-"));
        }
    }
    if let Some(b) = ranking.best_overall() {
        let _ = writeln!(md, "- best overall: **{b}**");
    }
    let energy = crate::compare_loops::energy_table(&labels, &comparisons);
    crate::compare_loops::write_markdown(&mut md, &loop_rankings, &energy);
    // Say what each model misses: a duty error above 0.2 in a regime is an on–off miss.
    for (f, c) in fits.iter().zip(&comparisons) {
        for r in Regime::ALL {
            if let Some(m) = c.per_regime.get(r) {
                if m.duty_error > 0.2 {
                    let _ = writeln!(
                        md,
                        "- {} misses the on–off behaviour in {}: duty {:.2} against the measured {:.2}",
                        f.label,
                        r.name().replace('_', "-"),
                        m.model_duty,
                        m.measured_duty
                    );
                }
            }
        }
    }
    // Fits not to be trusted as they stand (`*` bullets: the report shows them in its own box).
    let warned: Vec<String> = fits
        .iter()
        .flat_map(|f| {
            f.warnings
                .iter()
                .map(move |w| format!("* {}: {w}", f.label))
        })
        .collect();
    if !warned.is_empty() {
        let _ = writeln!(md, "\n**Warnings**\n\n{}", warned.join("\n"));
    }
    write_atomic(&out.join("compare.csv"), csv.as_bytes())?;
    crate::compare_loops::write_cycles_csv(
        &out.join("cycles.csv"),
        &measured,
        &labels,
        &comparisons,
    )?;
    write_atomic(
        &out.join("compare.md"),
        crate::report::md_text(&md).as_bytes(),
    )?;
    if exp.output.report {
        // The report: regimes table, frequency response, the record and the fits.
        let mut curves = vec![frf(
            "measured",
            &data.record.t,
            &data.record.x,
            data.kinematics.omega.as_deref(),
        )];
        if let Ok((c, _)) = simulated_response(&exp, &data, None) {
            curves.push(c);
        }
        curves.extend(responses.into_iter().flatten().map(|r| r.0));
        let mut regimes = Section::new("Models regime by regime");
        regimes.paragraphs = md
            .lines()
            .filter(|l| l.starts_with("- "))
            .map(|l| l.trim_start_matches("- ").replace("**", ""))
            .collect();
        let mut table = Table {
            caption:
                "Relative force RMS error per regime (on–off duty error in brackets); lower is better."
                    .into(),
            columns: [
                "model",
                "pre-resonance",
                "resonance",
                "post-resonance",
                "overall",
            ]
            .iter()
            .map(|c| c.to_string())
            .collect(),
            rows: Vec::new(),
        };
        for (f, c) in fits.iter().zip(&comparisons) {
            let mut row = vec![f.label.clone()];
            for r in Regime::ALL {
                row.push(c.per_regime.get(r).map_or("—".to_string(), |m| {
                    format!("{:.3} ({:.2})", m.relative_rms_error, m.duty_error)
                }));
            }
            row.push(format!(
                "{:.3} ({:.2})",
                c.overall.relative_rms_error, c.overall.duty_error
            ));
            table.rows.push(row);
        }
        regimes.paragraphs.push(duty_meaning(measured.on_threshold));
        regimes.tables.push(table);
        regimes
            .paragraphs
            .push(crate::compare_loops::DUTY_EXPLAINED.into());
        regimes.tables.push(energy);
        let bars: Vec<(&str, Vec<f64>)> = fits
            .iter()
            .zip(&comparisons)
            .map(|(f, c)| {
                let mut v: Vec<f64> = Regime::ALL
                    .iter()
                    .map(|&r| {
                        c.per_regime
                            .get(r)
                            .map_or(f64::NAN, |m| m.relative_rms_error)
                    })
                    .collect();
                v.push(c.overall.relative_rms_error);
                (f.label.as_str(), v)
            })
            .collect();
        let fig = regime_errors(
            &out.join("figures"),
            "regime_errors",
            &["pre-resonance", "resonance", "post-resonance", "overall"],
            &bars,
            "relative force RMS error",
        )?;
        regimes.figures.push(FigureRef::new(
            fig,
            "Relative force RMS error of each model in each regime of the record (lower is better).",
        ));
        let change = |b: Option<stf_core::regimes::Boundary>| {
            b.map(|b| RegimeChange {
                omega: b.omega,
                uncertainty: b.uncertainty,
            })
        };
        let changes = [
            change(measured.boundaries.pre_resonance),
            change(measured.boundaries.resonance_post),
        ];
        let frequency = frequency_section(&curves, changes, out)?;
        let mut sections = vec![regimes, frequency];
        sections.extend(record_sections(&data, &fits, out)?);
        let forces: Vec<(&str, &[f64])> = fits
            .iter()
            .map(|f| (f.label.as_str(), f.fitted.as_slice()))
            .collect();
        sections.extend(crate::regime_figures::regime_section(
            &exp, &data, &forces, out,
        )?);
        write_report(
            &format!("Comparison: {}", exp.path.display()),
            vec![
                crate::verdict::compare_verdict(
                    &ranking,
                    &measured.cycles,
                    &measured.labels,
                    data.record.f_stf.as_deref().unwrap_or(&[]),
                    &forces,
                ),
                format!(
                    "{} cycles of {}; noise floor σ = {:.4} N.",
                    measured.labels.len(),
                    data.record.source,
                    measured.noise_sigma
                ),
            ],
            sections,
            out,
        )?;
    }
    results.commit()?;
    say!("{}", md.strip_suffix('\n').unwrap_or(&md));
    say!(
        "{}",
        wrote_line(
            out_arg,
            &["compare.json", "compare.md", "compare.csv", "cycles.csv"],
            exp.output.report
        )
    );
    Ok(())
}
