//! One unit of a campaign — record N, its experiment, its command — run in this process into
//! `DIR/units/<NNN>-<record stem>/`: `stf-lab campaign C.toml --out DIR --unit N`. The local
//! runner starts it as a child process; a Slurm array task will run the same line, so a
//! cluster run and a local run give identical unit outputs.
//!
//! The unit's folder is locked from the start of its run to the end (`crate::writing::lock`),
//! so no other run writes it meanwhile. The unit runs the command's study call
//! (`stf_study::fit`, `compare`, `discover`) and writes its results folder as the command does
//! ([`crate::results`], swapped in whole, `crate::writing::results_dir`), then
//! `unit.json` ([`UnitJson`]) beside them, atomically: a unit killed midway leaves no
//! `unit.json` that matches its inputs, so it is rerun. A unit whose command fails gets a
//! folder holding only its `unit.json` (status `failed`, the error); if even that cannot be
//! written (the folder holds a file stf-lab did not write) the unit's error says so, and its
//! earlier `unit.json` stays as it was. Without `--force` a unit whose `unit.json` says `ok`
//! with the same inputs' hash ([`super::hash`]) is skipped.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use indexmap::IndexMap;
use serde::{Deserialize, Serialize};

use super::file::{Campaign, CommandName, Unit};
use super::hash::unit_hash;
use crate::experiment::Experiment;
use crate::terminal::progress::Progress;
use crate::writing::lock::OutputLock;
use crate::writing::results_dir::ResultsDir;
use crate::writing::write_json;
use stf_study::observer::Observer;

/// The folder of unit folders under the campaign's output.
pub const UNITS: &str = "units";

/// The name of a unit's own record of its run.
pub const UNIT_JSON: &str = "unit.json";

/// How a unit ended.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum UnitStatus {
    /// The command wrote its results.
    Ok,
    /// The command failed; `error` says why.
    Failed,
}

/// `unit.json`: what a unit ran on, its inputs' hash and how it ended.
#[derive(Clone, Debug, Deserialize, Serialize)]
pub struct UnitJson {
    /// The unit's number (`--unit N`, 1-based: the campaign file's N-th record).
    pub unit: usize,
    /// The record, as written in the campaign file.
    pub record: String,
    /// The experiment, as written in the campaign file.
    pub experiment: String,
    /// `fit`, `compare` or `discover`.
    pub command: CommandName,
    /// The record's conditions, by name.
    pub conditions: IndexMap<String, f64>,
    /// SHA-256 of the unit's inputs and the program's version (hex).
    pub inputs_hash: String,
    /// The program's version.
    pub version: String,
    /// `ok` or `failed`.
    pub status: UnitStatus,
    /// The command's error, when failed.
    pub error: Option<String>,
    /// Wall time of the command, s.
    pub wall_seconds: f64,
}

/// The folder of `unit` under the campaign output `out`.
pub fn unit_dir(out: &Path, unit: &Unit) -> PathBuf {
    out.join(UNITS).join(unit.folder_name())
}

/// The `unit.json` in `dir`, if there is one that reads.
pub fn read_unit_json(dir: &Path) -> Option<UnitJson> {
    let text = std::fs::read_to_string(dir.join(UNIT_JSON)).ok()?;
    serde_json::from_str(&text).ok()
}

/// The hash of `unit`'s inputs (its experiment loaded to find the files it reads).
pub fn inputs_hash(unit: &Unit) -> Result<String> {
    let exp = Experiment::load(&unit.experiment)?;
    unit_hash(unit, &exp)
}

/// Whether `dir` holds a finished run of a unit whose inputs hash to `hash`, its results
/// file included (one deleted by hand makes the unit run again).
pub fn is_current(dir: &Path, hash: &str) -> bool {
    read_unit_json(dir).is_some_and(|u| {
        u.status == UnitStatus::Ok && u.inputs_hash == hash && results_missing(dir, &u).is_none()
    })
}

/// The results file of a unit that finished `ok` in `dir`, if it is no longer there (deleted
/// by hand): the campaign table cannot read the unit, so it runs again.
pub fn results_missing(dir: &Path, unit: &UnitJson) -> Option<&'static str> {
    let file = super::unit_results::results_file(unit.command);
    (unit.status == UnitStatus::Ok && !dir.join(file).is_file()).then_some(file)
}

/// Run unit `number` of `campaign` into its folder under `out` (skipped, without `force`,
/// when it is current). The unit's record of its run; an error if its command failed (the
/// failure is in its `unit.json` too).
pub fn run_one(
    campaign: &Campaign,
    number: usize,
    out: &Path,
    force: bool,
    quiet: bool,
) -> Result<UnitJson> {
    run_one_observed(campaign, number, out, force, &Progress::new(quiet))
}

/// [`run_one`], the unit's study watched by `observer` (a front end's own: Python's).
pub fn run_one_observed(
    campaign: &Campaign,
    number: usize,
    out: &Path,
    force: bool,
    observer: &dyn Observer,
) -> Result<UnitJson> {
    let unit = campaign.unit(number)?;
    let dir = unit_dir(out, unit);
    let exp = Experiment::load(&unit.experiment)?;
    let hash = unit_hash(unit, &exp)?;
    if !force {
        if let Some(done) = read_unit_json(&dir).filter(|_| is_current(&dir, &hash)) {
            crate::say!(
                "unit {number} ({}): unchanged since its last run, skipped",
                unit.record_given
            );
            return Ok(done);
        }
    }
    crate::writing::atomic::ensure_dir(&out.join(UNITS))
        .with_context(|| format!("cannot create folder {}", out.join(UNITS).display()))?;
    let _lock = OutputLock::acquire(&dir)?;
    let started = Instant::now();
    let exp = exp.with_data_file(unit.record.clone());
    let result = run_study(unit.command, exp, &dir, observer);
    let mut json = UnitJson {
        unit: number,
        record: unit.record_given.clone(),
        experiment: unit.experiment_given.clone(),
        command: unit.command,
        conditions: unit.conditions.iter().cloned().collect(),
        inputs_hash: hash,
        version: env!("CARGO_PKG_VERSION").to_string(),
        status: UnitStatus::Ok,
        error: None,
        wall_seconds: started.elapsed().as_secs_f64(),
    };
    match result {
        Ok(()) => {
            write_json(&dir.join(UNIT_JSON), &json)?;
            Ok(json)
        }
        Err(e) => {
            json.status = UnitStatus::Failed;
            json.error = Some(format!("{e:#}"));
            let failed = format!("unit {number} ({}) failed", unit.record_given);
            match write_failed(&dir, &json) {
                Ok(()) => Err(e.context(failed)),
                Err(w) => Err(e.context(format!(
                    "{failed}, and its unit.json could not be written either ({w:#})"
                ))),
            }
        }
    }
}

/// Run the unit's study (`command` on `exp`) and write its results folder in `dir`, swapped
/// in whole: the same study calls and writers as the command's.
fn run_study(
    command: CommandName,
    mut exp: Experiment,
    dir: &Path,
    progress: &dyn Observer,
) -> Result<()> {
    let results = ResultsDir::begin(dir, true)?;
    let out = results.path();
    match command {
        CommandName::Fit if !exp.identify.is_empty() => {
            let found = stf_study::identify::identify(&exp, progress)?;
            crate::results::fit::write_identification(&exp, out, &found)?;
        }
        CommandName::Fit => {
            let fitted = stf_study::fit::fit(&mut exp, progress)?;
            crate::results::fit::write(&exp, &fitted, out)?;
        }
        CommandName::Compare => {
            let compared = stf_study::compare::compare(&mut exp, progress)?;
            crate::results::compare::write(&exp, &compared, out)?;
        }
        CommandName::Discover => {
            let found = stf_study::discover::discover(&mut exp, progress)?;
            crate::results::discover::write(&exp, &found, out)?;
        }
    }
    results.commit()
}

/// A folder holding only the failed unit's `unit.json`, swapped in whole.
fn write_failed(dir: &Path, json: &UnitJson) -> Result<()> {
    let results = ResultsDir::begin(dir, true)?;
    write_json(&results.path().join(UNIT_JSON), json)?;
    results.commit()
}
