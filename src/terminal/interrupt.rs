//! Ctrl-C (SIGINT) or SIGTERM during a run: the program removes the results it was building
//! and its lock files, stops the child processes it started, says what had finished and what
//! was written, and exits with 130.
//!
//! Results are built apart (a staging folder, or staged files beside the outputs) and put in
//! place only at the end. Every file write ([`crate::writing::atomic`]) and every commit's
//! renames hold a shared guard ([`writing`], [`hold_off`]); the handler takes the guard
//! exclusively, so it waits for writes and renames under way and no write starts after it:
//! a staging folder it removes is never created again by a write still running, and its
//! message is true — either nothing was written (the earlier results are intact) or the new
//! results are all in place. A campaign's units run as child processes
//! ([`child_started`]); the handler sends them SIGTERM and waits for them to end before it
//! counts what finished ([`set_outcome`]). SIGKILL cannot be caught; what it leaves is
//! repaired or cleaned by the next run into the same output ([`crate::writing`]).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex, RwLock, RwLockReadGuard};
use std::time::Duration;

/// What the run has done so far, as the interrupt message tells it.
#[derive(Clone, Debug, Default)]
pub struct RunState {
    /// Finished steps, e.g. "fit of power_law".
    pub finished: Vec<String>,
    /// Staged results (folders or files) not yet in place: removed on an interrupt.
    pub staged: Vec<PathBuf>,
    /// Outputs in place, e.g. "out/fit".
    pub written: Vec<String>,
    /// The whole message after `interrupted: `, when the run keeps its own count (a
    /// campaign: which units finished).
    pub outcome: Option<String>,
}

static STATE: Mutex<RunState> = Mutex::new(RunState {
    finished: Vec::new(),
    staged: Vec::new(),
    written: Vec::new(),
    outcome: None,
});
static GUARD: RwLock<()> = RwLock::new(());
static INTERRUPTED: AtomicBool = AtomicBool::new(false);
static CHILDREN: Mutex<Vec<u32>> = Mutex::new(Vec::new());
static CHILDREN_GONE: Condvar = Condvar::new();

fn update(change: impl FnOnce(&mut RunState)) {
    if let Ok(mut s) = STATE.lock() {
        change(&mut s);
    }
}

/// Record that `what` (e.g. "fit of power_law") has finished.
pub fn finished_step(what: impl Into<String>) {
    update(|s| s.finished.push(what.into()));
}

/// Record results being built at `path` (removed if the run is interrupted).
pub fn staged(path: &Path) {
    update(|s| s.staged.push(path.to_path_buf()));
}

/// The staged results at `path` are gone (put in place or removed).
pub fn unstaged(path: &Path) {
    update(|s| s.staged.retain(|p| p != path));
}

/// Record that the results `what` (a path as the user gave it) are in place.
pub fn written(what: impl Into<String>) {
    update(|s| s.written.push(what.into()));
}

/// Set the interrupt message (after `interrupted: `) for a run that counts its own progress.
pub fn set_outcome(text: impl Into<String>) {
    update(|s| s.outcome = Some(text.into()));
}

/// Hold interrupts off while results are put in place: an interrupt waits until the guard is
/// dropped. (The same guard as [`writing`]; never hold two at once in one thread.)
pub fn hold_off() -> RwLockReadGuard<'static, ()> {
    GUARD
        .read()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Held while a file is written or a folder created: an interrupt waits for the write to
/// end, and a write does not start once the interrupt is being handled.
pub fn writing() -> RwLockReadGuard<'static, ()> {
    hold_off()
}

/// Whether the run has been interrupted (the handler has started).
pub fn is_interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// Start a child process with `start` unless the run is interrupted, and register it so an
/// interrupt stops it; `None` when interrupted (nothing started). Call [`child_ended`] when
/// it has ended and its outcome is recorded.
pub fn child_started<T>(
    start: impl FnOnce() -> std::io::Result<(T, u32)>,
) -> Option<std::io::Result<T>> {
    let mut children = CHILDREN.lock().unwrap_or_else(|e| e.into_inner());
    if is_interrupted() {
        return None;
    }
    Some(start().map(|(child, pid)| {
        children.push(pid);
        child
    }))
}

/// When the run has been interrupted, wait here for the handler to end the process (a run
/// whose children were stopped must not go on to write its tables).
pub fn park_if_interrupted() {
    while is_interrupted() {
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The child `pid` has ended and what it did is recorded.
pub fn child_ended(pid: u32) {
    let mut children = CHILDREN.lock().unwrap_or_else(|e| e.into_inner());
    children.retain(|&p| p != pid);
    CHILDREN_GONE.notify_all();
}

/// The interrupt message for a run in `state`.
pub fn message(state: &RunState) -> String {
    if let Some(outcome) = &state.outcome {
        return format!("interrupted: {outcome}");
    }
    if !state.written.is_empty() {
        return format!(
            "interrupted: the results were already written to {}",
            state.written.join(" and ")
        );
    }
    if state.finished.is_empty() {
        "interrupted: nothing had finished; no results were written (earlier results are intact)"
            .to_string()
    } else {
        format!(
            "interrupted: finished {}; no results were written for this run (earlier results are intact)",
            state.finished.join(", ")
        )
    }
}

/// Remove staged results (a folder or a file), best effort.
fn remove_staged(path: &Path) {
    if path.is_dir() {
        let _ = std::fs::remove_dir_all(path);
    } else {
        let _ = std::fs::remove_file(path);
    }
}

/// Send `signal` to every child still running.
#[cfg(unix)]
fn signal_children(children: &[u32], signal: nix::sys::signal::Signal) {
    for &pid in children {
        if let Ok(pid) = i32::try_from(pid) {
            let _ = nix::sys::signal::kill(nix::unistd::Pid::from_raw(pid), signal);
        }
    }
}

/// Stop the child processes: SIGTERM (each removes its own staged results and ends), then,
/// for any still running after `patience`, SIGKILL; wait until the runner has recorded each.
fn stop_children(patience: Duration) {
    let mut children = CHILDREN.lock().unwrap_or_else(|e| e.into_inner());
    INTERRUPTED.store(true, Ordering::SeqCst);
    #[cfg(unix)]
    signal_children(&children, nix::sys::signal::Signal::SIGTERM);
    for round in 0..2 {
        let wait = if round == 0 {
            patience
        } else {
            Duration::from_secs(5)
        };
        let (now, _) = CHILDREN_GONE
            .wait_timeout_while(children, wait, |c| !c.is_empty())
            .unwrap_or_else(|e| e.into_inner());
        children = now;
        if children.is_empty() {
            return;
        }
        #[cfg(unix)]
        signal_children(&children, nix::sys::signal::Signal::SIGKILL);
    }
}

/// Install the handler of Ctrl-C and SIGTERM (once; a failure to install is not fatal).
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        stop_children(Duration::from_secs(20));
        let _exclusive = GUARD.write().unwrap_or_else(|e| e.into_inner());
        let now = STATE.lock().map(|s| s.clone()).unwrap_or_default();
        for path in &now.staged {
            remove_staged(path);
        }
        crate::tell!("{}", message(&now));
        std::process::exit(130);
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_message_says_what_was_written() {
        let mut s = RunState::default();
        assert!(message(&s).contains("no results were written (earlier results are intact)"));
        s.finished.push("fit of viscous".into());
        let m = message(&s);
        assert!(
            m.contains("finished fit of viscous; no results were written"),
            "{m}"
        );
        s.written.push("out/fit".into());
        let m = message(&s);
        assert_eq!(
            m,
            "interrupted: the results were already written to out/fit"
        );
        s.outcome = Some("2 of 5 unit(s) had finished".into());
        assert_eq!(message(&s), "interrupted: 2 of 5 unit(s) had finished");
    }
}
