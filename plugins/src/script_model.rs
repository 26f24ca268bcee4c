//! A force model written as a rhai script.
//!
//! The script contract (see `models/scripts/` for documented examples):
//!
//! ```rhai
//! //! Power-law thickening with a structure variable λ that builds up with speed.
//! /// name => [default, min, max, unit]
//! fn params() { #{ K: [5.0, 0.0, 1e3, "N (s/m)^n"], n: [1.6, 1.0, 4.0, ""], tau: [0.05, 1e-4, 10.0, "s"] } }
//! fn n_internal() { 1 }
//! /// Force of the fluid on the blade, N.
//! fn force(p, t, x, v, z) { p.K * (1.0 + z[0]) * v.abs() ** p.n * v.sign() }
//! /// dλ/dt
//! fn rates(p, t, x, v, z) { [(v.abs() - z[0]) / p.tau] }
//! ```
//!
//! - required: `params()` returning `#{ name: [default, min, max, unit(, doc)] }` and
//!   `force(p, t, x, v, z)` returning the force in N;
//! - optional: `n_internal()` (number of internal states, default 0), `rates(p, t, x, v, z)`
//!   returning an array of `n_internal` rates (required when `n_internal() > 0`),
//!   `added_mass(p, t, x, v, z)` in kg, `initial(p)` returning the initial internal state;
//! - `p` is an object map of the parameter values (`p.K`), `z` an array of the internal state;
//! - parameter order is the map's key order, which rhai sorts by key (`K`, `n`, `tau`);
//! - the first `//!` line is the model's summary; top-level statements are never run.
//!
//! The script is compiled once, checked at load (functions and arities, the params map, one
//! call of each function at the defaults) and then runs on one of two paths:
//!
//! - **compiled** ([`ScriptModel::is_compiled`]): when `force`, `rates` and `added_mass` stay
//!   inside the loop-free subset of [`crate::script_compiled`] (arithmetic, comparisons,
//!   `if`/`else`, `let`, `return`, rhai's math functions, `p.NAME`, `z[i]`), they are
//!   translated from rhai's AST into Rust closures that reproduce rhai's results bit for bit.
//!   A call that rhai would fail (integer division by zero, overflow, a type rhai rejects) is
//!   re-run on the VM, so errors and their messages are rhai's own. A power-law force call
//!   costs tens of ns instead of ≈ 2 µs on the VM;
//! - **VM**: anything else (loops, strings, maps, helper functions, …) runs on rhai's bytecode
//!   VM in the sandbox of [`crate::sandbox`], with its operation budgets ([`crate::limits`]).
//!
//! A script larger than its [`ScriptLimits`] (bytes, functions, AST nodes, constants) is
//! refused before rhai's bytecode compiler sees it, with the limit named.
//!
//! Why a translation of our own: rhai has no JIT, and its fastest engine (the `grain` bytecode
//! VM) still pays ≈ 0.5 µs per call plus dynamic dispatch per operator, so a paper sweep with a
//! script model took ≈ 25× the native time; no crate compiles rhai's AST to native code.
//! Errors name the script's path and line.
//!
//! ```
//! use stf_plugins::ScriptModel;
//! use stf_core::physics::force_model::{ForceModel, ModelState};
//! let m = ScriptModel::from_source("lin", "fn params() { #{ c: [2.0, 0.0, 10.0, \"N s/m\"] } }\n\
//!                                          fn force(p, t, x, v, z) { p.c * v }").unwrap();
//! let s = ModelState { t: 0.0, x: 0.0, v: 0.5, z: &[] };
//! assert_eq!(m.force(&[2.0], &s, &mut []).unwrap(), 1.0);
//! ```

use std::cell::RefCell;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

use rhai::grain::{Compiler, SharedProgram};
use rhai::{CallFnOptions, Dynamic, EvalAltResult, Scope};
use stf_core::data::bounded::{read_file_to_string, BoundedError};
use stf_core::physics::force_model::{ForceModel, ModelError, ModelState};
use stf_core::physics::param_spec::{defaults, ParamSpec};

use crate::error::{ScriptError, ScriptLocation};
use crate::limits::{duration_text, ScriptLimits, ScriptRun, Usage};
use crate::sandbox::{
    self, CallBudget, BUDGET_TOKEN, DEADLINE_TOKEN, MAX_CALL_LEVELS, RUN_BUDGET_TOKEN,
};
use crate::script_compiled::{self, CompiledFn};
use crate::script_params::{param_docs, parse_params, to_f64};
use crate::script_size;

/// Most evaluations timed at load to measure a script's cost of a call.
const TIMING_CALLS: u32 = 1000;
/// Seconds after which no more evaluations are timed at load.
const TIMING_SECONDS: f64 = 0.02;

/// Most internal states a script may declare.
pub const MAX_INTERNAL: usize = 64;

/// Functions a script may define: name, arity, required.
const CONTRACT: &[(&str, usize, &str, bool)] = &[
    ("params", 0, "params()", true),
    ("force", 5, "force(p, t, x, v, z)", true),
    ("n_internal", 0, "n_internal()", false),
    ("rates", 5, "rates(p, t, x, v, z)", false),
    ("added_mass", 5, "added_mass(p, t, x, v, z)", false),
    ("initial", 1, "initial(p)", false),
];

/// Parameter maps built for recent parameter vectors, per thread: `(model id, values, map)`.
/// In a simulation the values never change, so the map is built once and shared.
const PARAM_CACHE_SIZE: usize = 8;
thread_local! {
    static PARAM_MAPS: RefCell<Vec<(u64, Vec<f64>, Dynamic)>> = const { RefCell::new(Vec::new()) };
}

/// A force model defined by a rhai script.
pub struct ScriptModel {
    id: u64,
    name: String,
    path: String,
    summary: String,
    specs: Vec<ParamSpec>,
    n_internal: usize,
    has_added_mass: bool,
    has_initial: bool,
    program: SharedProgram,
    /// Line of each contract function the script defines: where an error is reported when
    /// rhai's bytecode VM gives no position (stopped calls, data too large, deep recursion).
    fn_lines: Vec<(&'static str, usize)>,
    /// The compiled fast path, when the script is inside its subset.
    compiled: Option<Compiled>,
    /// The limits its calls run under.
    limits: ScriptLimits,
    /// Operations and time its calls have used in this run (shared by every load of the
    /// script).
    run_used: Arc<Usage>,
    /// Operations of one `force` call at the defaults, from rest, on the VM.
    force_operations: u64,
}

/// The hot functions translated to closures ([`crate::script_compiled`]).
struct Compiled {
    force: CompiledFn,
    rates: Option<CompiledFn>,
    added_mass: Option<CompiledFn>,
}

/// A failure of a script call: line (if rhai knows it) and message.
struct CallError {
    line: Option<usize>,
    message: String,
}

impl std::fmt::Debug for ScriptModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ScriptModel")
            .field("path", &self.path)
            .field("params", &self.specs)
            .field("n_internal", &self.n_internal)
            .field("compiled", &self.is_compiled())
            .finish()
    }
}

impl ScriptModel {
    /// Load, compile and check the script at `path`, in a run of its own with the default
    /// limits; the model's name is the file stem.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, ScriptError> {
        Self::load_in(path, &ScriptRun::default())
    }

    /// [`ScriptModel::load`] in `run`: its limits, and its operation budget shared with every
    /// other load of the same path in it.
    pub fn load_in(path: impl AsRef<Path>, run: &ScriptRun) -> Result<Self, ScriptError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        // Read no more than the size limit (a wrong path such as `/dev/zero` is refused, not
        // read into memory).
        let limit = run.limits().max_bytes as u64;
        let source = read_file_to_string(path, limit).map_err(|e| match e {
            BoundedError::Io(error) => ScriptError::Read {
                path: shown.clone(),
                did_you_mean: if error.kind() == std::io::ErrorKind::NotFound {
                    stf_core::names::nearby_file(path)
                } else {
                    String::new()
                },
                error,
            },
            too_large => ScriptError::TooLarge {
                path: shown.clone(),
                message: format!("it {too_large} (`[scripts] max_bytes`)"),
            },
        })?;
        let name = path
            .file_stem()
            .map_or_else(|| shown.clone(), |s| s.to_string_lossy().into_owned());
        Self::compile(name, shown, &source, run)
    }

    /// Compile and check a script given as text; `name` is used as its name and path.
    pub fn from_source(name: &str, source: &str) -> Result<Self, ScriptError> {
        Self::from_source_in(name, source, &ScriptRun::default())
    }

    /// [`ScriptModel::from_source`] in `run`.
    pub fn from_source_in(name: &str, source: &str, run: &ScriptRun) -> Result<Self, ScriptError> {
        Self::compile(name.to_string(), name.to_string(), source, run)
    }

    /// The limits its calls run under.
    pub fn limits(&self) -> &ScriptLimits {
        &self.limits
    }

    /// Operations of one `force` call at the defaults, from rest, on rhai's VM (what the
    /// load-time check measured; deterministic).
    pub fn force_operations(&self) -> u64 {
        self.force_operations
    }

    /// Seconds one evaluation of the force (with the rates) took at the defaults when the
    /// script was loaded, on the path its calls take (compiled or VM): what a run's plan
    /// multiplies ([`ScriptRun::plan`]).
    pub fn call_seconds(&self) -> f64 {
        self.run_used.call_nanos.load(Ordering::Relaxed) as f64 * 1e-9
    }

    /// The script's path (or the name given to [`ScriptModel::from_source`]).
    pub fn path(&self) -> &str {
        &self.path
    }

    /// Whether calls take the compiled fast path (`false`: every call runs on rhai's VM).
    pub fn is_compiled(&self) -> bool {
        self.compiled.is_some()
    }

    /// The same model with the compiled fast path dropped, so every call runs on rhai's VM
    /// (for comparisons and benchmarks).
    pub fn vm_only(mut self) -> Self {
        self.compiled = None;
        self
    }

    /// Compile `source` (shown as `path`) in `run` and check it: its size, its syntax, the
    /// contract functions, its parameters and internal states, and one call of each
    /// function at the defaults.
    fn compile(
        name: String,
        path: String,
        source: &str,
        run: &ScriptRun,
    ) -> Result<Self, ScriptError> {
        let at = |line: Option<usize>| ScriptLocation::new(&path, line);
        let limits = run.limits();
        let ast = parse(source, &path, limits)?;
        let defined: Vec<(String, usize)> = ast
            .iter_functions()
            .map(|f| (f.name.to_string(), f.params.len()))
            .collect();
        check_contract(&defined, source, at)?;
        let has =
            |fname: &str, arity: usize| defined.iter().any(|(n, a)| n == fname && *a == arity);

        let mut model = ScriptModel {
            id: next_id(),
            name,
            summary: summary_of(source),
            specs: Vec::new(),
            n_internal: 0,
            has_added_mass: has("added_mass", 5),
            has_initial: has("initial", 1),
            program: Compiler::new().compile(&ast).into_shared(),
            path: path.clone(),
            fn_lines: CONTRACT
                .iter()
                .filter_map(|(fname, ..)| Some((*fname, fn_line(source, fname)?)))
                .collect(),
            compiled: None,
            limits: limits.clone(),
            run_used: run.counter(&path),
            force_operations: 0,
        };
        let params_line = model.line_of("params");
        let value = model.call("params", ()).map_err(|e| model.load_error(e))?;
        model.specs = parse_params(value, &param_docs(source, params_line)).map_err(|message| {
            ScriptError::Params {
                at: at(params_line),
                message,
            }
        })?;
        if has("n_internal", 0) {
            model.n_internal = model.read_n_internal()?;
        }
        if model.n_internal > 0 && !has("rates", 5) {
            return Err(ScriptError::Contract {
                at: at(model.line_of("n_internal")),
                message: format!(
                    "n_internal() is {}, so the script must define fn rates(p, t, x, v, z)",
                    model.n_internal
                ),
            });
        }
        model.compiled = model.translate(&ast);
        model.force_operations = model.check_at_defaults().map_err(|e| model.load_error(e))?;
        Ok(model)
    }

    /// The line where the script defines contract function `fname`.
    fn line_of(&self, fname: &str) -> Option<usize> {
        self.fn_lines
            .iter()
            .find_map(|(name, line)| (*name == fname).then_some(*line))
    }

    /// A call that failed while the script was loaded, placed in the script.
    fn load_error(&self, e: CallError) -> ScriptError {
        ScriptError::Runtime {
            at: ScriptLocation::new(&self.path, e.line),
            message: e.message,
        }
    }

    /// What `n_internal()` returns: an integer from 0 to [`MAX_INTERNAL`].
    fn read_n_internal(&self) -> Result<usize, ScriptError> {
        let value = self
            .call("n_internal", ())
            .map_err(|e| self.load_error(e))?;
        value
            .as_int()
            .ok()
            .and_then(|n| usize::try_from(n).ok())
            .filter(|&n| n <= MAX_INTERNAL)
            .ok_or_else(|| ScriptError::Contract {
                at: ScriptLocation::new(&self.path, self.line_of("n_internal")),
                message: format!(
                    "n_internal() must return an integer from 0 to {MAX_INTERNAL}, not {value}"
                ),
            })
    }

    /// Translate the hot functions to closures; `None` if any is outside the subset.
    fn translate(&self, ast: &rhai::AST) -> Option<Compiled> {
        let names: Vec<String> = self.specs.iter().map(|s| s.name.clone()).collect();
        // `Some(None)`: a function the model does not use; `None`: outside the subset.
        let optional = |used: bool, fname: &str, arrays: bool| {
            used.then(|| script_compiled::translate(ast, fname, &names, arrays))
                .map_or(Some(None), |compiled| compiled.map(Some))
        };
        Some(Compiled {
            force: script_compiled::translate(ast, "force", &names, false)?,
            rates: optional(self.n_internal > 0, "rates", true)?,
            added_mass: optional(self.has_added_mass, "added_mass", false)?,
        })
    }

    /// Call every function once at the defaults, from rest, so errors show at load time;
    /// returns the operations of one `force` call on the VM.
    fn check_at_defaults(&self) -> Result<u64, CallError> {
        let p = defaults(&self.specs);
        let mut z = vec![0.0; self.n_internal];
        if self.has_initial {
            self.initial_state(&p, &mut z)?;
        }
        let s = ModelState {
            t: 0.0,
            x: 0.0,
            v: 0.0,
            z: &z,
        };
        let mut dz = vec![0.0; self.n_internal];
        let ops = &self.run_used.operations;
        let before = ops.load(Ordering::Relaxed);
        let _ = self.call("force", self.args(&p, &s))?;
        let force_operations = ops.load(Ordering::Relaxed).saturating_sub(before);
        self.time_force(&p, &s, &mut dz)?;
        if self.has_added_mass {
            self.eval_number("added_mass", &p, &s)?;
        }
        Ok(force_operations)
    }

    /// Time evaluations of the force (with the rates) at `p`, `s` on the path calls take:
    /// one, or for a fast one as many as fit in [`TIMING_SECONDS`] (at most
    /// [`TIMING_CALLS`]), the median of their times kept as the script's cost of a call. The
    /// median, not the mean: on a busy machine one call pre-empted for a time slice (a few
    /// ms) made the mean of a 20 ms window 1.3 ms a call for a script of microseconds, and
    /// the run was refused as over its time limit. Only the first call counts against the
    /// run's operations, so what a load uses stays the same every time.
    fn time_force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<(), CallError> {
        let ops = &self.run_used.operations;
        let clock = Instant::now();
        let mut times = Vec::new();
        let mut last = 0.0;
        let mut after_first = None;
        while times.len() < TIMING_CALLS as usize && (times.is_empty() || last < TIMING_SECONDS) {
            self.eval_force(p, s, dz)?;
            after_first.get_or_insert_with(|| ops.load(Ordering::Relaxed));
            let now = clock.elapsed().as_secs_f64();
            times.push(now - last);
            last = now;
        }
        let after_first = after_first.unwrap_or_else(|| ops.load(Ordering::Relaxed));
        let _ = ops.fetch_sub(
            ops.load(Ordering::Relaxed).saturating_sub(after_first),
            Ordering::Relaxed,
        );
        times.sort_by(f64::total_cmp);
        let median = times.get(times.len() / 2).copied().unwrap_or(last);
        self.run_used
            .call_nanos
            .store((median * 1e9).round() as u64, Ordering::Relaxed);
        Ok(())
    }

    /// What the next call may use: its own budget, or what is left of the run's.
    fn budget(&self) -> CallBudget {
        let left = self
            .limits
            .run_operations
            .saturating_sub(self.run_used.operations.load(Ordering::Relaxed));
        CallBudget {
            operations: left.min(self.limits.call_operations),
            from_run: left < self.limits.call_operations,
            seconds: self.limits.call_seconds,
        }
    }

    /// Call script function `fname` on this thread's VM, under [`ScriptModel::budget`].
    fn call(&self, fname: &str, args: impl rhai::FuncArgs) -> Result<Dynamic, CallError> {
        let options = CallFnOptions::new().eval_ast(false).rewind_scope(true);
        let budget = self.budget();
        let clock = Instant::now();
        let (result, used) = sandbox::with_vm(budget, |vm| {
            vm.call_fn_with_options::<Dynamic>(
                options,
                &mut Scope::new(),
                &self.program,
                fname,
                args,
            )
        })
        .ok_or_else(|| CallError {
            line: None,
            message: format!("fn {fname} called re-entrantly on one thread"),
        })?;
        let nanos = u64::try_from(clock.elapsed().as_nanos()).unwrap_or(u64::MAX);
        let total_nanos = self
            .run_used
            .nanos
            .fetch_add(nanos, Ordering::Relaxed)
            .saturating_add(nanos);
        let total = self
            .run_used
            .operations
            .fetch_add(used, Ordering::Relaxed)
            .saturating_add(used);
        let value = result
            .map_err(|e| describe(*e, fname, &self.limits, used, &self.specs))
            .map_err(|e| CallError {
                line: e.line.or_else(|| self.line_of(fname)),
                message: e.message,
            })?;
        // Calls running in parallel each stay within what was left when they started; the
        // one that carries the total past the budget fails too, so a run fails exactly when
        // its calls need more than the budget.
        if total > self.limits.run_operations {
            return Err(CallError {
                line: self.line_of(fname),
                message: format!("{} (in fn {fname})", run_budget_message(&self.limits)),
            });
        }
        if total_nanos as f64 * 1e-9 > self.limits.run_seconds {
            return Err(CallError {
                line: self.line_of(fname),
                message: format!(
                    "stopped by its run time budget: this script's calls in this run took \
                     more than {} (`[scripts] run_seconds`); it is too slow for this run \
                     (in fn {fname})",
                    duration_text(self.limits.run_seconds)
                ),
            });
        }
        Ok(value)
    }

    /// The parameter map for `p`, cached per thread.
    fn param_map(&self, p: &[f64]) -> Dynamic {
        PARAM_MAPS.with(|cell| {
            let mut cache = cell.borrow_mut();
            if let Some((_, _, map)) = cache
                .iter()
                .find(|(id, values, _)| *id == self.id && same_bits(values, p))
            {
                return map.clone();
            }
            let map: rhai::Map = self
                .specs
                .iter()
                .zip(p)
                .map(|(spec, &v)| (spec.name.as_str().into(), Dynamic::from_float(v)))
                .collect();
            let map = Dynamic::from_map(map).into_shared();
            if cache.len() >= PARAM_CACHE_SIZE {
                let _ = cache.remove(0);
            }
            cache.push((self.id, p.to_vec(), map.clone()));
            map
        })
    }

    fn args(&self, p: &[f64], s: &ModelState) -> (Dynamic, f64, f64, f64, rhai::Array) {
        let z: rhai::Array = s.z.iter().map(|&v| Dynamic::from_float(v)).collect();
        (self.param_map(p), s.t, s.x, s.v, z)
    }

    fn eval_number(&self, fname: &str, p: &[f64], s: &ModelState) -> Result<f64, CallError> {
        let compiled = match (&self.compiled, fname) {
            (Some(c), "force") => Some(&c.force),
            (Some(c), "added_mass") => c.added_mass.as_ref(),
            _ => None,
        };
        if let Some(f) = compiled.and_then(|c| c.number(p, s)) {
            return Ok(f);
        }
        let value = self.call(fname, self.args(p, s))?;
        to_f64(&value).ok_or_else(|| CallError {
            line: None,
            message: format!(
                "fn {fname} returned {} ({value}), not a number",
                value.type_name()
            ),
        })
    }

    /// `f`, the value `fname` returned at `p`, `s`, if it is finite; else an error naming the
    /// script, the function's line and the arguments (a NaN force would only show later as
    /// a residual or a state that is not finite, far from its cause).
    fn finite(&self, fname: &str, f: f64, p: &[f64], s: &ModelState) -> Result<f64, ModelError> {
        if f.is_finite() {
            Ok(f)
        } else {
            Err(self.model_error(self.not_finite(fname, f, p, s)))
        }
    }

    /// `fname` returned `f`, not a finite number, at `p`, `s`: said with the arguments.
    fn not_finite(&self, fname: &str, f: f64, p: &[f64], s: &ModelState) -> CallError {
        let params: Vec<String> = self
            .specs
            .iter()
            .zip(p)
            .map(|(spec, v)| format!("{} = {v}", spec.name))
            .collect();
        CallError {
            line: self.line_of(fname),
            message: format!(
                "fn {fname} returned {f}, not a finite number, at t = {}, x = {}, v = {} with \
                 {}",
                s.t,
                s.x,
                s.v,
                if params.is_empty() {
                    "no parameters".to_string()
                } else {
                    params.join(", ")
                }
            ),
        }
    }

    fn eval_force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, CallError> {
        let f = self.eval_number("force", p, s)?;
        if self.n_internal > 0 {
            let rates = self.compiled.as_ref().and_then(|c| c.rates.as_ref());
            if rates.is_some_and(|r| r.array(p, s, dz).is_some()) {
                return Ok(f);
            }
            let value = self.call("rates", self.args(p, s))?;
            self.write_array("rates", value, dz)?;
        }
        Ok(f)
    }

    fn initial_state(&self, p: &[f64], z0: &mut [f64]) -> Result<(), CallError> {
        let value = self.call("initial", (self.param_map(p),))?;
        self.write_array("initial", value, z0)
    }

    /// Write an array of numbers returned by `fname` into `out` (lengths must match).
    fn write_array(&self, fname: &str, value: Dynamic, out: &mut [f64]) -> Result<(), CallError> {
        let n = out.len();
        let bad = |what: String| CallError {
            line: None,
            message: format!("fn {fname} must return an array of {n} numbers; {what}"),
        };
        let type_name = value.type_name();
        let Some(items) = value.try_cast::<rhai::Array>() else {
            return Err(bad(format!("it returned {type_name}")));
        };
        if items.len() != out.len() {
            return Err(bad(format!("it returned {} elements", items.len())));
        }
        for (i, (slot, item)) in out.iter_mut().zip(&items).enumerate() {
            *slot =
                to_f64(item).ok_or_else(|| bad(format!("element {i} is {}", item.type_name())))?;
        }
        Ok(())
    }

    fn model_error(&self, e: CallError) -> ModelError {
        let message = match e.line {
            Some(line) => format!("line {line}: {}", e.message),
            None => e.message,
        };
        ModelError::new(self.path.clone(), message)
    }
}

impl ForceModel for ScriptModel {
    fn name(&self) -> &str {
        &self.name
    }
    fn summary(&self) -> &str {
        &self.summary
    }
    fn params(&self) -> &[ParamSpec] {
        &self.specs
    }
    fn n_internal(&self) -> usize {
        self.n_internal
    }
    /// The script's `initial(p)`, or zeros. The trait gives no way to fail here, so an error
    /// (already ruled out at the defaults when the script was loaded) yields NaN, which the
    /// simulation reports as a non-finite state.
    fn initial_internal(&self, p: &[f64], z0: &mut [f64]) {
        if !self.has_initial {
            z0.fill(0.0);
        } else if self.initial_state(p, z0).is_err() {
            z0.fill(f64::NAN);
        }
    }
    fn added_mass(&self, p: &[f64], s: &ModelState) -> Result<f64, ModelError> {
        if !self.has_added_mass {
            return Ok(0.0);
        }
        let m = self
            .eval_number("added_mass", p, s)
            .map_err(|e| self.model_error(e))?;
        self.finite("added_mass", m, p, s)
    }
    fn force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, ModelError> {
        let f = self.eval_force(p, s, dz).map_err(|e| self.model_error(e))?;
        self.finite("force", f, p, s)
    }
}

/// The syntax tree of `source`, shown as `path`, within the size `limits`.
fn parse(source: &str, path: &str, limits: &ScriptLimits) -> Result<rhai::AST, ScriptError> {
    let too_large = |message: String| ScriptError::TooLarge {
        path: path.to_string(),
        message,
    };
    script_size::check_bytes(source, limits).map_err(too_large)?;
    let mut ast = sandbox::engine()
        .compile(source)
        .map_err(|e| ScriptError::Syntax {
            at: ScriptLocation::new(path, e.1.line()),
            message: e.0.to_string(),
        })?;
    script_size::check_ast(&ast, limits).map_err(too_large)?;
    if let Some((name, line)) = sandbox::clock_call(&ast) {
        return Err(ScriptError::Contract {
            at: ScriptLocation::new(path, line),
            message: sandbox::no_clock_message(name),
        });
    }
    ast.set_source(path);
    Ok(ast)
}

/// Every contract function `defined` (name, arity) takes its arguments, and the required
/// ones are there; `at` places an error.
fn check_contract(
    defined: &[(String, usize)],
    source: &str,
    at: impl Fn(Option<usize>) -> ScriptLocation,
) -> Result<(), ScriptError> {
    for &(fname, arity, signature, required) in CONTRACT {
        let mut arities = defined.iter().filter(|(n, _)| n == fname).map(|(_, a)| *a);
        if arities.clone().any(|a| a == arity) {
            continue;
        }
        if let Some(wrong) = arities.next() {
            return Err(ScriptError::Contract {
                at: at(fn_line(source, fname)),
                message: format!("fn {fname} takes {wrong} argument(s); it must be fn {signature}"),
            });
        }
        if required {
            return Err(ScriptError::Contract {
                at: at(None),
                message: format!("the script must define fn {signature}"),
            });
        }
    }
    Ok(())
}

/// Equal bit for bit (so -0.0 and 0.0 get separate parameter maps).
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

fn next_id() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(0);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// The first `//!` line of a script.
fn summary_of(source: &str) -> String {
    source
        .lines()
        .find_map(|l| l.trim().strip_prefix("//!"))
        .map(|s| s.trim().to_string())
        .unwrap_or_default()
}

/// The line (1-based) where `fn name(` is defined.
fn fn_line(source: &str, name: &str) -> Option<usize> {
    source
        .lines()
        .position(|l| {
            l.trim_start()
                .strip_prefix("fn ")
                .and_then(|rest| rest.trim_start().strip_prefix(name))
                .is_some_and(|rest| rest.trim_start().starts_with('('))
        })
        .map(|i| i + 1)
}

/// Why a script was stopped by its run budget.
fn run_budget_message(limits: &ScriptLimits) -> String {
    format!(
        "stopped by its run budget: this script's calls in this run used more than {} \
         operations (`[scripts] run_operations`); it is too slow for this run",
        limits.run_operations
    )
}

/// A runtime error as line + message, from the innermost function call that failed; `used`
/// is the operations the call performed.
fn describe(
    mut err: EvalAltResult,
    fname: &str,
    limits: &ScriptLimits,
    used: u64,
    params: &[ParamSpec],
) -> CallError {
    let mut line = err.position().line();
    let mut callee = fname.to_string();
    while let EvalAltResult::ErrorInFunctionCall(name, _, inner, pos) = err {
        line = pos.line().or(line);
        callee = name;
        err = *inner;
    }
    line = err.position().line().or(line);
    let message = match &err {
        EvalAltResult::ErrorTerminated(token, _) if is_token(token, BUDGET_TOKEN) => format!(
            "stopped by its operation budget: more than {} operations in one call (an endless \
             loop?; `[scripts] call_operations`)",
            limits.call_operations
        ),
        EvalAltResult::ErrorTerminated(token, _) if is_token(token, RUN_BUDGET_TOKEN) => {
            run_budget_message(limits)
        }
        EvalAltResult::ErrorTerminated(token, _) if is_token(token, DEADLINE_TOKEN) => format!(
            "stopped by the wall-clock safety limit of {} s in one call, after {used} \
             operations, within its operation budget of {}: its single operations are slow \
             (work on large arrays or strings?); unlike the operation budget, this limit \
             depends on the machine's speed and load (`[scripts] call_seconds`)",
            limits.call_seconds, limits.call_operations
        ),
        EvalAltResult::Exit(value, _) => format!(
            "the script called exit({value}); a script cannot end the run: return a number \
             from the function instead"
        ),
        EvalAltResult::ErrorStackOverflow(_) => {
            format!("stopped: more than {MAX_CALL_LEVELS} nested calls (endless recursion?)")
        }
        EvalAltResult::ErrorPropertyNotFound(name, _) => unknown_property(name, params),
        EvalAltResult::ErrorFunctionNotFound(signature, _) => {
            format!(
                "Function not found: {signature}{}",
                function_hint(signature)
            )
        }
        _ => {
            let _ = err.take_position();
            err.to_string()
        }
    };
    CallError {
        line,
        message: format!("{message} (in fn {callee})"),
    }
}

/// A map key the script reads that is not there: a parameter's name mistyped (`p.nn`).
fn unknown_property(name: &str, params: &[ParamSpec]) -> String {
    let names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
    format!(
        "`{name}` is not a parameter of this script{}: its parameters (from fn params) are {}",
        stf_core::names::did_you_mean(name, names.iter().copied()),
        if names.is_empty() {
            "none".to_string()
        } else {
            names.join(", ")
        }
    )
}

/// The fix for a function rhai does not have, where there is a usual one: `**` for powers;
/// an operand that is `()` (nothing) is named as such.
fn function_hint(signature: &str) -> String {
    let name = signature.split([' ', '(']).next().unwrap_or_default();
    if ["pow", "powf", "powi", "math::pow"].contains(&name) {
        format!(": rhai has no `{name}`; `**` is the power operator (`v.abs() ** p.n`)")
    } else if signature.contains("()") {
        ": one of its operands is () (nothing): a variable or a function without a value?".into()
    } else {
        String::new()
    }
}

/// Whether a termination token is `expected`.
fn is_token(token: &Dynamic, expected: &str) -> bool {
    token.clone().into_string().is_ok_and(|t| t == expected)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn fn_lines_and_summary_are_found() {
        let src = "//! A model.\n\nfn params() { #{} }\n  fn  force (p, t, x, v, z) { 0.0 }";
        assert_eq!(fn_line(src, "params"), Some(3));
        assert_eq!(fn_line(src, "force"), Some(4));
        assert_eq!(fn_line(src, "rates"), None);
        assert_eq!(summary_of(src), "A model.");
    }

    #[test]
    fn parameters_reach_the_script_by_name() {
        let m = ScriptModel::from_source(
            "m",
            "fn params() { #{ b: [1.0, 0.0, 9.0, \"\"], a: [2.0, 0.0, 9.0, \"\"] } }\n\
             fn force(p, t, x, v, z) { p.a * 10.0 + p.b }",
        )
        .unwrap();
        let s = ModelState {
            t: 0.0,
            x: 0.0,
            v: 0.0,
            z: &[],
        };
        assert_eq!(m.force(&[3.0, 4.0], &s, &mut []).unwrap(), 34.0);
        // A new parameter vector is seen (no stale cache).
        assert_eq!(m.force(&[5.0, 6.0], &s, &mut []).unwrap(), 56.0);
    }
}
