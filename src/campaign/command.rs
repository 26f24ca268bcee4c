//! `stf-lab campaign CAMPAIGN.toml --out DIR`: run every unit of a campaign (`crate::campaign`)
//! — at most `--jobs` at once, each in a child process — skipping those whose inputs have not
//! changed since they finished (unless `--force`), then write the campaign table and report.
//! With `--unit N` it runs unit N alone, in this process: what each child, and later each
//! Slurm array task, runs. With a `[global]` section, the joint fit of all records
//! (`crate::campaign::global`) follows the units, into `DIR/global.json` and the report's
//! first section. `campaign.json`, `campaign.csv`, `report.md` and `report.html` are put in
//! place as one unit (`crate::writing::staged_files`). Interrupted, the run stops its units
//! and says how many finished (`crate::campaign::runner`); it writes no table then.
//!
//! With `--slurm` the units not finished are submitted instead as Slurm job arrays (cut by
//! `crate::campaign::slurm_plan` within the cluster's `MaxArraySize`), and a job after all of
//! them runs `--collect`: the table, report and `[global]` fit from the units' folders
//! — the same step a local run ends with — naming every unit that is missing or failed
//! (`crate::campaign::slurm`). `--dry-run` shows what `--slurm` would submit.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{bail, Context, Error, Result};

use crate::campaign::runner::{Pending, Runner};
use crate::campaign::slurm_script::{Job, SlurmOptions, SLURM};
use crate::campaign::unit::{
    inputs_hash, read_unit_json, results_missing, run_one, run_one_observed, unit_dir, UnitStatus,
};
use crate::campaign::{global, out_dir, report, table, Campaign, Unit};
use crate::campaign::{slurm, slurm_plan, slurm_script};
use crate::say;
use crate::writing::staged_files::StagedFiles;
use crate::writing::{resolve, write_json};
use stf_study::observer::Observer;

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
    /// Only build the table, report and `[global]` fit from the finished units.
    pub collect: bool,
    /// Submit to Slurm instead of running here.
    pub slurm: Option<SlurmSettings>,
}

/// `--slurm` and its settings.
pub struct SlurmSettings {
    /// Partition, time, memory and account of the jobs.
    pub options: SlurmOptions,
    /// Print the scripts and commands; submit and write nothing.
    pub dry_run: bool,
}

/// Run `stf-lab campaign`.
pub fn run(path: &Path, out: &Path, settings: &Settings) -> Result<()> {
    let campaign = Campaign::load(path)?;
    if let Some(n) = settings.unit {
        crate::campaign::runner::die_with_parent();
        out_dir::check(out)?;
        run_one(&campaign, n, out, settings.force, settings.quiet)?;
        say!("wrote {}", unit_dir(out, campaign.unit(n)?).display());
        return Ok(());
    }
    if settings.collect {
        let _lock = out_dir::begin(out)?;
        return collect(&campaign, out);
    }
    if let Some(slurm) = &settings.slurm {
        return submit(&campaign, out, settings.force, slurm);
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
    crate::terminal::interrupt::park_if_interrupted();
    finish(&campaign, out, &errors)
}

/// Run the campaign at `path` into `out` in this process, as `stf-lab campaign` does but one
/// unit after another with no child processes: for a front end that is not this program
/// (Python has no `stf-lab` to start). The units not finished (all with `force`) run the
/// study watched by `observer`; then the table, report and `[global]` fit are written. Asked
/// to stop (`observer.cancelled()`), it stops between units and writes no table; the units
/// that finished keep their folders.
pub fn run_in_process(path: &Path, out: &Path, force: bool, observer: &dyn Observer) -> Result<()> {
    let campaign = Campaign::load(path)?;
    let _lock = out_dir::begin(out)?;
    let pending = plan(&campaign, out, force)?;
    let mut errors = BTreeMap::new();
    for (i, p) in pending.iter().enumerate() {
        if observer.cancelled() {
            return Err(stf_study::error::Interrupted.into());
        }
        let unit = p.unit;
        observer.note(&format!(
            "unit {} of {} to run: {}",
            i + 1,
            pending.len(),
            unit.record_given
        ));
        if let Err(e) = run_one_observed(&campaign, unit.number, out, true, observer) {
            errors.insert(unit.number, format!("{e:#}"));
        }
    }
    finish(&campaign, out, &errors)
}

/// `--collect`: the table, report and `[global]` fit from the units' folders, as a run ends;
/// a unit without a `unit.json` of its present inputs is a failed row saying it did not
/// finish (and where its Slurm log is, if it has one).
fn collect(campaign: &Campaign, out: &Path) -> Result<()> {
    let mut errors = BTreeMap::new();
    for unit in &campaign.units {
        let dir = unit_dir(out, unit);
        let why = match read_unit_json(&dir) {
            None => format!("it did not finish: no unit.json in {}", dir.display()),
            Some(u) if u.inputs_hash != inputs_hash(unit)? => format!(
                "it did not finish: the unit.json in {} is from other inputs",
                dir.display()
            ),
            Some(_) => continue,
        };
        let log = slurm::unit_log_note(&out.join(SLURM), unit.number);
        errors.insert(unit.number, format!("{why}{log}"));
    }
    finish(campaign, out, &errors)
}

/// `--slurm`: submit the units not finished as a job array and the collect step after it
/// (or, with `--dry-run`, show the scripts and commands). Nothing to run: collect here.
fn submit(campaign: &Campaign, out: &Path, force: bool, settings: &SlurmSettings) -> Result<()> {
    settings.options.check()?;
    slurm_script::check_sbatch_path(&resolve(out).join(SLURM))?;
    let lock = match settings.dry_run {
        true => {
            out_dir::check(out)?;
            None
        }
        false => Some(out_dir::begin(out)?),
    };
    let pending = plan(campaign, out, force)?;
    say!(
        "campaign {}: {} unit(s), {} to run",
        campaign.path.display(),
        campaign.units.len(),
        pending.len()
    );
    if pending.is_empty() {
        if settings.dry_run {
            say!("nothing would be submitted: without --dry-run the table is collected here");
            return Ok(());
        }
        say!("nothing to submit: the table is collected here");
        return collect(campaign, out);
    }
    let job = slurm_job(campaign, out, force, &pending, &settings.options)?;
    let scripts = job.scripts()?;
    if settings.dry_run {
        say!("dry run: nothing is submitted or written\n");
        say!("{}", slurm::dry_run_text(&job, &scripts).trim_end());
        return Ok(());
    }
    slurm::write_scripts(&job, &scripts)?;
    let ids = slurm::submit(&job)?;
    drop(lock);
    let folder = job.folder();
    for (k, (id, array)) in ids.units_jobs.iter().zip(&job.arrays).enumerate() {
        say!(
            "units job: {id} (array {} of {}: {} task(s), units {}; logs {}/unit-N.log)",
            k + 1,
            job.arrays.len(),
            array.tasks.len(),
            slurm_script::array_spec(&array.units().collect::<Vec<_>>()),
            folder.display()
        );
    }
    say!(
        "collect job: {} (after job(s) {} end, log {}/collect.log)",
        ids.collect_job,
        ids.units_jobs.join(", "),
        folder.display()
    );
    say!(
        "follow with: squeue -j {},{}; the table and report are written into {} by the collect \
         job",
        ids.units_jobs.join(","),
        ids.collect_job,
        out.display()
    );
    Ok(())
}

/// The Slurm jobs of `pending`: units per task and arrays within the cluster's
/// `MaxArraySize`, from the campaign's `[slurm]` settings or their defaults (said).
fn slurm_job<'a>(
    campaign: &Campaign,
    out: &Path,
    force: bool,
    pending: &[Pending],
    options: &'a SlurmOptions,
) -> Result<Job<'a>> {
    let spec = &campaign.slurm;
    let (max_array_size, source) = slurm::max_array_size(spec.max_array_size);
    let commands: Vec<_> = pending.iter().map(|p| p.unit.command).collect();
    let per_task = spec
        .units_per_task
        .unwrap_or_else(|| slurm_plan::default_units_per_task(&commands));
    let units: Vec<usize> = pending.iter().map(|p| p.unit.number).collect();
    let arrays = slurm_plan::arrays(&units, per_task, max_array_size);
    say!(
        "{} unit(s) in {} task(s) of at most {per_task} unit(s) ({}), {} array(s) of at most \
         {max_array_size} task(s) ({source})",
        units.len(),
        arrays.iter().map(|a| a.tasks.len()).sum::<usize>(),
        match spec.units_per_task {
            Some(_) => "[slurm] units_per_task",
            None => "the default for these commands",
        },
        arrays.len(),
    );
    Ok(Job {
        exe: std::env::current_exe().context("cannot find this program for the batch scripts")?,
        campaign: resolve(&campaign.path),
        out: resolve(out),
        arrays,
        units_per_task: per_task,
        throttle: spec.throttle,
        cpus_per_task: spec.cpus_per_task.unwrap_or(1),
        force,
        options,
    })
}

/// The table, report and `[global]` fit of the units in `out`; `errors` holds, by unit, why
/// a unit has no results. An error naming the failed units after everything is written.
fn finish(campaign: &Campaign, out: &Path, errors: &BTreeMap<usize, String>) -> Result<()> {
    crate::terminal::interrupt::set_outcome(format!(
        "every unit had ended (their results are in {}); the campaign's table and report were \
         not written for this run (earlier ones are intact)",
        out.join(crate::campaign::unit::UNITS).display()
    ));
    let table = table::collect(campaign, out, errors);
    let (global, global_error) = global_fit(campaign, out);
    let mut staged = StagedFiles::new();
    write_json(&staged.stage(&out.join("campaign.json"))?, &table)?;
    table::write_csv(&staged.stage(&out.join("campaign.csv"))?, &table)?;
    let drawn = report::write(&table, global.as_ref(), out, &mut staged)?;
    staged.commit()?;
    crate::terminal::interrupt::set_outcome(format!(
        "the units, the campaign's table and its report were already written to {}",
        out.display()
    ));
    report::remove_stale_figures(&drawn, &out.join("figures"))?;
    if let Some(g) = &global {
        say!("global fit: {}", g.verdict);
        let values: Vec<String> = g
            .params
            .iter()
            .map(|p| {
                let value = stf_study::digits::with_error(p.value, p.std_error);
                let unit = if p.unit.is_empty() {
                    String::new()
                } else {
                    format!(" {}", p.unit)
                };
                format!("{} = {value}{unit} ({})", p.name, p.role)
            })
            .collect();
        say!("  {} over the records: {}", g.model, values.join(", "));
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
            "{} of {} unit(s) failed: their rows in {} say why{global}{}",
            table.failed,
            table.units,
            out.join("campaign.csv").display(),
            failed_units(&table)
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
        let missing = last.as_ref().and_then(|u| results_missing(&dir, u));
        let reason = match &last {
            _ if force => None,
            None => None,
            Some(u) if u.inputs_hash != hash => Some("its inputs changed: rerun".to_string()),
            Some(u) if u.status == UnitStatus::Failed => {
                Some("it failed last time: rerun".to_string())
            }
            Some(_) if missing.is_some() => {
                missing.map(|file| format!("its {file} is missing from {}: rerun", dir.display()))
            }
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

/// A line per failed unit of `table`: `\n  unit 3 (rec.csv): why` (the first line of why).
fn failed_units(table: &table::CampaignJson) -> String {
    let mut seen = std::collections::BTreeSet::new();
    let mut text = String::new();
    for row in table.rows.iter().filter(|r| r.status != "ok") {
        if seen.insert(row.unit) {
            let why = row.error.as_deref().unwrap_or("failed");
            let why = why.lines().next().unwrap_or("");
            text.push_str(&format!("\n  unit {} ({}): {why}", row.unit, row.record));
        }
    }
    text
}

/// `unit 3 (rec.csv)`.
fn name(unit: &Unit) -> String {
    format!("unit {} ({})", unit.number, unit.record_given)
}
