//! The local runner: a campaign's units as child processes of this same program
//! (`std::env::current_exe()` with `--unit N`, exactly what a Slurm array task will run), at
//! most `jobs` at once, so memory stays bounded by `jobs` units. Each child's terminal output
//! goes to `DIR/logs/<unit folder>.log`; one line is printed per unit as it finishes (ok or
//! failed, wall time). How a unit ended is read from its `unit.json`, checked against the
//! inputs' hash the runner expects; a child that died without one is a failure naming its
//! exit status and its log.
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
        let status = std::fs::File::create(&log)
            .and_then(|f| Ok((f.try_clone()?, f)))
            .and_then(|(out, err)| {
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
        let error = match status {
            Err(e) => Some(format!("cannot start {}: {e}", exe.display())),
            Ok(status) => match read_unit_json(&p.dir).filter(|u| u.inputs_hash == p.hash) {
                Some(u) if u.status == UnitStatus::Ok => None,
                Some(u) => Some(u.error.unwrap_or_else(|| "failed".into())),
                None => Some(format!(
                    "the unit ended ({status}) without writing its unit.json: see {}",
                    log.display()
                )),
            },
        };
        Finished {
            number: p.unit.number,
            error,
            wall,
        }
    }
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
