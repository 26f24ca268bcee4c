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
//! A [`ScriptRun`] holds the limits and one operation counter per script path; every model
//! loaded through it (a program loads the same script for several fits) draws on that
//! script's counter. [`crate::ScriptModel::load`] gives each load a run of its own.

use std::collections::BTreeMap;
use std::sync::atomic::AtomicU64;
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
        }
    }
}

/// One run's limits and the operations each script has used in it so far.
#[derive(Clone, Debug, Default)]
pub struct ScriptRun {
    limits: ScriptLimits,
    used: Arc<Mutex<BTreeMap<String, Arc<AtomicU64>>>>,
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

    /// The operation counter of the script at `path` (shared by every load of it).
    pub(crate) fn counter(&self, path: &str) -> Arc<AtomicU64> {
        let mut map = self
            .used
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        map.entry(path.to_string()).or_default().clone()
    }

    /// Operations the script at `path` has used in this run.
    pub fn operations_used(&self, path: &str) -> u64 {
        self.counter(path)
            .load(std::sync::atomic::Ordering::Relaxed)
    }
}
