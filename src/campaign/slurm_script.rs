//! The two Slurm batch scripts of a campaign (`--slurm`): a job array whose task N runs unit
//! N with the line the local runner runs (`stf-lab campaign C.toml --out DIR --unit N`), and
//! a collect job (`--collect`: the table, the report and `[global]` from the finished units).
//! Only text is built here; [`super::slurm`] writes and submits it.
//!
//! Paths are absolute, so the scripts run from any folder and can be resubmitted by hand.
//! The command lines are quoted by the `shlex` crate; the values that go into `#SBATCH`
//! lines (partition, time, memory, account, log paths) are checked instead, since Slurm
//! reads those lines with its own rules (`%` is a file-name pattern there, a space ends the
//! value).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// The folder of the scripts and the jobs' logs under the campaign's output.
pub const SLURM: &str = "slurm";

/// The array job's script in [`SLURM`].
pub const UNITS_SCRIPT: &str = "units.sbatch";

/// The collect job's script in [`SLURM`].
pub const COLLECT_SCRIPT: &str = "collect.sbatch";

/// What the command line sets of the jobs; `None` leaves it to the cluster's defaults.
#[derive(Clone, Debug, Default)]
pub struct SlurmOptions {
    /// `--partition`.
    pub partition: Option<String>,
    /// `--time`, per unit (and for the collect job).
    pub time: Option<String>,
    /// `--mem`, per unit (and for the collect job).
    pub mem: Option<String>,
    /// `--account`.
    pub account: Option<String>,
}

impl SlurmOptions {
    /// Refuse a value Slurm would not read as meant, naming its flag.
    pub fn check(&self) -> Result<()> {
        let name_chars = |c: char| c.is_ascii_alphanumeric() || "_.,-".contains(c);
        check_value("--partition", self.partition.as_deref(), name_chars)?;
        check_value("--account", self.account.as_deref(), name_chars)?;
        check_value("--time", self.time.as_deref(), |c| {
            c.is_ascii_digit() || c == ':' || c == '-'
        })?;
        if let Some(t) = &self.time {
            if !t.starts_with(|c: char| c.is_ascii_digit()) || t.ends_with([':', '-']) {
                bail!("--time {t}: give a time limit such as 01:30:00, 90 or 1-00:00:00");
            }
        }
        check_value("--mem", self.mem.as_deref(), |c| c.is_ascii_alphanumeric())?;
        if let Some(m) = &self.mem {
            let digits = m.trim_end_matches(['K', 'M', 'G', 'T']);
            if digits.is_empty()
                || !digits.bytes().all(|b| b.is_ascii_digit())
                || m.len() > digits.len() + 1
            {
                bail!("--mem {m}: give a size such as 2G or 500M (a number, then K, M, G or T)");
            }
        }
        Ok(())
    }

    /// The `#SBATCH` lines these options give.
    fn lines(&self) -> Vec<String> {
        [
            ("partition", &self.partition),
            ("time", &self.time),
            ("mem", &self.mem),
            ("account", &self.account),
        ]
        .into_iter()
        .filter_map(|(key, value)| value.as_ref().map(|v| format!("#SBATCH --{key}={v}")))
        .collect()
    }
}

/// A flag's value: not empty, only the characters `allowed` accepts.
fn check_value(flag: &str, value: Option<&str>, allowed: impl Fn(char) -> bool) -> Result<()> {
    match value {
        Some("") => bail!("{flag}: the value is empty"),
        Some(v) => match v.chars().find(|&c| !allowed(c)) {
            Some(c) => bail!("{flag} {v:?}: {c:?} is not allowed in this value"),
            None => Ok(()),
        },
        None => Ok(()),
    }
}

/// What the scripts run: absolute paths and the units to run.
pub struct Job<'a> {
    /// This program.
    pub exe: PathBuf,
    /// The campaign file.
    pub campaign: PathBuf,
    /// The campaign's output folder.
    pub out: PathBuf,
    /// The numbers of the units to run (the array's task ids), ascending.
    pub units: Vec<usize>,
    /// Rerun units even when finished (`--force`).
    pub force: bool,
    /// Partition, time, memory, account.
    pub options: &'a SlurmOptions,
}

/// The two scripts' text.
pub struct Scripts {
    /// The job array: one task per unit.
    pub units: String,
    /// The collect job.
    pub collect: String,
}

impl Job<'_> {
    /// The folder of the scripts and logs.
    pub fn folder(&self) -> PathBuf {
        self.out.join(SLURM)
    }

    /// Both scripts.
    pub fn scripts(&self) -> Result<Scripts> {
        let folder = self.folder();
        check_sbatch_path(&folder)?;
        let name = job_name(&self.campaign);
        let mut unit_line = self.command_line()?;
        unit_line.push_str(" --unit \"$SLURM_ARRAY_TASK_ID\" --quiet");
        if self.force {
            unit_line.push_str(" --force");
        }
        let units = self.script(
            &[
                format!("#SBATCH --job-name={name}"),
                format!("#SBATCH --array={}", array_spec(&self.units)),
                format!("#SBATCH --output={}/unit-%a.log", folder.display()),
            ],
            "# Task N runs unit N of the campaign, as a local run does.",
            &unit_line,
        );
        let collect = self.script(
            &[
                format!("#SBATCH --job-name={name}-collect"),
                format!("#SBATCH --output={}/collect.log", folder.display()),
            ],
            "# The campaign table, report and [global] fit from the finished units; a unit\n\
             # missing or failed is named and fails this job.",
            &(self.command_line()? + " --collect --quiet"),
        );
        Ok(Scripts { units, collect })
    }

    /// A script: the shebang, `head` and the options as `#SBATCH` lines, then `command`.
    fn script(&self, head: &[String], comment: &str, command: &str) -> String {
        let mut lines = vec!["#!/bin/sh".to_string()];
        lines.extend(head.iter().cloned());
        lines.extend(self.options.lines());
        lines.push("#SBATCH --ntasks=1".into());
        lines.push("#SBATCH --cpus-per-task=1".into());
        lines.push(format!("#SBATCH --chdir={}", self.folder().display()));
        lines.push(comment.into());
        lines.push(format!("exec {command}"));
        lines.join("\n") + "\n"
    }

    /// `EXE campaign C.toml --out DIR`, quoted for the shell.
    fn command_line(&self) -> Result<String> {
        let exe = quote(&self.exe)?;
        let campaign = quote(&self.campaign)?;
        let out = quote(&self.out)?;
        Ok(format!("{exe} campaign {campaign} --out {out}"))
    }
}

/// A path quoted for `sh`.
fn quote(path: &Path) -> Result<String> {
    let text = path.to_str().with_context(|| {
        format!(
            "{}: a path the batch script can hold must be UTF-8",
            path.display()
        )
    })?;
    Ok(shlex::try_quote(text)
        .with_context(|| format!("{}: cannot be quoted for the shell", path.display()))?
        .into_owned())
}

/// Refuse a folder Slurm's `--output` and `--chdir` lines would misread.
pub fn check_sbatch_path(folder: &Path) -> Result<()> {
    let text = folder.to_string_lossy();
    if let Some(c) = text
        .chars()
        .find(|c| c.is_whitespace() || c.is_control() || "%\"'\\".contains(*c))
    {
        bail!(
            "{}: Slurm's #SBATCH lines cannot hold a path with {c:?}: give --out a folder \
             whose path has no spaces, quotes, backslashes or %",
            folder.display()
        );
    }
    Ok(())
}

/// `stf-lab-<campaign file stem>`, with only letters, digits, `-`, `_` and `.`.
fn job_name(campaign: &Path) -> String {
    let stem = campaign
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let safe: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("stf-lab-{safe}")
}

/// The array's task ids in Slurm's list form, runs of consecutive numbers as ranges:
/// `1-3,5,7-8`.
pub fn array_spec(units: &[usize]) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut i = 0;
    while i < units.len() {
        let start = units[i];
        let mut end = start;
        while i + 1 < units.len() && units[i + 1] == end + 1 {
            i += 1;
            end = units[i];
        }
        parts.push(if end > start {
            format!("{start}-{end}")
        } else {
            start.to_string()
        });
        i += 1;
    }
    parts.join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn array_spec_lists_units_with_runs_as_ranges() {
        assert_eq!(array_spec(&[1, 3, 5]), "1,3,5");
        assert_eq!(array_spec(&[1, 2, 3, 5, 7, 8]), "1-3,5,7-8");
        assert_eq!(array_spec(&[4]), "4");
    }

    #[test]
    fn options_refuse_values_slurm_would_misread() {
        let with = |f: fn(&mut SlurmOptions)| {
            let mut o = SlurmOptions::default();
            f(&mut o);
            o.check().map_err(|e| e.to_string())
        };
        assert!(with(|o| {
            o.partition = Some("short,long".into());
            o.time = Some("01:30:00".into());
            o.mem = Some("2G".into());
            o.account = Some("lab-1".into());
        })
        .is_ok());
        let e = with(|o| o.partition = Some("a b".into())).unwrap_err();
        assert!(e.contains("--partition") && e.contains("' '"), "{e}");
        let e = with(|o| o.mem = Some("2GB".into())).unwrap_err();
        assert!(e.contains("--mem 2GB"), "{e}");
        let e = with(|o| o.time = Some("1:30:".into())).unwrap_err();
        assert!(e.contains("--time 1:30:"), "{e}");
        let e = with(|o| o.account = Some(String::new())).unwrap_err();
        assert!(e.contains("--account: the value is empty"), "{e}");
    }

    #[test]
    fn scripts_hold_the_unit_line_and_the_options() {
        let options = SlurmOptions {
            partition: Some("short".into()),
            time: Some("00:10:00".into()),
            mem: Some("1G".into()),
            account: None,
        };
        let job = Job {
            exe: "/opt/stf lab/stf-lab".into(),
            campaign: "/data/c.toml".into(),
            out: "/data/out".into(),
            units: vec![1, 2, 4],
            force: false,
            options: &options,
        };
        let s = job.scripts().unwrap();
        assert!(s.units.contains("#SBATCH --array=1-2,4\n"), "{}", s.units);
        assert!(s
            .units
            .contains("#SBATCH --output=/data/out/slurm/unit-%a.log\n"));
        assert!(s
            .units
            .contains("#SBATCH --partition=short\n#SBATCH --time=00:10:00\n"));
        assert!(s.units.contains("#SBATCH --mem=1G\n") && !s.units.contains("--account"));
        assert!(
            s.units.contains(
                "exec '/opt/stf lab/stf-lab' campaign /data/c.toml --out /data/out --unit \
                 \"$SLURM_ARRAY_TASK_ID\" --quiet\n"
            ),
            "{}",
            s.units
        );
        assert!(
            s.collect.contains(" --out /data/out --collect --quiet\n"),
            "{}",
            s.collect
        );
        assert!(!s.collect.contains("--array"));
    }

    #[test]
    fn an_output_folder_slurm_would_misread_is_refused() {
        let options = SlurmOptions::default();
        let job = Job {
            exe: "/bin/stf-lab".into(),
            campaign: "/c.toml".into(),
            out: "/data/run 100%".into(),
            units: vec![1],
            force: true,
            options: &options,
        };
        let e = job.scripts().err().unwrap().to_string();
        assert!(
            e.contains("/data/run 100%/slurm") && e.contains("' '"),
            "{e}"
        );
    }
}
