//! The local runner: a campaign's units as child processes of this same program
//! (`std::env::current_exe()` with `--unit N`, exactly what a Slurm array task will run), at
//! most `jobs` at once, so memory stays bounded by `jobs` units. Each child's terminal output
//! goes to `DIR/logs/<unit folder>.log`; one line is printed per unit as it finishes (ok or
//! failed, wall time).
//!
//! How a unit ended is read from the `unit.json` its child wrote — a new one, checked against
//! the inputs' hash the runner expects: a `unit.json` left by an earlier run never passes for
//! this run's (a child that refused to replace its folder ends with an error, and the unit is
//! failed with it). A child that wrote none is a failure naming its exit status, its error
//! and its log. A log is written to a temporary file beside it (`crate::writing::atomic`)
//! and renamed over the last one when the child has ended, so a run killed midway leaves the
//! previous log whole (and the next run removes the temporary); a child that ended without
//! its `unit.json` gets a closing line saying that its log may stop short.
//!
//! Children die with the campaign: each asks the kernel for SIGTERM when its parent ends
//! (`PR_SET_PDEATHSIG`, [`die_with_parent`]), so even a SIGKILLed campaign leaves no unit
//! running; on Ctrl-C or SIGTERM the campaign stops them and waits for them
//! (`crate::terminal::interrupt`), then says how many units finished. A unit still locked by a child
//! of an earlier run (one that had not yet ended) is waited for before it is started again.
//!
//! Threads from the standard library: each only waits on its child, so a pool crate would
//! add nothing.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

use super::file::Unit;
use super::unit::{read_unit_json, UnitStatus, UNIT_JSON};
use crate::writing::atomic::AtomicFile;
use crate::writing::lock::{holder, is_held_elsewhere};

/// The folder of the children's logs under the campaign's output.
pub const LOGS: &str = "logs";

/// The variable that tells a unit's process the id of the campaign that started it.
pub const PARENT_ENV: &str = "STF_LAB_CAMPAIGN_PARENT";

/// How long a unit still locked by an earlier run's child is waited for.
const LIVE_UNIT_PATIENCE: Duration = Duration::from_secs(60);

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
        crate::writing::atomic::ensure_dir(&logs)?;
        let next = AtomicUsize::new(0);
        let done = Mutex::new(Vec::new());
        let total = pending.len();
        crate::terminal::interrupt::set_outcome(interrupted_text(self.out, pending, &[]));
        std::thread::scope(|s| {
            for _ in 0..self.jobs.clamp(1, total.max(1)) {
                s.spawn(|| loop {
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(p) = pending.get(i) else { break };
                    if crate::terminal::interrupt::is_interrupted() {
                        break;
                    }
                    let (finished, pid) = self.run_child(&exe, &logs, p);
                    let mut done = done.lock().unwrap_or_else(|e| e.into_inner());
                    done.push((i, finished.clone()));
                    crate::terminal::interrupt::set_outcome(interrupted_text(
                        self.out, pending, &done,
                    ));
                    crate::say!("{}", progress_line(done.len(), total, p.unit, &finished));
                    if let Some(pid) = pid {
                        crate::terminal::interrupt::child_ended(pid);
                    }
                });
            }
        });
        let mut done = done.into_inner().unwrap_or_else(|e| e.into_inner());
        done.sort_by_key(|(i, _)| *i);
        Ok(done.into_iter().map(|(_, f)| f).collect())
    }

    /// One child: `stf-lab campaign C --out DIR --unit N --force --quiet`. How it ended, and
    /// its process id if it was started (to be told to [`crate::terminal::interrupt::child_ended`]
    /// once its outcome is recorded).
    fn run_child(&self, exe: &Path, logs: &Path, p: &Pending) -> (Finished, Option<u32>) {
        let started = Instant::now();
        let log = logs.join(format!("{}.log", p.unit.folder_name()));
        let before = stamp(&p.dir.join(UNIT_JSON));
        let staged = AtomicFile::create(&log).map_err(|e| e.to_string());
        let ran = staged.as_ref().map_err(Clone::clone).and_then(|tmp| {
            wait_for_live_unit(p)?;
            self.start(exe, p, tmp)
        });
        let wall = started.elapsed();
        let fresh = stamp(&p.dir.join(UNIT_JSON)) != before;
        let unit_json = read_unit_json(&p.dir).filter(|u| fresh && u.inputs_hash == p.hash);
        let partial = unit_json.is_none();
        let pid = ran.as_ref().ok().map(|(_, pid)| *pid);
        let mut error = match (&ran, unit_json) {
            (_, Some(u)) if u.status == UnitStatus::Ok => None,
            (_, Some(u)) => Some(u.error.unwrap_or_else(|| "failed".into())),
            (Err(e), None) => Some(e.clone()),
            (Ok((status, _)), None) => Some(without_unit_json(*status, &staged, &log)),
        };
        if let Ok(tmp) = staged {
            if let Err(e) = finish_log(tmp, partial) {
                error.get_or_insert_with(|| format!("cannot write {}: {e}", log.display()));
            }
        }
        let finished = Finished {
            number: p.unit.number,
            error,
            wall,
        };
        (finished, pid)
    }

    /// Start the child with its output to `log` and wait for it: its exit status and id.
    fn start(
        &self,
        exe: &Path,
        p: &Pending,
        log: &AtomicFile,
    ) -> Result<(ExitStatus, u32), String> {
        let cannot = |e: std::io::Error| format!("cannot start {}: {e}", exe.display());
        let out = log.as_file().try_clone().map_err(cannot)?;
        let err = log.as_file().try_clone().map_err(cannot)?;
        let mut command = Command::new(exe);
        command
            .arg("campaign")
            .arg(self.campaign)
            .arg("--out")
            .arg(self.out)
            .arg("--unit")
            .arg(p.unit.number.to_string())
            .args(["--force", "--quiet"])
            .env(PARENT_ENV, std::process::id().to_string())
            .stdin(Stdio::null())
            .stdout(out)
            .stderr(err);
        let started = crate::terminal::interrupt::child_started(|| {
            let child = command.spawn()?;
            let id = child.id();
            Ok((child, id))
        });
        match started {
            None => Err("not started: the campaign was interrupted".into()),
            Some(Err(e)) => Err(cannot(e)),
            Some(Ok(mut child)) => {
                let id = child.id();
                let status = child.wait();
                match status {
                    Ok(status) => Ok((status, id)),
                    Err(e) => {
                        crate::terminal::interrupt::child_ended(id);
                        Err(format!("cannot wait for unit {}: {e}", p.unit.number))
                    }
                }
            }
        }
    }
}

/// When the unit's folder is still locked by a process of an earlier run (a unit left running
/// by a campaign that was killed), wait for it to end; refuse after [`LIVE_UNIT_PATIENCE`].
fn wait_for_live_unit(p: &Pending) -> Result<(), String> {
    if !is_held_elsewhere(&p.dir) {
        return Ok(());
    }
    let who = holder(&p.dir).map_or(String::new(), |pid| format!(" (process {pid})"));
    crate::say!(
        "unit {} {}: still being written by an earlier run{who}; waiting for it to end",
        p.unit.number,
        p.unit.record_given
    );
    let until = Instant::now() + LIVE_UNIT_PATIENCE;
    while is_held_elsewhere(&p.dir) {
        if Instant::now() > until || crate::terminal::interrupt::is_interrupted() {
            return Err(format!(
                "{} is still being written by an earlier run{who}; rerun when it has ended",
                p.dir.display()
            ));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    Ok(())
}

/// What identifies the file at `path` (a rewrite renames a new file into place, so any
/// rewrite changes it); `None` if there is none.
fn stamp(path: &Path) -> Option<(u64, u64, Option<std::time::SystemTime>)> {
    let meta = std::fs::metadata(path).ok()?;
    #[cfg(unix)]
    let (dev, ino) = {
        use std::os::unix::fs::MetadataExt;
        (meta.dev(), meta.ino())
    };
    #[cfg(not(unix))]
    let (dev, ino) = (0, meta.len());
    Some((dev, ino, meta.modified().ok()))
}

/// Why a unit whose child ended (`status`) has no new `unit.json`: its error as its log
/// says it, and where the log is.
fn without_unit_json(
    status: ExitStatus,
    staged: &Result<AtomicFile, String>,
    log: &Path,
) -> String {
    let said = staged
        .as_ref()
        .ok()
        .and_then(|tmp| std::fs::read_to_string(tmp.path()).ok())
        .and_then(|text| {
            text.lines()
                .rev()
                .find_map(|l| l.strip_prefix("error: ").map(str::to_string))
        });
    match said {
        Some(e) => format!(
            "{e} (the unit ended, {status}, without writing a new unit.json: see {})",
            log.display()
        ),
        None => format!(
            "the unit ended ({status}) without writing a new unit.json: see {}",
            log.display()
        ),
    }
}

/// The interrupt message of a run of `pending` into `out` with `done` ended (by index):
/// how many finished (their folders in place), failed or were stopped, and not started.
fn interrupted_text(out: &Path, pending: &[Pending], done: &[(usize, Finished)]) -> String {
    let numbers = |ok: bool| -> Vec<String> {
        let mut n: Vec<usize> = done
            .iter()
            .filter(|(_, f)| f.error.is_none() == ok)
            .map(|(_, f)| f.number)
            .collect();
        n.sort_unstable();
        n.iter().map(usize::to_string).collect()
    };
    let (ok, not_ok) = (numbers(true), numbers(false));
    let mut text = format!(
        "{} of {} unit(s) to run had finished",
        ok.len(),
        pending.len()
    );
    if !ok.is_empty() {
        text.push_str(&format!(
            " (unit {}: their results are in {}, and a rerun skips them)",
            ok.join(", "),
            out.join(super::unit::UNITS).display()
        ));
    }
    if !not_ok.is_empty() {
        text.push_str(&format!(
            "; {} failed or were stopped (unit {})",
            not_ok.len(),
            not_ok.join(", ")
        ));
    }
    let rest = pending.len() - done.len();
    if rest > 0 {
        text.push_str(&format!(
            "; {rest} were stopped or not started (they wrote nothing)"
        ));
    }
    text + "; the campaign's table and report were not written for this run (earlier ones are \
            intact)"
}

/// Put the child's staged log in place; `partial`: the child ended without its `unit.json`
/// (killed, crashed, refused), which a last line says (its output may stop short).
fn finish_log(tmp: AtomicFile, partial: bool) -> Result<(), crate::writing::WriteError> {
    if partial {
        use std::io::{Seek, SeekFrom, Write};
        let note = (|| {
            let mut f = tmp.as_file();
            f.seek(SeekFrom::End(0))?;
            writeln!(
                f,
                "\n[stf-lab campaign] the unit ended without writing its unit.json: this log may \
                 stop short of what the unit did"
            )
        })();
        if let Err(source) = note {
            return Err(crate::writing::WriteError::Io {
                path: tmp.path().to_path_buf(),
                source,
            });
        }
    }
    tmp.commit()
}

/// In a unit's process started by a campaign ([`PARENT_ENV`]): ask to be sent SIGTERM when
/// that campaign ends, however it ends, and end now if it has ended already. (Run by hand,
/// without the variable, a unit is left alone.)
pub fn die_with_parent() {
    let Some(parent) = std::env::var_os(PARENT_ENV) else {
        return;
    };
    #[cfg(target_os = "linux")]
    {
        use nix::sys::signal::Signal;
        let _ = nix::sys::prctl::set_pdeathsig(Signal::SIGTERM);
        let now = nix::unistd::getppid().as_raw().to_string();
        if parent.to_string_lossy() != now {
            crate::tell!("error: the campaign that started this unit has ended");
            std::process::exit(130);
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = parent;
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
        let staged = AtomicFile::create(&log).unwrap();
        std::fs::write(staged.path(), "fitted 1 model(s)\n").unwrap();
        // Until the child ends, the last log is untouched.
        assert_eq!(
            std::fs::read_to_string(&log).unwrap(),
            "the last run's log\n"
        );
        finish_log(staged, false).unwrap();
        assert_eq!(
            std::fs::read_to_string(&log).unwrap(),
            "fitted 1 model(s)\n"
        );
        let staged = AtomicFile::create(&log).unwrap();
        std::fs::write(staged.path(), "reading the rec").unwrap();
        finish_log(staged, true).unwrap();
        let text = std::fs::read_to_string(&log).unwrap();
        assert!(
            text.starts_with(
                "reading the rec\n[stf-lab campaign] the unit ended without writing its unit.json"
            ),
            "{text}"
        );
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn a_rewritten_file_has_a_new_stamp() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("unit.json");
        assert_eq!(stamp(&p), None);
        crate::writing::write_atomic(&p, b"{}").unwrap();
        let first = stamp(&p);
        assert!(first.is_some());
        crate::writing::write_atomic(&p, b"{}").unwrap();
        assert_ne!(stamp(&p), first);
    }
}
