//! Every call into the lab's workflows, in one file: reading an experiment, simulating its
//! `[simulate]` section, fitting, comparing. Each returns an owned outcome — the JSON the
//! command line writes (the same `Serialize` type, numbers tidied to the digits they carry as
//! `output::write_json` does), its verdict and the arrays behind it — and writes nothing.
//!
//! Until the study layer (`stf-study`) lands this calls the program crate's library
//! functions (`stf_lab::fitting`, `stf_lab::outputs`, `stf_lab::validation`); the few steps
//! the commands keep private (the comparison of fits, the simulation's excitation) are
//! restated here, marked, to be replaced by the study's calls.

use std::path::Path;

use anyhow::{bail, Context};
use serde::Serialize;
use stf_core::data::response::peak;
use stf_core::numerics::interpolate::Linear;
use stf_core::physics::excitation::Excitation;
use stf_core::physics::oscillator::Oscillator;
use stf_core::regimes::{compare as compare_regimes, rank_models, rank_on_loops, Comparison};
use stf_core::simulate::synthetic::{sample_record, SensorNoise};
use stf_core::simulate::Simulation;
use stf_lab::cmd_compare::{measured_regimes, Compared};
use stf_lab::experiment::{Drive, Experiment, FitLevel};
use stf_lab::fitting::{fit_all, load_data, FitData, ModelFit};
use stf_lab::model_config::{configure_for, resolve};
use stf_lab::outputs::compare_json::CompareJson;
use stf_lab::outputs::fit_json::FitJson;
use stf_lab::progress::Progress;
use stf_lab::validation::ValidationRecord;

use crate::errors::{CallError, Kind, OrKind};
use crate::run::Job;

/// The experiment at `path`: read from the file, or from `text` (an experiment built in
/// Python; `path` then names it in messages and its folder is where relative paths start).
pub fn experiment(path: &Path, text: Option<&str>) -> Result<Experiment, CallError> {
    match text {
        Some(text) => Experiment::parse(path, text),
        None => Experiment::load(path),
    }
    .or_kind(Kind::Experiment)
}

/// `value` as the command line writes it: JSON text, numbers to the digits they carry.
fn json_text<T: Serialize>(value: &T) -> Result<String, CallError> {
    let mut v = serde_json::to_value(value)
        .context("cannot serialize the result")
        .or_kind(Kind::Other)?;
    stf_lab::digits::tidy_json(&mut v);
    Ok(v.to_string())
}

/// A fitted model's curve: its label and the prediction of the measured signal.
pub type Curve = (String, Vec<f64>);

/// What `fit` (and the fit inside `compare`) hands back.
pub struct FitOutcome {
    /// `fit.json` (or `compare.json`), as text.
    pub json: String,
    /// The report's verdict: the best model and why.
    pub verdict: String,
    /// `params.csv`'s rows (model, parameter, value, std_error, unit, fixed, at_bound), as
    /// JSON text.
    pub params_table: String,
    /// `compare.csv`'s rows (models × regimes), as JSON text; `[]` for a fit.
    pub regimes_table: String,
    /// The best model by AIC (the simplest within ΔAIC 2: the verdict's rule), its index.
    pub best: Option<usize>,
    /// `force` or `trajectory`.
    pub level: &'static str,
    /// The sample times, s.
    pub t: Vec<f64>,
    /// The measured signal fitted (`f_stf` N or `x` m).
    pub measured: Vec<f64>,
    /// Each model's fit of it.
    pub fitted: Vec<Curve>,
}

/// Read the experiment's record (and `[validate]`'s second record).
fn load(exp: &mut Experiment, job: &Job) -> Result<(FitData, Option<ValidationRecord>), CallError> {
    if !exp.identify.is_empty() {
        let msg = "`[[identify]]` stages are not in the Python package yet: run \
                   `stf-lab fit` on this experiment";
        return Err(CallError::new(
            anyhow::anyhow!("{}: {msg}", exp.path.display()),
            Kind::Experiment,
        ));
    }
    job.say("reading the record");
    let data = load_data(exp).or_kind(Kind::Experiment)?;
    let validation = stf_lab::validation::load(exp, &data).or_kind(Kind::Experiment)?;
    job.cancel.check();
    Ok((data, validation))
}

/// Fit every model of the experiment to `data` (scored on `validation`'s record too).
fn fit_models(
    exp: &Experiment,
    data: &FitData,
    validation: Option<&ValidationRecord>,
    job: &Job,
) -> Result<Vec<ModelFit>, CallError> {
    job.say(format!("fitting {} model(s)", exp.models.len().max(1)));
    let mut fits = fit_all(exp, data, &Progress::new(true))
        .map_err(|e| CallError::new(e, fit_failure_kind(exp, data)))?;
    job.cancel.check();
    if let Some(rec) = validation {
        job.say("scoring the fits on the second record");
        stf_lab::validation::score_fits(&mut fits, rec);
    }
    Ok(fits)
}

/// What a failed `fit_all` was: a `[[models]]` entry naming a model that does not resolve
/// (`ModelError`), one that does not configure (a parameter unknown or out of bounds:
/// `ExperimentError`), or the fit itself (`FitError`). Asked only after a failure.
fn fit_failure_kind(exp: &Experiment, data: &FitData) -> Kind {
    let scales = data.scales(&exp.system);
    for entry in &exp.models {
        let one = std::slice::from_ref(entry);
        if configure_for(one, &exp.path, &exp.dir, &exp.scripts, Some(&scales)).is_err() {
            let unresolved = entry
                .specs()
                .any(|s| resolve(s, &exp.dir, &exp.scripts).is_err());
            return if unresolved {
                Kind::Model
            } else {
                Kind::Experiment
            };
        }
    }
    Kind::Fit
}

/// The index of the best fit by the verdict's rule.
fn best_of(fits: &[ModelFit]) -> Option<usize> {
    let scored: Vec<(f64, usize)> = fits
        .iter()
        .map(|f| {
            (
                f.result.aic,
                f.result.params.iter().filter(|p| !p.fixed).count(),
            )
        })
        .collect();
    stf_lab::verdict::best_by_aic(&scored)
}

/// The arrays of a fit outcome, moved out of `data` and `fits`.
fn curves(data: FitData, fits: Vec<ModelFit>) -> (Vec<f64>, Vec<f64>, Vec<Curve>) {
    let measured = data.target().to_vec();
    let fitted = fits.into_iter().map(|f| (f.label, f.fitted)).collect();
    (data.record.t, measured, fitted)
}

/// `stf-lab fit` without its files: `fit.json`'s content, the verdict and the curves.
pub fn fit(mut exp: Experiment, job: &Job) -> Result<FitOutcome, CallError> {
    let (data, validation) = load(&mut exp, job)?;
    let fits = fit_models(&exp, &data, validation.as_ref(), job)?;
    let json = json_text(&FitJson::new(&exp.path, &data, &fits))?;
    let verdict = stf_lab::verdict::fit_verdict(&fits, data.level);
    let level = stf_lab::outputs::level_name(data.level);
    let params_table = json_text(&stf_lab::param_table::rows_of_fits(&fits))?;
    let best = best_of(&fits);
    let (t, measured, fitted) = curves(data, fits);
    let regimes_table = "[]".to_string();
    Ok(FitOutcome {
        json,
        verdict,
        params_table,
        regimes_table,
        best,
        level,
        t,
        measured,
        fitted,
    })
}

/// The models' simulated resonance peak (|x| m, ω rad/s), none where a simulation fails.
/// Restates `cmd_compare`'s private `simulated_response` (its peak only) until the study
/// layer exposes the comparison.
fn simulated_peak(exp: &Experiment, data: &FitData, f: &ModelFit) -> anyhow::Result<(f64, f64)> {
    let k = &data.kinematics;
    let mut osc = Oscillator::new(f.system, k.excitation());
    if let Some(c) = &f.configured {
        osc = osc.with_model(c.model.clone(), f.model_values())?;
    }
    let (x0, v0) = k.initial_state();
    let run = Simulation::new(&osc)
        .settings(exp.integrator.clone())
        .initial(x0, v0)
        .run_at(&k.t)?;
    let p = peak(&run.t, &run.x, k.omega.as_deref()).context("empty simulation")?;
    Ok((p.amplitude, p.omega))
}

/// `stf-lab compare` without its files: `compare.json`'s content, the verdict and the fits'
/// curves. Restates `cmd_compare`'s private `compare_fits` (the frequency-response curves
/// of the report left out) until the study layer exposes it.
pub fn compare(mut exp: Experiment, job: &Job) -> Result<FitOutcome, CallError> {
    let (data, validation) = load(&mut exp, job)?;
    if data.level != FitLevel::Force {
        let msg = "compare scores models on the measured STF force; the record needs `f_stf`";
        return Err(CallError::new(
            anyhow::anyhow!("{}: {msg}", exp.path.display()),
            Kind::Experiment,
        ));
    }
    job.say("classifying the record's regimes");
    let measured = measured_regimes(&exp, &data).or_kind(Kind::Fit)?;
    let fits = fit_models(&exp, &data, validation.as_ref(), job)?;
    let sig = data.force_data();
    let comparisons: Vec<Comparison> = fits
        .iter()
        .map(|f| compare_regimes(&measured, &sig, &f.fitted, &exp.regimes))
        .collect::<Result<_, _>>()
        .map_err(|e| CallError::new(e.into(), Kind::Fit))?;
    job.cancel.check();
    job.say("simulating each model's resonance");
    let measured_peak = peak(
        &data.record.t,
        &data.record.x,
        data.kinematics.omega.as_deref(),
    )
    .context("empty record")
    .or_kind(Kind::Record)?;
    let responses = fits
        .iter()
        .map(|f| {
            simulated_peak(&exp, &data, f)
                .ok()
                .map(|p| (placeholder_curve(), p))
        })
        .collect();
    let labels: Vec<&str> = fits.iter().map(|f| f.label.as_str()).collect();
    let pairs: Vec<(&str, &Comparison)> = labels.iter().copied().zip(comparisons.iter()).collect();
    let ranking = rank_models(&pairs);
    let loop_rankings = rank_on_loops(&measured, &pairs);
    let c = Compared {
        measured,
        fits,
        comparisons,
        measured_peak,
        responses,
        ranking,
        loop_rankings,
    };
    let json = json_text(&CompareJson::new(&exp, &data, &c))?;
    let forces: Vec<(&str, &[f64])> = c
        .fits
        .iter()
        .map(|f| (f.label.as_str(), f.fitted.as_slice()))
        .collect();
    let f_stf = data.record.f_stf.as_deref().unwrap_or(&[]);
    let verdict = stf_lab::verdict::compare_verdict(
        &c.ranking,
        &c.measured.cycles,
        &c.measured.labels,
        f_stf,
        &forces,
    );
    let params_table = json_text(&stf_lab::param_table::rows_of_fits(&c.fits))?;
    let labels: Vec<&str> = c.fits.iter().map(|f| f.label.as_str()).collect();
    let regimes_table = json_text(&stf_lab::outputs::compare_csv::rows(
        &labels,
        &c.comparisons,
    ))?;
    let best = best_of(&c.fits);
    let (t, measured, fitted) = curves(data, c.fits);
    Ok(FitOutcome {
        json,
        verdict,
        params_table,
        regimes_table,
        best,
        level: "force",
        t,
        measured,
        fitted,
    })
}

/// The frequency-response curve compare.json does not read (its report draws it).
fn placeholder_curve() -> stf_lab::report::FrfCurve {
    stf_lab::report::FrfCurve {
        label: String::new(),
        omega: Vec::new(),
        x_peak: Vec::new(),
        role: stf_lab::report::FrfRole::Model,
    }
}

/// A synthetic record and the JSON summary of its run.
pub struct Simulated {
    /// The record, as `stf-lab simulate` writes it (sensor noise as `[simulate] noise` says).
    pub record: stf_core::data::record::Record,
}

/// The excitation of `drive` at the sample `times`, and whether it is a rotor. Restates
/// `cmd_simulate`'s private `excitation_of` until the study layer exposes the simulation.
fn excitation_of(drive: &Drive, times: &[f64]) -> (Excitation, bool) {
    match drive {
        Drive::Rotor(angle) => (Excitation::Rotor(angle.clone()), true),
        Drive::Free => (Excitation::None, false),
        Drive::Force(chirp) => {
            let u = times.iter().map(|&t| chirp.at(t)).collect();
            let held = if chirp.held() {
                Linear::held(times.to_vec(), u)
            } else {
                Linear::new(times.to_vec(), u)
            };
            (Excitation::Force(held), false)
        }
    }
}

/// `stf-lab simulate` without its files: the record of the experiment's `[simulate]`.
pub fn simulate(exp: Experiment, job: &Job) -> Result<Simulated, CallError> {
    let run = || -> anyhow::Result<Simulated> {
        let Some(spec) = &exp.simulate else {
            bail!(
                "{}: has no [simulate] section to make a record from",
                exp.path.display()
            );
        };
        let n = ((spec.t1 - spec.t0) * spec.rate).round() as usize + 1;
        let times: Vec<f64> = (0..n).map(|i| spec.t0 + i as f64 / spec.rate).collect();
        let (excitation, rotor) = excitation_of(&spec.drive, &times);
        let mut osc = Oscillator::new(exp.system, excitation);
        if !spec.truth.is_empty() {
            let truth = configure_for(&spec.truth, &exp.path, &exp.dir, &exp.scripts, None)?;
            let values = truth.values();
            osc = osc
                .with_model(truth.model, values)
                .context("cannot plug the truth model into the oscillator")?;
        }
        job.say(format!("simulating {:.1} s", spec.t1 - spec.t0));
        let sim = Simulation::new(&osc)
            .settings(exp.integrator.clone())
            .initial(spec.x0, spec.v0)
            .run_at(&times)
            .with_context(|| format!("simulation of {} failed", exp.path.display()))?;
        let noise = if spec.noise {
            SensorNoise::RIG
        } else {
            SensorNoise::NONE
        };
        let mut record = sample_record(&sim, &noise, spec.seed, rotor);
        record.source = format!("simulated from {}", exp.path.display());
        Ok(Simulated { record })
    };
    run().or_kind(Kind::Experiment)
}
