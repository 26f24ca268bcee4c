//! Submitting a campaign to Slurm (`--slurm`): the scripts of [`super::slurm_script`] are
//! written into `DIR/slurm/` (atomically, so a user can read and resubmit them), then
//! `sbatch --parsable` submits the job array and, with `--dependency=afterany:<array id>`,
//! the collect job: it runs when every task has ended, however it ended, so a failed unit is
//! named by the collect step instead of leaving the job waiting for ever. `--dry-run` shows
//! the same scripts and commands and runs nothing.
//!
//! Slurm is driven through its own client (`sbatch`), not a library: that is the interface
//! every site supports, and it keeps this program free of Slurm's C libraries.

use std::ffi::OsString;
use std::io::ErrorKind;
use std::path::Path;
use std::process::{Command, Stdio};

use anyhow::{bail, Context, Result};

use super::slurm_script::{Job, Scripts, COLLECT_SCRIPT, UNITS_SCRIPT};
use crate::writing::write_atomic;

/// The job ids Slurm gave.
pub struct Submitted {
    /// The job array of the units.
    pub units_job: String,
    /// The collect job.
    pub collect_job: String,
}

/// What `--dry-run` prints: each script under its path, then the `sbatch` commands.
pub fn dry_run_text(job: &Job, scripts: &Scripts) -> String {
    let folder = job.folder();
    let mut text = String::new();
    for (name, body) in [
        (UNITS_SCRIPT, &scripts.units),
        (COLLECT_SCRIPT, &scripts.collect),
    ] {
        text.push_str(&format!(
            "==> {} <==\n{body}\n",
            folder.join(name).display()
        ));
    }
    text.push_str("==> submitted with <==\n");
    for line in commands_shown(&folder) {
        text.push_str(&line);
        text.push('\n');
    }
    text
}

/// The two `sbatch` command lines, the array's id as `<units job id>`.
fn commands_shown(folder: &Path) -> [String; 2] {
    [
        format!("sbatch --parsable {}", folder.join(UNITS_SCRIPT).display()),
        format!(
            "sbatch --parsable --dependency=afterany:<units job id> {}",
            folder.join(COLLECT_SCRIPT).display()
        ),
    ]
}

/// Write both scripts into the job's folder, each atomically.
pub fn write_scripts(job: &Job, scripts: &Scripts) -> Result<()> {
    let folder = job.folder();
    crate::writing::atomic::ensure_dir(&folder)?;
    write_atomic(&folder.join(UNITS_SCRIPT), scripts.units.as_bytes())?;
    write_atomic(&folder.join(COLLECT_SCRIPT), scripts.collect.as_bytes())
}

/// Submit the written scripts: the array, then the collect job after it.
pub fn submit(job: &Job) -> Result<Submitted> {
    let folder = job.folder();
    let units_job = sbatch(&[
        "--parsable".into(),
        folder.join(UNITS_SCRIPT).into_os_string(),
    ])?;
    let collect_job = sbatch(&[
        "--parsable".into(),
        format!("--dependency=afterany:{units_job}").into(),
        folder.join(COLLECT_SCRIPT).into_os_string(),
    ])
    .with_context(|| {
        format!(
            "the units were submitted as job {units_job}, but not the collect job: when they \
             have ended, run the collect step by hand (the command line in {})",
            folder.join(COLLECT_SCRIPT).display()
        )
    })?;
    Ok(Submitted {
        units_job,
        collect_job,
    })
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
}
