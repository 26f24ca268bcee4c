//! The local runner: a campaign's units as child processes of this same program
//! (`std::env::current_exe()` with `--unit N`, exactly what a Slurm array task will run), at
//! most `jobs` at once, so memory stays bounded by `jobs` units. Each child's terminal output
//! goes to `DIR/logs/<unit folder>.log`; one line is printed per unit as it finishes (ok or
//! failed, wall time). How a unit ended is read from its `unit.json`, checked against the
//! inputs' hash the runner expects; a child that died without one is a failure naming its
//! exit status and its log. A log is written to a temporary file beside it (the `tempfile`
//! crate) and renamed over the last one when the child has ended, so a run killed midway
//! leaves the previous log whole; a child that ended without its `unit.json` gets a closing
//! line saying that its log may stop short.
//!
//! Threads from the standard library: each only waits on its child, so a pool crate would
//! add nothing.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

use super::file::Unit;
use super::unit::{read_unit_json, UnitStatus};

/// The folder of the children's logs under the campaign's output.
pub const LOGS: &str = "logs";

/// A unit the runner is to run, with the hash its inputs have now.
pub struct Pending<'a> {
    /// The unit.
    pub unit: &'a Unit,
    /// Its folder.
    pub dir: PathBuf,
    /// Its inputs' hash.
    pub hash: String,
}

/// How a unit's run ended, as the runner saw it.
#[derive(Clone, Debug)]
pub struct Finished {
    /// The unit's number.
    pub number: usize,
    /// `None` when it wrote its results; else why not.
    pub error: Option<String>,
    /// Wall time of the child process.
    pub wall: Duration,
}

/// What the runner needs to start a unit.
pub struct Runner<'a> {
    /// The campaign file.
    pub campaign: &'a Path,
    /// The campaign's output folder.
    pub out: &'a Path,
    /// Units at once.
    pub jobs: usize,
}

impl Runner<'_> {
    /// Run `pending`, at most `jobs` at once; a progress line per unit as it finishes. The
    /// outcomes in the order of `pending`.
    pub fn run(&self, pending: &[Pending]) -> Result<Vec<Finished>> {
        let exe = std::env::current_exe().context("cannot find this program to run the units")?;
        let logs = self.out.join(LOGS);
        std::fs::create_dir_all(&logs)
            .with_context(|| format!("cannot create folder {}", logs.display()))?;
        let next = AtomicUsize::new(0);
        let done = Mutex::new(Vec::new());
        let total = pending.len();
        std::thread::scope(|s| {
            for _ in 0..self.jobs.clamp(1, total.max(1)) {
                s.spawn(|| loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(p) = pending.get(i) else { break };
                    let finished = self.run_child(&exe, &logs, p);
                    let mut done = done.lock().unwrap_or_else(|e| e.into_inner());
                    done.push((i, finished.clone()));
                    crate::say!("{}", progress_line(done.len(), total, p.unit, &finished));
                });
            }
        });
        let mut done = done.into_inner().unwrap_or_else(|e| e.into_inner());
        done.sort_by_key(|(i, _)| *i);
        Ok(done.into_iter().map(|(_, f)| f).collect())
    }

    /// One child: `stf-lab campaign C --out DIR --unit N --force --quiet`.
    fn run_child(&self, exe: &Path, logs: &Path, p: &Pending) -> Finished {
        let started = Instant::now();
        let log = logs.join(format!("{}.log", p.unit.folder_name()));
        let staged = tempfile::Builder::new()
            .prefix(&format!(".{}.", p.unit.folder_name()))
            .suffix(".log.tmp")
            .tempfile_in(logs);
        let status = staged
            .as_ref()
            .map_err(|e| e.kind().into())
            .and_then(|tmp| {
                let (out, err) = (tmp.as_file().try_clone()?, tmp.as_file().try_clone()?);
                Command::new(exe)
                    .arg("campaign")
                    .arg(self.campaign)
                    .arg("--out")
                    .arg(self.out)
                    .arg("--unit")
                    .arg(p.unit.number.to_string())
                    .args(["--force", "--quiet"])
                    .stdin(Stdio::null())
                    .stdout(out)
                    .stderr(err)
                    .status()
            });
        let wall = started.elapsed();
        let unit_json = read_unit_json(&p.dir).filter(|u| u.inputs_hash == p.hash);
        let partial = unit_json.is_none();
        let mut error = match (status, unit_json) {
            (Err(e), _) => Some(format!("cannot start {}: {e}", exe.display())),
            (Ok(_), Some(u)) if u.status == UnitStatus::Ok => None,
            (Ok(_), Some(u)) => Some(u.error.unwrap_or_else(|| "failed".into())),
            (Ok(status), None) => Some(format!(
                "the unit ended ({status}) without writing its unit.json: see {}",
                log.display()
            )),
        };
        if let Ok(tmp) = staged {
            if let Err(e) = finish_log(tmp, &log, partial) {
                error.get_or_insert_with(|| format!("cannot write {}: {e}", log.display()));
            }
        }
        Finished {
            number: p.unit.number,
            error,
            wall,
        }
    }
}

/// Put the child's staged log in place at `log`; `partial`: the child ended without its
/// `unit.json` (killed, crashed), which a last line says (its output may stop short).
fn finish_log(tmp: tempfile::NamedTempFile, log: &Path, partial: bool) -> std::io::Result<()> {
    if partial {
        use std::io::{Seek, SeekFrom, Write};
        let mut f = tmp.as_file();
        f.seek(SeekFrom::End(0))?;
        writeln!(
            f,
            "\n[stf-lab campaign] the unit ended without writing its unit.json: this log may \
             stop short of what the unit did"
        )?;
    }
    tmp.persist(log).map(|_| ()).map_err(|e| e.error)
}

/// `[3/9] unit 4 rec_a2_c1.csv: ok, 2.4 s` (or `failed, 0.3 s: why`).
fn progress_line(count: usize, total: usize, unit: &Unit, f: &Finished) -> String {
    let head = format!(
        "[{count}/{total}] unit {} {}",
        unit.number, unit.record_given
    );
    let secs = f.wall.as_secs_f64();
    match &f.error {
        None => format!("{head}: ok, {secs:.1} s"),
        Some(e) => format!("{head}: failed, {secs:.1} s: {}", first_line(e)),
    }
}

/// The first line of a message.
fn first_line(text: &str) -> &str {
    text.lines().next().unwrap_or("")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_log_replaces_the_last_one_whole_and_says_when_it_may_stop_short() {
        let dir = tempfile::tempdir().unwrap();
        let log = dir.path().join("001-r.log");
        std::fs::write(&log, "the last run's log\n").unwrap();
        let staged = tempfile::NamedTempFile::new_in(dir.path()).unwrap();
        std::fs::write(staged.path(), "fitted 1 model(s)\n").unwrap();
        // Until the child ends, the last log is untouched.
        assert_eq!(
            std::fs::read_to_string(&log).unwrap(),
            "the last run's log\n"
        );
        finish_log(staged, &log, false).unwrap();
        assert_eq!(
            std::fs::read_to_string(&log).unwrap(),
            "fitted 1 model(s)\n"
        );
        let staged = tempfile::NamedTempFile::new_in(dir.path()).unwrap();
        std::fs::write(staged.path(), "reading the rec").unwrap();
        finish_log(staged, &log, true).unwrap();
        let text = std::fs::read_to_string(&log).unwrap();
        assert!(
            text.starts_with(
                "reading the rec\n[stf-lab campaign] the unit ended without writing its unit.json"
            ),
            "{text}"
        );
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
