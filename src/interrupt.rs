//! Ctrl-C (SIGINT) or SIGTERM during a run: the program removes the results it was building,
//! says what had finished and what was written, and exits with 130.
//!
//! Results are built apart (a staging folder, or staged files beside the outputs) and put in
//! place only at the end, by renames made while [`hold_off`] is held: an interrupt that
//! arrives then waits for them to finish, so its message is true — either nothing was
//! written (the earlier results are intact) or the new results are all in place. SIGKILL
//! cannot be caught; what it leaves is repaired or cleaned by the next run into the same
//! output ([`crate::results_dir`]).

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// What the run has done so far, as the interrupt message tells it.
#[derive(Clone, Debug, Default)]
pub struct RunState {
    /// Finished steps, e.g. "fit of power_law".
    pub finished: Vec<String>,
    /// Staged results (folders or files) not yet in place: removed on an interrupt.
    pub staged: Vec<PathBuf>,
    /// Outputs in place, e.g. "out/fit".
    pub written: Vec<String>,
}

static STATE: Mutex<RunState> = Mutex::new(RunState {
    finished: Vec::new(),
    staged: Vec::new(),
    written: Vec::new(),
});
static SWAP: Mutex<()> = Mutex::new(());

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

/// Hold interrupts off while results are put in place: an interrupt waits until the guard is
/// dropped.
pub fn hold_off() -> MutexGuard<'static, ()> {
    SWAP.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The interrupt message for a run in `state`.
pub fn message(state: &RunState) -> String {
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

/// Install the handler of Ctrl-C and SIGTERM (once; a failure to install is not fatal).
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        let _swap = hold_off();
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
    }
}
