//! Ctrl-C during long work: the program says what it had finished and exits with 130. Results
//! are written atomically once the work is done, so an interrupted run leaves the previous
//! results intact and no half-written file under a final name.

use std::sync::{Mutex, OnceLock};

fn finished() -> &'static Mutex<Vec<String>> {
    static FINISHED: OnceLock<Mutex<Vec<String>>> = OnceLock::new();
    FINISHED.get_or_init(|| Mutex::new(Vec::new()))
}

/// Record that `what` (e.g. "fit of power_law") has finished.
pub fn finished_step(what: impl Into<String>) {
    if let Ok(mut list) = finished().lock() {
        list.push(what.into());
    }
}

/// Install the Ctrl-C handler (once; a failure to install is not fatal).
pub fn install() {
    let _ = ctrlc::set_handler(|| {
        let done = finished().lock().map(|l| l.clone()).unwrap_or_default();
        if done.is_empty() {
            eprintln!("interrupted: nothing had finished; no results were written");
        } else {
            eprintln!(
                "interrupted: finished {}; no results were written for this run (earlier results are intact)",
                done.join(", ")
            );
        }
        std::process::exit(130);
    });
}
