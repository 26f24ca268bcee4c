//! Every call into the lab's workflows, in one file: the study API (`stf_study::prelude`:
//! read an experiment, fit, identify, compare, discover; `stf_study::simulate` for a
//! `[simulate]` section). Each returns an owned [`Outcome`] — the JSON the command line writes (the same
//! `Serialize` type, its numbers tidied to the digits they carry as `stf-lab` writes them),
//! the report's verdict, the tables behind its CSV files and the arrays behind its figures —
//! and writes nothing.

use std::path::Path;

use serde::Serialize;
use stf_study::error::{ErrorKind, StudyError};
use stf_study::experiment::Experiment;
use stf_study::fitting::ModelFit;
use stf_study::outputs::identification_json::IdentificationJson;
use stf_study::prelude;

use crate::errors::{of_kind, study};
use crate::run::Run;
use crate::watch::Watch;

/// The experiment at `path`: read from the file, or from `text` (an experiment built in
/// Python; `path` then names it in messages and its folder is where relative paths start).
pub fn experiment(path: &Path, text: Option<&str>) -> Result<Experiment, StudyError> {
    match text {
        Some(text) => Experiment::parse(path, text).map_err(study),
        None => prelude::read_experiment(path),
    }
}

/// `value` as the command line writes it: JSON text, numbers to the digits they carry.
fn json_text<T: Serialize>(value: &T) -> Result<String, StudyError> {
    let mut v = serde_json::to_value(value).map_err(|e| {
        of_kind(
            ErrorKind::Experiment,
            format!("cannot serialize the result: {e}"),
        )
    })?;
    stf_study::digits::tidy_json(&mut v);
    Ok(v.to_string())
}

/// A curve: its label and its values at the record's times.
pub type Curve = (String, Vec<f64>);

/// What a workflow hands back.
#[derive(Default)]
pub struct Outcome {
    /// `fit.json`, `compare.json` or `discovery.json`, as text.
    pub json: String,
    /// The report's verdict.
    pub verdict: String,
    /// `params.csv`'s rows, as JSON text (`[]` for a discovery).
    pub params_table: String,
    /// `compare.csv`'s rows (models × regimes), as JSON text (`[]` but for a comparison).
    pub regimes_table: String,
    /// The best fit by the verdict's rule (the simplest within ΔAIC 2), its index.
    pub best: Option<usize>,
    /// `force` or `trajectory`.
    pub level: &'static str,
    /// The sample times, s.
    pub t: Vec<f64>,
    /// The measured signal (`f_stf` N or `x` m).
    pub measured: Vec<f64>,
    /// Each model's curve of it (for a discovery: `base` and `final`).
    pub curves: Vec<Curve>,
    /// The study's warnings about the inputs.
    pub warnings: Vec<String>,
    /// A discovery's final model as a `[[models]]` entry, and its `[system]` entry (TOML).
    pub entries: (String, String),
}

/// The best of `fits` by the verdict's rule.
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
    stf_study::verdict::best_by_aic(&scored)
}

/// The curves of `fits`, moved out.
fn curves_of(fits: Vec<ModelFit>) -> Vec<Curve> {
    fits.into_iter().map(|f| (f.label, f.fitted)).collect()
}

/// `stf-lab fit` (every model; no `[[identify]]`) without its files.
pub fn fit(mut exp: Experiment, run: &Run) -> Result<Outcome, StudyError> {
    let watch = Watch::new(run);
    let fitted = prelude::fit(&mut exp, &watch)?;
    let json = json_text(&fitted.json(&exp))?;
    let params_table = json_text(&fitted.param_rows())?;
    let verdict = fitted.verdict().text;
    let data = fitted.data;
    Ok(Outcome {
        json,
        verdict,
        params_table,
        regimes_table: "[]".into(),
        best: best_of(&fitted.fits),
        level: data.level.name(),
        measured: data.target().to_vec(),
        t: data.record.t,
        curves: curves_of(fitted.fits),
        warnings: watch.warnings(),
        entries: Default::default(),
    })
}

/// `stf-lab fit` of an experiment with `[[identify]]` stages: each stage's oscillator fit.
/// The curves are each stage's simulated x (their records differ: `t` and `measured` are
/// the last stage's).
pub fn identify(exp: Experiment, run: &Run) -> Result<Outcome, StudyError> {
    let watch = Watch::new(run);
    let found = prelude::identify(&exp, &watch)?;
    let units = stf_study::shown_units::ShownUnits::of(
        &exp.data_layout,
        stf_study::experiment::FitLevel::Trajectory,
    );
    let doc = IdentificationJson::new(
        &exp.path,
        &exp.identify,
        &found.stages,
        found.system,
        &units,
    );
    let json = json_text(&doc)?;
    let rows: Vec<_> = found
        .stages
        .iter()
        .enumerate()
        .flat_map(|(i, o)| {
            stf_study::param_table::rows_of(
                &format!("stage {}", i + 1),
                &o.result,
                None,
                &o.warnings,
                &units,
            )
        })
        .collect();
    let params_table = json_text(&rows)?;
    let mut out = Outcome {
        json,
        params_table,
        regimes_table: "[]".into(),
        level: "trajectory",
        warnings: watch.warnings(),
        ..Outcome::default()
    };
    for (i, stage) in found.stages.into_iter().enumerate() {
        out.curves
            .push((format!("stage {}", i + 1), stage.simulated));
        out.t = stage.t;
        out.measured = stage.x;
    }
    Ok(out)
}

/// `stf-lab compare` without its files.
pub fn compare(mut exp: Experiment, run: &Run) -> Result<Outcome, StudyError> {
    let watch = Watch::new(run);
    let result = prelude::compare(&mut exp, &watch)?;
    let json = json_text(&result.json(&exp))?;
    let c = &result.compared;
    let labels = c.labels();
    let regimes_table = json_text(&stf_study::outputs::compare_csv::rows(
        &labels,
        &c.comparisons,
    ))?;
    let params_table = json_text(&stf_study::param_table::rows_of_fits(
        &c.fits,
        &result.data.units,
    ))?;
    let verdict = stf_study::verdict::compare_verdict(c, result.data.words());
    let best = best_of(&c.fits);
    let data = result.data;
    Ok(Outcome {
        json,
        verdict,
        params_table,
        regimes_table,
        best,
        level: "force",
        measured: data.target().to_vec(),
        t: data.record.t,
        curves: curves_of(result.compared.fits),
        warnings: watch.warnings(),
        entries: Default::default(),
    })
}

/// `stf-lab discover` without its files: `discovery.json`, the verdict, the measured signal
/// with the base's and the final model's curves, and the final model's entries.
pub fn discover(mut exp: Experiment, run: &Run) -> Result<Outcome, StudyError> {
    let watch = Watch::new(run);
    let found = prelude::discover(&mut exp, &watch)?;
    let (doc, entries) = found.json(&exp).map_err(study)?;
    let json = json_text(&doc)?;
    let verdict = found.verdict().text;
    let (before, after) = found.modelled();
    let level = found.data.level.name();
    let measured = found.data.target().to_vec();
    Ok(Outcome {
        json,
        verdict,
        params_table: "[]".into(),
        regimes_table: "[]".into(),
        level,
        measured,
        t: found.data.record.t,
        curves: vec![("base".into(), before), ("final".into(), after)],
        warnings: watch.warnings(),
        entries,
        best: None,
    })
}

/// `stf-lab simulate` without its files: the record of the experiment's `[simulate]` and its
/// run's summary (the sidecar's `summary`: peak, breakaway, …) as JSON text.
pub fn simulate(
    exp: Experiment,
    run: &Run,
) -> Result<(stf_core::data::record::Record, String), StudyError> {
    run.say("simulating");
    let mut made = stf_study::simulate::simulate(&exp).map_err(study)?;
    made.record.source = format!("simulated from {}", exp.path.display());
    let summary = json_text(&made.summary)?;
    Ok((made.record, summary))
}
