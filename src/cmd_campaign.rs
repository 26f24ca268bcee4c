//! `stf-lab campaign CAMPAIGN.toml --out DIR`: run every unit of a campaign (`crate::campaign`)
//! — at most `--jobs` at once, each in a child process — skipping those whose inputs have not
//! changed since they finished (unless `--force`), then write the campaign table and report.
//! With `--unit N` it runs unit N alone, in this process: what each child, and later each
//! Slurm array task, runs. With a `[global]` section, the joint fit of all records
//! (`crate::campaign::global`) follows the units, into `DIR/global.json` and the report's
//! first section.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Error, Result};

use crate::campaign::runner::{Pending, Runner};
use crate::campaign::unit::{inputs_hash, read_unit_json, run_one, unit_dir, UnitStatus};
use crate::campaign::{global, out_dir, report, table, Campaign, Unit};
use crate::output::write_json;
use crate::say;

/// The command line's settings.
pub struct Settings {
    /// Rerun every unit, finished or not.
    pub force: bool,
    /// No progress display.
    pub quiet: bool,
    /// Units at once (default: the machine's cores).
    pub jobs: Option<usize>,
    /// Run this unit alone, in this process.
    pub unit: Option<usize>,
}

/// Run `stf-lab campaign`.
pub fn run(path: &Path, out: &Path, settings: &Settings) -> Result<()> {
    let campaign = Campaign::load(path)?;
    if let Some(n) = settings.unit {
        out_dir::check(out)?;
        run_one(&campaign, n, out, settings.force, settings.quiet)?;
        say!("wrote {}", unit_dir(out, campaign.unit(n)?).display());
        return Ok(());
    }
    if settings.jobs == Some(0) {
        bail!("--jobs 0: give at least 1");
    }
    let _lock = out_dir::begin(out)?;
    let pending = plan(&campaign, out, settings.force)?;
    let jobs = settings
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    say!(
        "campaign {}: {} unit(s), {} to run, at most {jobs} at once",
        path.display(),
        campaign.units.len(),
        pending.len()
    );
    let runner = Runner {
        campaign: path,
        out,
        jobs,
    };
    let errors: BTreeMap<usize, String> = runner
        .run(&pending)?
        .into_iter()
        .filter_map(|f| f.error.map(|e| (f.number, e)))
        .collect();
    let table = table::collect(&campaign, out, &errors);
    write_json(&out.join("campaign.json"), &table)?;
    table::write_csv(&out.join("campaign.csv"), &table)?;
    let (global, global_error) = global_fit(&campaign, out);
    report::write(&table, global.as_ref(), out)?;
    if let Some(g) = &global {
        say!("global fit: {}", g.verdict);
        say!("wrote {}", out.join(global::GLOBAL_JSON).display());
    }
    say!(
        "wrote {0}/campaign.csv, {0}/campaign.json ({1} row(s)), {0}/report.html, {0}/report.md \
         and {0}/figures/",
        out.display(),
        table.rows.len()
    );
    if table.failed > 0 {
        let global = global_error.map_or(String::new(), |e| {
            format!("; the [global] fit failed too: {e:#}")
        });
        bail!(
            "{} of {} unit(s) failed: their rows in {} say why{global}",
            table.failed,
            table.units,
            out.join("campaign.csv").display()
        );
    }
    if let Some(e) = global_error {
        return Err(e.context("the campaign's [global] fit failed"));
    }
    Ok(())
}

/// The `[global]` fit, written to `DIR/global.json`, or its error; without `[global]` (or
/// when it fails) a `global.json` left by an earlier run is removed, so none is stale.
fn global_fit(campaign: &Campaign, out: &Path) -> (Option<global::GlobalJson>, Option<Error>) {
    let stale = || {
        let _ = std::fs::remove_file(out.join(global::GLOBAL_JSON));
    };
    match campaign
        .global
        .as_ref()
        .map(|_| global::write(campaign, out))
    {
        Some(Ok(g)) => (Some(g), None),
        Some(Err(e)) => {
            stale();
            (None, Some(e))
        }
        None => {
            stale();
            (None, None)
        }
    }
}

/// The units to run, each with its inputs' hash; a line for each unit skipped or rerun
/// with the reason.
fn plan<'a>(campaign: &'a Campaign, out: &Path, force: bool) -> Result<Vec<Pending<'a>>> {
    let mut pending = Vec::new();
    for unit in &campaign.units {
        let dir = unit_dir(out, unit);
        let hash = inputs_hash(unit)?;
        let last = read_unit_json(&dir);
        let reason = match &last {
            _ if force => None,
            None => None,
            Some(u) if u.inputs_hash != hash => Some("its inputs changed: rerun"),
            Some(u) if u.status == UnitStatus::Failed => Some("it failed last time: rerun"),
            Some(_) => {
                say!("{}: unchanged since its last run, skipped", name(unit));
                continue;
            }
        };
        if let Some(reason) = reason {
            say!("{}: {reason}", name(unit));
        }
        pending.push(Pending { unit, dir, hash });
    }
    Ok(pending)
}

/// `unit 3 (rec.csv)`.
fn name(unit: &Unit) -> String {
    format!("unit {} ({})", unit.number, unit.record_given)
}
