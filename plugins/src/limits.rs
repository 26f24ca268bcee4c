//! The limits a script runs under, and the run whose operation budget its calls share.
//!
//! Two kinds of limit, both deterministic: the size of a script (bytes, functions, AST nodes
//! and literal constants, checked before rhai's bytecode compiler runs, whose time grows with
//! the square of the number of constants and functions: 20 000 one-line helpers took over a
//! minute), and operations (one call of a script function; and every call of one script in
//! one run together, so that a slow script cannot keep a fit busy for hours). A wall-clock
//! limit per call stays as the last resort for scripts whose single operations are slow
//! (work on arrays or strings near their size limits), which the operation count cannot see;
//! a script stopped by it is told so, since that verdict depends on the machine.
//!
//! A third limit is time, per run: every call's wall-clock time is added up per script, and a
//! script whose calls in one run take more than [`ScriptLimits::run_seconds`] is stopped. A
//! program says before a run what it will cost ([`ScriptRun::plan`]: each script's cost of a
//! call, measured when it was loaded, times the calls the run needs) and refuses a run that
//! would take longer than that.
//!
//! A [`ScriptRun`] holds the limits and one usage counter per script path; every model
//! loaded through it (a program loads the same script for several fits) draws on that
//! script's counter. [`crate::ScriptModel::load`] gives each load a run of its own.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// The limits of a script's size and of its calls.
#[derive(Clone, Debug, PartialEq)]
pub struct ScriptLimits {
    /// Longest script, bytes.
    pub max_bytes: usize,
    /// Most functions a script may define.
    pub max_functions: usize,
    /// Most AST nodes (statements and expressions, function bodies included).
    pub max_nodes: usize,
    /// Most literal constants (numbers, strings, …) written in a script.
    pub max_constants: usize,
    /// Operations one call of a script function may perform.
    pub call_operations: u64,
    /// Operations all calls of one script in one run may perform together.
    pub run_operations: u64,
    /// Wall-clock seconds one call may take: the last resort, for slow single operations.
    pub call_seconds: f64,
    /// Wall-clock seconds all calls of one script in one run may take together (summed over
    /// threads); a run planned to take longer is refused before it starts.
    pub run_seconds: f64,
}

/// Default [`ScriptLimits::max_bytes`].
pub const MAX_BYTES: usize = 64 * 1024;
/// Default [`ScriptLimits::max_functions`].
pub const MAX_FUNCTIONS: usize = 256;
/// Default [`ScriptLimits::max_nodes`].
pub const MAX_NODES: usize = 10_000;
/// Default [`ScriptLimits::max_constants`].
pub const MAX_CONSTANTS: usize = 1_000;
/// Default [`ScriptLimits::call_operations`].
pub const CALL_OPERATIONS: u64 = 1_000_000;
/// Default [`ScriptLimits::run_operations`]: ten thousand million operations, about ten
/// minutes of simple operations on rhai's VM.
pub const RUN_OPERATIONS: u64 = 10_000_000_000;
/// Default [`ScriptLimits::call_seconds`].
pub const CALL_SECONDS: f64 = 10.0;
/// Default [`ScriptLimits::run_seconds`]: ten minutes.
pub const RUN_SECONDS: f64 = 600.0;

impl Default for ScriptLimits {
    fn default() -> Self {
        ScriptLimits {
            max_bytes: MAX_BYTES,
            max_functions: MAX_FUNCTIONS,
            max_nodes: MAX_NODES,
            max_constants: MAX_CONSTANTS,
            call_operations: CALL_OPERATIONS,
            run_operations: RUN_OPERATIONS,
            call_seconds: CALL_SECONDS,
            run_seconds: RUN_SECONDS,
        }
    }
}

/// What one script has used in a run, and what one of its calls costs.
#[derive(Debug, Default)]
pub(crate) struct Usage {
    /// Operations of all its calls.
    pub operations: AtomicU64,
    /// Wall-clock nanoseconds of all its calls on rhai's VM.
    pub nanos: AtomicU64,
    /// Nanoseconds one evaluation of its force (with its rates) took when it was loaded.
    pub call_nanos: AtomicU64,
}

/// One run's limits and what each script has used in it so far.
#[derive(Clone, Debug, Default)]
pub struct ScriptRun {
    limits: ScriptLimits,
    used: Arc<Mutex<BTreeMap<String, Arc<Usage>>>>,
}

impl ScriptRun {
    /// A run with these limits, nothing used yet.
    pub fn new(limits: ScriptLimits) -> Self {
        ScriptRun {
            limits,
            used: Arc::default(),
        }
    }

    /// The limits.
    pub fn limits(&self) -> &ScriptLimits {
        &self.limits
    }

    /// The usage counter of the script at `path` (shared by every load of it).
    pub(crate) fn counter(&self, path: &str) -> Arc<Usage> {
        let mut map = self
            .used
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        map.entry(path.to_string()).or_default().clone()
    }

    /// Operations the script at `path` has used in this run.
    pub fn operations_used(&self, path: &str) -> u64 {
        self.counter(path).operations.load(Ordering::Relaxed)
    }

    /// Each script loaded in this run, with the seconds one evaluation of its force took
    /// when it was loaded.
    pub fn call_costs(&self) -> Vec<(String, f64)> {
        let map = self
            .used
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        map.iter()
            .map(|(path, u)| {
                (
                    path.clone(),
                    u.call_nanos.load(Ordering::Relaxed) as f64 * 1e-9,
                )
            })
            .collect()
    }

    /// What a run of `calls` force evaluations of every script loaded in it will cost: one
    /// line a script (`what` names the run: "a fit") with its seconds; an error if a script
    /// would take longer than [`ScriptLimits::run_seconds`].
    pub fn plan(&self, calls: f64, what: &str) -> Result<Vec<(String, f64)>, crate::ScriptError> {
        let mut lines = Vec::new();
        for (path, seconds) in self.call_costs() {
            let total = seconds * calls;
            let line = format!(
                "{path}: this script costs ~{} a call: {what} needs ~{} calls, ~{}",
                duration_text(seconds),
                count_text(calls),
                duration_text(total)
            );
            if total > self.limits.run_seconds {
                return Err(crate::ScriptError::Budget {
                    path,
                    message: format!(
                        "{}; the limit is {} of script calls a run (`[scripts] run_seconds`: \
                         raise it to run anyway, or make the script faster)",
                        line.split_once(": ")
                            .map_or(line.as_str(), |(_, rest)| rest),
                        duration_text(self.limits.run_seconds)
                    ),
                });
            }
            lines.push((line, total));
        }
        Ok(lines)
    }
}

/// A count for messages: whole below a million, else in powers of ten (`4.0e6`).
pub fn count_text(n: f64) -> String {
    if n < 1e6 {
        format!("{n:.0}")
    } else {
        format!("{n:.1e}")
    }
}

/// A duration for messages, in the unit that reads best (`40 µs`, `1.2 s`, `3.5 h`, `46 days`).
pub fn duration_text(seconds: f64) -> String {
    let s = seconds;
    if !s.is_finite() {
        return format!("{s} s");
    }
    if s < 1e-3 {
        format!("{:.1} µs", s * 1e6)
    } else if s < 1.0 {
        format!("{:.1} ms", s * 1e3)
    } else if s < 120.0 {
        format!("{s:.1} s")
    } else if s < 7200.0 {
        format!("{:.1} min", s / 60.0)
    } else if s < 2.0 * 86400.0 {
        format!("{:.1} h", s / 3600.0)
    } else if s < 2.0 * 365.0 * 86400.0 {
        format!("{:.0} days", s / 86400.0)
    } else {
        format!("{:.0} years", s / (365.0 * 86400.0))
    }
}
