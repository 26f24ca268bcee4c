//! The Slurm batch scripts of a campaign (`--slurm`): one per job array
//! ([`super::slurm_plan`]), whose task I runs its units one after another, each with the line
//! the local runner runs (`stf-lab campaign C.toml --out DIR --unit N`) and its output in
//! `unit-N.log`, with the throttle (`%N`), CPUs per task and a time limit of `--time` per
//! unit; and a collect job (`--collect`: the table, the report and `[global]` from the
//! finished units). Only text is built here; [`super::slurm`] writes and submits it.
//!
//! Paths are absolute, so the scripts run from any folder and can be resubmitted by hand.
//! The command lines are quoted by the `shlex` crate; the values that go into `#SBATCH`
//! lines (partition, time, memory, account, log paths) are checked instead, since Slurm
//! reads those lines with its own rules (`%` is a file-name pattern there, a space ends the
//! value).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::slurm_plan::ArrayPlan;

/// The folder of the scripts and the jobs' logs under the campaign's output.
pub const SLURM: &str = "slurm";

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
            if seconds_of(t).is_none() {
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

    /// The `#SBATCH` lines these options give to a job of `units` units run one after
    /// another: its time limit is `--time` times `units`.
    fn lines(&self, units: usize) -> Vec<String> {
        let time = self.time.as_ref().map(|t| match (units, seconds_of(t)) {
            (1, _) | (_, None) => t.clone(),
            (n, Some(s)) => time_of(s.saturating_mul(n as u64)),
        });
        [
            ("partition", &self.partition),
            ("time", &time),
            ("mem", &self.mem),
            ("account", &self.account),
        ]
        .into_iter()
        .filter_map(|(key, value)| value.as_ref().map(|v| format!("#SBATCH --{key}={v}")))
        .collect()
    }
}

/// A Slurm time limit in seconds: `M`, `M:S`, `H:M:S`, `D-H`, `D-H:M` or `D-H:M:S`.
pub fn seconds_of(time: &str) -> Option<u64> {
    let (days, rest) = match time.split_once('-') {
        Some((d, r)) => (Some(d.parse::<u64>().ok()?), r),
        None => (None, time),
    };
    let parts: Vec<u64> = rest
        .split(':')
        .map(|p| p.parse::<u64>().ok())
        .collect::<Option<_>>()?;
    let (h, m, s) = match (days, parts.as_slice()) {
        (None, [m]) => (0, *m, 0),
        (None, [m, s]) => (0, *m, *s),
        (None, [h, m, s]) | (Some(_), [h, m, s]) => (*h, *m, *s),
        (Some(_), [h]) => (*h, 0, 0),
        (Some(_), [h, m]) => (*h, *m, 0),
        _ => return None,
    };
    Some(days.unwrap_or(0) * 86_400 + h * 3600 + m * 60 + s)
}

/// Seconds as a Slurm time limit: `HH:MM:SS`, or `D-HH:MM:SS` from a day on.
pub fn time_of(seconds: u64) -> String {
    let (d, rest) = (seconds / 86_400, seconds % 86_400);
    let hms = format!(
        "{:02}:{:02}:{:02}",
        rest / 3600,
        rest % 3600 / 60,
        rest % 60
    );
    match d {
        0 => hms,
        d => format!("{d}-{hms}"),
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
    /// The units to run, cut into arrays of tasks ([`super::slurm_plan`]).
    pub arrays: Vec<ArrayPlan>,
    /// Units per task: the time limit of a task is `--time` times this.
    pub units_per_task: usize,
    /// Tasks of one array running at once (`%N`), if limited.
    pub throttle: Option<usize>,
    /// `--cpus-per-task` of the array tasks.
    pub cpus_per_task: usize,
    /// Rerun units even when finished (`--force`).
    pub force: bool,
    /// Partition, time, memory, account.
    pub options: &'a SlurmOptions,
}

/// The scripts' text.
pub struct Scripts {
    /// The job arrays, in order: [`units_script`]`(1)`, `(2)`, ….
    pub units: Vec<String>,
    /// The collect job.
    pub collect: String,
}

/// The script of job array `k` (1-based) in [`SLURM`]: `units-K.sbatch`.
pub fn units_script(k: usize) -> String {
    format!("units-{k}.sbatch")
}

/// The log of task `task` of array `k` in [`SLURM`] (Slurm's own messages: a task cancelled,
/// timed out or preempted is said there); `%a` in the script.
pub fn task_log(k: usize, task: &str) -> String {
    format!("array-{k}-task-{task}.log")
}

/// The log of unit `n` in [`SLURM`]: the unit's output, written by its task.
pub fn unit_log(n: usize) -> String {
    format!("unit-{n}.log")
}

/// The first words of a unit's log: which Slurm task ran it and where that task's log is.
pub const UNIT_LOG_HEAD: &str = "[stf-lab campaign] run by Slurm task";

impl Job<'_> {
    /// The folder of the scripts and logs.
    pub fn folder(&self) -> PathBuf {
        self.out.join(SLURM)
    }

    /// Every unit of the job's arrays, in order.
    pub fn units(&self) -> Vec<usize> {
        self.arrays.iter().flat_map(ArrayPlan::units).collect()
    }

    /// All scripts.
    pub fn scripts(&self) -> Result<Scripts> {
        let folder = self.folder();
        check_sbatch_path(&folder)?;
        let units = (1..=self.arrays.len())
            .map(|k| self.units_script(k))
            .collect::<Result<Vec<_>>>()?;
        let name = job_name(&self.campaign);
        let mut lines = vec![
            format!("#SBATCH --job-name={name}-collect"),
            format!("#SBATCH --output={}/collect.log", folder.display()),
        ];
        lines.extend(self.options.lines(1));
        lines.push("#SBATCH --cpus-per-task=1".into());
        let collect = self.script(
            &lines,
            "# The campaign table, report and [global] fit from the finished units; a unit\n\
             # missing or failed is named and fails this job.",
            &format!("exec {} --collect --quiet", self.command_line()?),
        );
        Ok(Scripts { units, collect })
    }

    /// The script of array `k` (1-based): a `case` giving each task index its units, then a
    /// loop running them one after another, each into its own log.
    fn units_script(&self, k: usize) -> Result<String> {
        let array = &self.arrays[k - 1];
        let folder = self.folder();
        let throttle = self.throttle.map_or(String::new(), |t| format!("%{t}"));
        let mut lines = vec![
            format!("#SBATCH --job-name={}", job_name(&self.campaign)),
            format!("#SBATCH --array=0-{}{throttle}", array.tasks.len() - 1),
            format!(
                "#SBATCH --output={}/{}",
                folder.display(),
                task_log(k, "%a")
            ),
        ];
        lines.extend(self.options.lines(self.units_per_task));
        lines.push(format!("#SBATCH --cpus-per-task={}", self.cpus_per_task));
        let mut body = String::from("case \"$SLURM_ARRAY_TASK_ID\" in\n");
        for (i, units) in array.tasks.iter().enumerate() {
            let list: Vec<String> = units.iter().map(usize::to_string).collect();
            body.push_str(&format!("  {i}) units=\"{}\" ;;\n", list.join(" ")));
        }
        body.push_str(
            "  *) echo \"error: array task $SLURM_ARRAY_TASK_ID has no units\" >&2; exit 2 ;;\n\
             esac\n",
        );
        let mut unit_line = self.command_line()?;
        unit_line.push_str(" --unit \"$n\" --quiet");
        if self.force {
            unit_line.push_str(" --force");
        }
        let task_log = task_log(k, "$SLURM_ARRAY_TASK_ID");
        body.push_str(&format!(
            "failed=0\n\
             for n in $units; do\n\
             \x20 echo \"unit $n: its output in unit-$n.log\"\n\
             \x20 {{\n\
             \x20   echo \"{UNIT_LOG_HEAD} ${{SLURM_ARRAY_JOB_ID}}_$SLURM_ARRAY_TASK_ID \
             (array {k}; its log: {task_log})\"\n\
             \x20   {unit_line}\n\
             \x20 }} > \"unit-$n.log\" 2>&1 || failed=$((failed + 1))\n\
             done\n\
             if [ \"$failed\" -gt 0 ]; then\n\
             \x20 echo \"error: $failed unit(s) of this task failed: see their logs\" >&2\n\
             \x20 exit 1\n\
             fi"
        ));
        let comment = format!(
            "# Task I of this array runs the units listed for I below, one after another, each\n\
             # as a local run does (`--unit N`), its output in unit-N.log; {} unit(s) per task.",
            self.units_per_task
        );
        Ok(self.script(&lines, &comment, &body))
    }

    /// A script: the shebang, `head` as `#SBATCH` lines, then `body`.
    fn script(&self, head: &[String], comment: &str, body: &str) -> String {
        let mut lines = vec!["#!/bin/sh".to_string()];
        lines.extend(head.iter().cloned());
        lines.push("#SBATCH --ntasks=1".into());
        lines.push(format!("#SBATCH --chdir={}", self.folder().display()));
        lines.push(comment.into());
        lines.push(body.into());
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

    /// A job of `arrays` with the given options.
    fn job(options: &SlurmOptions, arrays: Vec<ArrayPlan>, per_task: usize) -> Job<'_> {
        Job {
            exe: "/opt/stf lab/stf-lab".into(),
            campaign: "/data/c.toml".into(),
            out: "/data/out".into(),
            arrays,
            units_per_task: per_task,
            throttle: None,
            cpus_per_task: 1,
            force: false,
            options,
        }
    }

    #[test]
    fn scripts_hold_the_unit_line_and_the_options() {
        let options = SlurmOptions {
            partition: Some("short".into()),
            time: Some("00:10:00".into()),
            mem: Some("1G".into()),
            account: None,
        };
        let arrays = crate::campaign::slurm_plan::arrays(&[1, 2, 4], 1, 1001);
        let s = job(&options, arrays, 1).scripts().unwrap();
        assert_eq!(s.units.len(), 1);
        let units = &s.units[0];
        assert!(units.contains("#SBATCH --array=0-2\n"), "{units}");
        assert!(units.contains("#SBATCH --output=/data/out/slurm/array-1-task-%a.log\n"));
        assert!(units.contains("#SBATCH --partition=short\n#SBATCH --time=00:10:00\n"));
        assert!(units.contains("#SBATCH --mem=1G\n") && !units.contains("--account"));
        assert!(units.contains("#SBATCH --cpus-per-task=1\n"));
        assert!(
            units.contains("  0) units=\"1\" ;;\n  1) units=\"2\" ;;\n  2) units=\"4\" ;;\n"),
            "{units}"
        );
        assert!(
            units.contains(
                "'/opt/stf lab/stf-lab' campaign /data/c.toml --out /data/out --unit \"$n\" \
                 --quiet\n"
            ),
            "{units}"
        );
        assert!(units.contains("} > \"unit-$n.log\" 2>&1"), "{units}");
        assert!(
            s.collect.contains(" --out /data/out --collect --quiet\n"),
            "{}",
            s.collect
        );
        assert!(!s.collect.contains("--array"));
        assert!(s.collect.contains("#SBATCH --time=00:10:00\n"));
    }

    #[test]
    fn tasks_of_several_units_get_their_time_a_throttle_and_cpus() {
        let options = SlurmOptions {
            time: Some("00:40:00".into()),
            ..SlurmOptions::default()
        };
        let arrays = crate::campaign::slurm_plan::arrays(&[1, 2, 3, 4, 5], 2, 2);
        let mut job = job(&options, arrays, 2);
        job.throttle = Some(3);
        job.cpus_per_task = 4;
        job.force = true;
        let s = job.scripts().unwrap();
        assert_eq!(s.units.len(), 2);
        assert!(
            s.units[0].contains("#SBATCH --array=0-1%3\n"),
            "{}",
            s.units[0]
        );
        assert!(s.units[0].contains("  0) units=\"1 2\" ;;\n  1) units=\"3 4\" ;;\n"));
        assert!(s.units[0].contains("#SBATCH --time=01:20:00\n"));
        assert!(s.units[0].contains("#SBATCH --cpus-per-task=4\n"));
        assert!(s.units[0].contains("--quiet --force\n"));
        assert!(s.units[1].contains("#SBATCH --array=0-0%3\n"));
        assert!(s.units[1].contains("  0) units=\"5\" ;;\n"));
        assert!(s.units[1].contains("array-2-task-%a.log"));
        assert!(s.collect.contains("#SBATCH --time=00:40:00\n"));
        assert!(s.collect.contains("#SBATCH --cpus-per-task=1\n"));
    }

    #[test]
    fn time_limits_are_read_and_written_in_slurm_s_forms() {
        assert_eq!(seconds_of("90"), Some(5400));
        assert_eq!(seconds_of("10:30"), Some(630));
        assert_eq!(seconds_of("01:30:00"), Some(5400));
        assert_eq!(seconds_of("1-2"), Some(93_600));
        assert_eq!(seconds_of("1-00:30"), Some(88_200));
        assert_eq!(seconds_of("2-01:00:05"), Some(176_405));
        assert_eq!(seconds_of("1:2:3:4"), None);
        assert_eq!(time_of(5400), "01:30:00");
        assert_eq!(time_of(176_405), "2-01:00:05");
    }

    #[test]
    fn an_output_folder_slurm_would_misread_is_refused() {
        let options = SlurmOptions::default();
        let mut job = job(
            &options,
            crate::campaign::slurm_plan::arrays(&[1], 1, 10),
            1,
        );
        job.out = "/data/run 100%".into();
        let e = job.scripts().err().unwrap().to_string();
        assert!(
            e.contains("/data/run 100%/slurm") && e.contains("' '"),
            "{e}"
        );
    }
}
