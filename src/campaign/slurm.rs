//! Submitting a campaign to Slurm (`--slurm`): the cluster's `MaxArraySize` is read
//! ([`max_array_size`]: `scontrol show config`, unless `[slurm] max_array_size` gives it), the
//! scripts of [`super::slurm_script`] are written into `DIR/slurm/` (atomically, so a user can
//! read and resubmit them), then `sbatch --parsable` submits each job array and, with
//! `--dependency=afterany:<id 1>:<id 2>…`, the collect job: it runs when every task of every
//! array has ended, however it ended, so a failed or killed unit is named by the collect step
//! instead of leaving the job waiting for ever. `--dry-run` shows the same scripts and
//! commands and runs nothing.
//!
//! Slurm is driven through its own client (`sbatch`), not a library: that is the interface
//! every site supports, and it keeps this program free of Slurm's C libraries.

use std::ffi::OsString;
use std::io::ErrorKind;
use std::path::Path;
use std::process::{Command, Stdio};

use anyhow::{bail, Context, Result};

use super::slurm_plan::SLURM_DEFAULT_MAX_ARRAY_SIZE;
use super::slurm_script::{unit_log, units_script, Job, Scripts, COLLECT_SCRIPT, UNIT_LOG_HEAD};
use crate::writing::write_atomic;

/// The job ids Slurm gave.
pub struct Submitted {
    /// The job arrays of the units, in order.
    pub units_jobs: Vec<String>,
    /// The collect job.
    pub collect_job: String,
}

/// The cluster's `MaxArraySize` and where it came from: `[slurm] max_array_size` when the
/// campaign gives it, else `scontrol show config`, else (no answer: a dry run away from the
/// cluster) Slurm's default, saying so.
pub fn max_array_size(given: Option<usize>) -> (usize, String) {
    if let Some(n) = given {
        return (n, "[slurm] max_array_size".into());
    }
    let said = Command::new("scontrol")
        .args(["show", "config"])
        .stdin(Stdio::null())
        .output();
    let why = match said {
        Ok(o) if o.status.success() => {
            match parse_max_array_size(&String::from_utf8_lossy(&o.stdout)) {
                Some(n) => {
                    return (
                        n,
                        "the cluster's MaxArraySize (scontrol show config)".into(),
                    )
                }
                None => "scontrol show config gave no MaxArraySize".to_string(),
            }
        }
        Ok(o) => format!(
            "scontrol show config failed ({}): {}",
            o.status,
            String::from_utf8_lossy(&o.stderr)
                .lines()
                .last()
                .unwrap_or("")
                .trim()
        ),
        Err(e) => format!("cannot run scontrol: {e}"),
    };
    (
        SLURM_DEFAULT_MAX_ARRAY_SIZE,
        format!(
            "Slurm's default MaxArraySize ({why}; give the cluster's as [slurm] max_array_size)"
        ),
    )
}

/// `MaxArraySize` in the output of `scontrol show config` (`MaxArraySize = 1001`).
pub fn parse_max_array_size(config: &str) -> Option<usize> {
    config.lines().find_map(|l| {
        let (key, value) = l.split_once('=')?;
        (key.trim() == "MaxArraySize").then(|| value.trim().parse().ok())?
    })
}

/// What `--dry-run` prints: each script under its path, then the `sbatch` commands.
pub fn dry_run_text(job: &Job, scripts: &Scripts) -> String {
    let folder = job.folder();
    let mut text = String::new();
    let named = scripts
        .units
        .iter()
        .enumerate()
        .map(|(i, body)| (units_script(i + 1), body))
        .chain([(COLLECT_SCRIPT.to_string(), &scripts.collect)]);
    for (name, body) in named {
        text.push_str(&format!(
            "==> {} <==\n{body}\n",
            folder.join(name).display()
        ));
    }
    text.push_str("==> submitted with <==\n");
    for line in commands_shown(&folder, scripts.units.len()) {
        text.push_str(&line);
        text.push('\n');
    }
    text
}

/// The `sbatch` command lines, the arrays' ids as `<units job K id>`.
fn commands_shown(folder: &Path, arrays: usize) -> Vec<String> {
    let mut lines: Vec<String> = (1..=arrays)
        .map(|k| {
            format!(
                "sbatch --parsable {}",
                folder.join(units_script(k)).display()
            )
        })
        .collect();
    let ids: Vec<String> = (1..=arrays)
        .map(|k| format!("<units job {k} id>"))
        .collect();
    lines.push(format!(
        "sbatch --parsable --dependency=afterany:{} {}",
        ids.join(":"),
        folder.join(COLLECT_SCRIPT).display()
    ));
    lines
}

/// Write the scripts into the job's folder, each atomically; array scripts of an earlier
/// submission that this one has not (`units-K.sbatch` beyond its arrays) are removed.
pub fn write_scripts(job: &Job, scripts: &Scripts) -> Result<()> {
    let folder = job.folder();
    crate::writing::atomic::ensure_dir(&folder)?;
    for (i, body) in scripts.units.iter().enumerate() {
        write_atomic(&folder.join(units_script(i + 1)), body.as_bytes())?;
    }
    write_atomic(&folder.join(COLLECT_SCRIPT), scripts.collect.as_bytes())?;
    for entry in std::fs::read_dir(&folder)?.filter_map(|e| e.ok()) {
        let name = entry.file_name().to_string_lossy().into_owned();
        let k = name
            .strip_prefix("units-")
            .and_then(|r| r.strip_suffix(".sbatch"))
            .and_then(|k| k.parse::<usize>().ok());
        if k.is_some_and(|k| k > scripts.units.len()) {
            std::fs::remove_file(entry.path()).with_context(|| {
                format!("cannot remove the stale script {}", entry.path().display())
            })?;
        }
    }
    Ok(())
}

/// Submit the written scripts: each array, then the collect job after all of them.
pub fn submit(job: &Job) -> Result<Submitted> {
    let folder = job.folder();
    let mut units_jobs: Vec<String> = Vec::new();
    for k in 1..=job.arrays.len() {
        let id = sbatch(&[
            "--parsable".into(),
            folder.join(units_script(k)).into_os_string(),
        ]);
        match id {
            Ok(id) => units_jobs.push(id),
            Err(e) if units_jobs.is_empty() => return Err(e),
            Err(e) => {
                return Err(e.context(format!(
                    "array {k} of {} was refused, after arrays 1 to {} were submitted as job(s) \
                     {}: cancel them (scancel {}) and submit again, or let them run and submit \
                     again when they have ended (their finished units are skipped)",
                    job.arrays.len(),
                    k - 1,
                    units_jobs.join(", "),
                    units_jobs.join(" ")
                )))
            }
        }
    }
    let collect_job = sbatch(&[
        "--parsable".into(),
        format!("--dependency=afterany:{}", units_jobs.join(":")).into(),
        folder.join(COLLECT_SCRIPT).into_os_string(),
    ])
    .with_context(|| {
        format!(
            "the units were submitted as job(s) {}, but not the collect job: when they have \
             ended, run the collect step by hand (the command line in {})",
            units_jobs.join(", "),
            folder.join(COLLECT_SCRIPT).display()
        )
    })?;
    Ok(Submitted {
        units_jobs,
        collect_job,
    })
}

/// Where a unit that did not finish was run on Slurm and how its task ended, read from the
/// logs in `folder` (`DIR/slurm/`): ` (its log: …/unit-N.log; its Slurm task …: "JOB 12 ON
/// node CANCELLED AT … DUE TO TIME LIMIT")`, or nothing when no Slurm task ran it.
pub fn unit_log_note(folder: &Path, n: usize) -> String {
    let log = folder.join(unit_log(n));
    let Ok(text) = std::fs::read_to_string(&log) else {
        return String::new();
    };
    let mut note = format!(" (its log: {}", log.display());
    let task_log = text
        .lines()
        .next()
        .filter(|l| l.starts_with(UNIT_LOG_HEAD))
        .and_then(|l| l.split("its log: ").nth(1))
        .map(|name| name.trim_end_matches(')').trim());
    if let Some(name) = task_log.filter(|n| !n.contains('/')) {
        let task = folder.join(name);
        let stopped = std::fs::read_to_string(&task).ok().and_then(|t| {
            t.lines()
                .rev()
                .find(|l| l.contains("***") && l.contains("CANCELLED"))
                .map(|l| l.split("***").nth(1).unwrap_or(l).trim().to_string())
        });
        match stopped {
            Some(why) => note.push_str(&format!(
                "; Slurm stopped its task: \"{why}\", see {}",
                task.display()
            )),
            None => note.push_str(&format!("; its task's log: {}", task.display())),
        }
    }
    note + ")"
}

/// Run `sbatch ARGS`; the job id it prints.
fn sbatch(args: &[OsString]) -> Result<String> {
    let output = Command::new("sbatch")
        .args(args)
        .stdin(Stdio::null())
        .output();
    let output = match output {
        Ok(o) => o,
        Err(e) if e.kind() == ErrorKind::NotFound => bail!(
            "sbatch is not on PATH: --slurm submits through Slurm's sbatch, so run it where \
             Slurm's client commands are (a login node); --dry-run shows the scripts without it"
        ),
        Err(e) => return Err(e).context("cannot run sbatch"),
    };
    let shown = args
        .iter()
        .map(|a| a.to_string_lossy())
        .collect::<Vec<_>>()
        .join(" ");
    if !output.status.success() {
        bail!(
            "sbatch {shown} failed ({}): {}",
            output.status,
            String::from_utf8_lossy(&output.stderr).trim()
        );
    }
    parse_job_id(&String::from_utf8_lossy(&output.stdout))
        .with_context(|| format!("sbatch {shown}"))
}

/// The job id of `sbatch --parsable`'s output: `1234` or `1234;cluster`.
pub fn parse_job_id(stdout: &str) -> Result<String> {
    let line = stdout.lines().map(str::trim).find(|l| !l.is_empty());
    let id = line.and_then(|l| l.split(';').next()).unwrap_or("");
    if id.is_empty() || !id.bytes().all(|b| b.is_ascii_digit()) {
        bail!("printed {:?}, not a job id", stdout.trim());
    }
    Ok(id.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn job_ids_are_read_with_or_without_a_cluster_name() {
        assert_eq!(parse_job_id("1234\n").unwrap(), "1234");
        assert_eq!(parse_job_id("77;north\n").unwrap(), "77");
        let e = parse_job_id("Submitted batch job 5\n").unwrap_err();
        assert!(e.to_string().contains("not a job id"), "{e}");
        assert!(parse_job_id("").is_err());
    }

    #[test]
    fn max_array_size_is_read_from_scontrol_s_config() {
        let config = "Configuration data as of 2026-11-27T22:00:00\n\
                      MailType                = (null)\n\
                      MaxArraySize            = 1001\n\
                      MaxJobCount             = 10000\n";
        assert_eq!(parse_max_array_size(config), Some(1001));
        assert_eq!(parse_max_array_size("MaxJobCount = 3\n"), None);
        assert_eq!(max_array_size(Some(3)).0, 3);
    }

    #[test]
    fn a_unit_s_note_names_its_logs_and_why_slurm_stopped_its_task() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(unit_log_note(dir.path(), 4), "");
        std::fs::write(
            dir.path().join("unit-4.log"),
            format!("{UNIT_LOG_HEAD} 77_1 (array 2; its log: array-2-task-1.log)\nfitting\n"),
        )
        .unwrap();
        let note = unit_log_note(dir.path(), 4);
        assert!(note.contains("unit-4.log; its task's log: "), "{note}");
        std::fs::write(
            dir.path().join("array-2-task-1.log"),
            "unit 4: its output in unit-4.log\nslurmstepd: error: *** JOB 79 ON n1 CANCELLED \
             AT 2026-11-27T23:00:00 DUE TO TIME LIMIT ***\n",
        )
        .unwrap();
        let note = unit_log_note(dir.path(), 4);
        assert!(
            note.contains(
                "Slurm stopped its task: \"JOB 79 ON n1 CANCELLED AT 2026-11-27T23:00:00 DUE TO \
                 TIME LIMIT\""
            ),
            "{note}"
        );
    }
}
