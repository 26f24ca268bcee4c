//! `stf-lab compare EXP.toml --out DIR`: fit every model, then compare them regime by regime.
//!
//! The measured record is cut into rotor cycles and each cycle labelled pre-resonance,
//! resonance or post-resonance (`stf_core::regimes`). Each fitted model's force, on the same
//! kinematics, is scored per regime (force RMS error, energy per cycle, on–off duty, peak
//! force, label agreement, boundary error), and the oscillator with the model plugged in is
//! simulated against the record for the resonance peak. Writes `compare.json`, `compare.md`
//! and `compare.csv` (models × regimes; [`crate::outputs::compare_json`],
//! [`crate::outputs::compare_csv`], [`crate::compare_markdown`]). With `[validate]`, each
//! model's `fit` in compare.json carries its error on the second record, as in fit.json.

use std::path::Path;

use anyhow::{bail, Context, Result};
use stf_core::data::response::{local_maxima, peak, Peak};
use stf_core::physics::oscillator::Oscillator;
use stf_core::regimes::{
    classify, compare, rank_models, rank_on_loops, Classification, Comparison, MetricRanking,
    Ranking, Regime, RegimeMetrics,
};
use stf_core::simulate::Simulation;

use crate::compare_markdown::{compare_markdown, duty_meaning};
use crate::experiment::{Experiment, FitLevel};
use crate::fitting::{fit_all, load_data, FitData, ModelFit};
use crate::outputs::compare_csv;
use crate::outputs::compare_json::CompareJson;
use crate::progress::Progress;
use crate::report::{regime_errors, FigureRef, FrfCurve, FrfRole, RegimeChange, Section, Table};
use crate::say;
use crate::standard_report::{frequency_section, record_sections, write_report};
use crate::writing::results_dir::{wrote_line, ResultsDir};
use crate::writing::{write_atomic, write_json};

/// The measured record's regimes.
pub fn measured_regimes(exp: &Experiment, data: &FitData) -> Result<Classification> {
    let f = data
        .record
        .f_stf
        .as_deref()
        .context("comparing models needs the record's `f_stf` column")?;
    let sig = data.force_data().with_force(f);
    let cycles = crate::fitting::cycles_of(data)?;
    Ok(classify(&sig, cycles, &exp.regimes)?)
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

/// Everything a comparison found: the measured record's regimes and peak, each model's fit,
/// its comparison and its simulated response, and the rankings.
pub struct Compared {
    /// The measured record's cycles, labels and boundaries.
    pub measured: Classification,
    /// Each model's fit, in the experiment's order.
    pub fits: Vec<ModelFit>,
    /// Each model's comparison with the record, in the same order.
    pub comparisons: Vec<Comparison>,
    /// The record's resonance peak.
    pub measured_peak: Peak,
    /// Each model's simulated response and its peak (|x| m, ω rad/s); none if it failed.
    pub responses: Vec<Option<(FrfCurve, (f64, f64))>>,
    /// The models in order of relative force RMS error.
    pub ranking: Ranking,
    /// The models in order on each loop metric.
    pub loop_rankings: Vec<MetricRanking>,
}

impl Compared {
    /// The models' labels, in order.
    pub fn labels(&self) -> Vec<&str> {
        self.fits.iter().map(|f| f.label.as_str()).collect()
    }

    /// Each model's simulated peak (|x| m, ω rad/s), none where the simulation failed.
    pub fn peaks(&self) -> Vec<Option<(f64, f64)>> {
        self.responses
            .iter()
            .map(|r| r.as_ref().map(|r| r.1))
            .collect()
    }
}

/// Compare every fit in `fits` with the record `data` regime by regime.
fn compare_fits(
    exp: &Experiment,
    data: &FitData,
    measured: Classification,
    fits: Vec<ModelFit>,
) -> Result<Compared> {
    let sig = data.force_data();
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
    let responses = fits
        .iter()
        .map(|f| simulated_response(exp, data, Some(f)).ok())
        .collect();
    let labels: Vec<&str> = fits.iter().map(|f| f.label.as_str()).collect();
    let pairs: Vec<(&str, &Comparison)> = labels.iter().copied().zip(comparisons.iter()).collect();
    let ranking = rank_models(&pairs);
    let loop_rankings = rank_on_loops(&measured, &pairs);
    Ok(Compared {
        measured,
        fits,
        comparisons,
        measured_peak,
        responses,
        ranking,
        loop_rankings,
    })
}

/// Run `stf-lab compare` on an experiment loaded (from its file, or a campaign's unit: its
/// record set with [`Experiment::with_data_file`]): the results are built in a staging
/// folder and swapped in as a whole ([`ResultsDir`]).
pub fn run_experiment(mut exp: Experiment, out_arg: &Path, force: bool, quiet: bool) -> Result<()> {
    let data = load_data(&mut exp)?;
    if data.level != FitLevel::Force {
        bail!(
            "{}: compare scores models on the measured STF force; the record needs `f_stf`",
            exp.path.display()
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
    let c = compare_fits(&exp, &data, measured, fits)?;
    write_json(
        &out.join("compare.json"),
        &CompareJson::new(&exp, &data, &c),
    )?;
    let labels = c.labels();
    let rows = compare_csv::rows(&labels, &c.comparisons);
    compare_csv::write(&out.join("compare.csv"), &rows)?;
    crate::compare_loops::write_cycles_csv(
        &out.join("cycles.csv"),
        &c.measured,
        &labels,
        &c.comparisons,
    )?;
    let md = compare_markdown(&exp, &data, &c);
    write_atomic(
        &out.join("compare.md"),
        crate::report::md_text(&md).as_bytes(),
    )?;
    if exp.output.report {
        write_compare_report(&exp, &data, &c, &md, out)?;
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

/// The report: regimes table, frequency response, the record and the fits.
fn write_compare_report(
    exp: &Experiment,
    data: &FitData,
    c: &Compared,
    md: &str,
    out: &Path,
) -> Result<()> {
    let mut curves = vec![frf(
        "measured",
        &data.record.t,
        &data.record.x,
        data.kinematics.omega.as_deref(),
    )];
    if let Ok((curve, _)) = simulated_response(exp, data, None) {
        curves.push(curve);
    }
    curves.extend(c.responses.iter().flatten().map(|r| r.0.clone()));
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
    let mut sections = vec![regimes_section(c, md, out)?, frequency];
    sections.extend(record_sections(data, &c.fits, out)?);
    let forces: Vec<(&str, &[f64])> = c
        .fits
        .iter()
        .map(|f| (f.label.as_str(), f.fitted.as_slice()))
        .collect();
    sections.extend(crate::regime_figures::regime_section(
        exp, data, &forces, out,
    )?);
    let verdict = crate::verdict::compare_verdict(
        &c.ranking,
        &c.measured.cycles,
        &c.measured.labels,
        data.record.f_stf.as_deref().unwrap_or(&[]),
        &forces,
    );
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
        .push(crate::compare_loops::DUTY_EXPLAINED.into());
    regimes.tables.push(crate::compare_loops::energy_table(
        &c.labels(),
        &c.comparisons,
    ));
    let bars = per_regime(c, |m| m.map_or(f64::NAN, |m| m.relative_rms_error));
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
    Ok(regimes)
}

/// The relative force RMS error (duty error) of each model per regime and overall.
fn errors_table(c: &Compared) -> Table {
    let cell = |m: &RegimeMetrics| format!("{:.3} ({:.2})", m.relative_rms_error, m.duty_error);
    let caption =
        "Relative force RMS error per regime (on–off duty error in brackets); lower is better.";
    let columns = [
        "model",
        "pre-resonance",
        "resonance",
        "post-resonance",
        "overall",
    ];
    let rows = per_regime(c, |m| m.map_or("—".to_string(), cell));
    let rows = rows
        .into_iter()
        .map(|(label, cells)| [vec![label.to_string()], cells].concat());
    Table::new(caption, &columns).with_rows(rows.collect())
}

/// Each model's label with `value` of its metrics in each regime (`None`: no cycle there),
/// then overall.
fn per_regime<T>(c: &Compared, value: impl Fn(Option<&RegimeMetrics>) -> T) -> Vec<(&str, Vec<T>)> {
    let values = |cmp: &Comparison| {
        let regimes = Regime::ALL.iter().map(|&r| value(cmp.per_regime.get(r)));
        regimes.chain([value(Some(&cmp.overall))]).collect()
    };
    let models = c.fits.iter().zip(&c.comparisons);
    models
        .map(|(f, cmp)| (f.label.as_str(), values(cmp)))
        .collect()
}
