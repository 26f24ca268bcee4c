//! The sandboxed rhai engine every script model runs in, and the per-thread bytecode VM.
//!
//! One engine, built once, serves all scripts: rhai's standard packages (arithmetic, math,
//! strings, arrays, maps: no file, network or process access exist in rhai), `import` and
//! `eval` disabled with a module resolver that resolves nothing, `print`/`debug` discarded,
//! strict variables (an undefined name is a compile error), no sleeping or clock functions
//! (rhai's `sleep` and `timestamp` are replaced by errors, and a script that names them is
//! refused at load: [`NO_CLOCK`]), and limits on call depth,
//! expression depth, string, array and map sizes. Each call to a script function runs under a
//! [`CallBudget`]: a number of operations — the call's own budget, or what is left of its
//! script's budget for the run, whichever is smaller — that decides deterministically whether a
//! call may finish, and a wall-clock deadline (checked every [`DEADLINE_CHECK_EVERY`]
//! operations) as the last resort for a call whose single operations are slow (large strings
//! and arrays under the size limits). See [`crate::limits`].
//!
//! Calls run on rhai's `grain` bytecode VM. A VM is reused per thread (it keeps its function
//! resolution cache), so no lock is taken on the hot path and models stay `Send + Sync`.

use std::cell::{Cell, RefCell};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use rhai::grain::Vm;
use rhai::module_resolvers::DummyModuleResolver;
use rhai::{Dynamic, Engine, EvalAltResult};

/// Operations between two looks at the clock. One look (≈ 20 ns) costs about as much as a
/// simple operation, so this adds ≈ 1 % to a call; one operation on data at the size limits
/// (`contains` or `sort` on a 10 000-element array) takes up to a few milliseconds, so the
/// call stops well within a second past its deadline.
pub const DEADLINE_CHECK_EVERY: u64 = 16;
/// Deepest nesting of script function calls.
pub const MAX_CALL_LEVELS: usize = 32;
/// Deepest nesting of expressions at a script's top level and inside its functions.
pub const MAX_EXPR_DEPTHS: (usize, usize) = (64, 32);
/// Longest string a script may build, in bytes.
pub const MAX_STRING_SIZE: usize = 10_000;
/// Largest array a script may build.
pub const MAX_ARRAY_SIZE: usize = 10_000;
/// Largest object map a script may build.
pub const MAX_MAP_SIZE: usize = 1_000;

/// rhai's functions that sleep or read the clock: a model's force depends on its arguments
/// alone, and a script that sleeps hangs a run while using no operations. Calls to them fail,
/// and a script that names them is refused at load ([`clock_call`]).
pub const NO_CLOCK: [&str; 2] = ["sleep", "timestamp"];

/// The token of the error raised when a call exceeds its operation budget.
pub(crate) const BUDGET_TOKEN: &str = "operation budget exceeded";
/// The token of the error raised when a call exceeds what is left of its script's budget
/// for the run.
pub(crate) const RUN_BUDGET_TOKEN: &str = "run operation budget exceeded";
/// The token of the error raised when a call exceeds its wall-clock deadline.
pub(crate) const DEADLINE_TOKEN: &str = "call deadline exceeded";

thread_local! {
    /// Operation count of this thread's VM when the current call started.
    static OPS_BASE: Cell<u64> = const { Cell::new(0) };
    /// Last operation count this thread's VM reported.
    static OPS_LAST: Cell<u64> = const { Cell::new(0) };
    /// Operation count at which the current call looks at the clock next.
    static NEXT_CLOCK_CHECK: Cell<u64> = const { Cell::new(0) };
    /// Operations the current call may perform, and whether that is the run's remainder.
    static LIMIT: Cell<(u64, bool)> = const { Cell::new((u64::MAX, false)) };
    /// When the current call must be finished.
    static DEADLINE: Cell<Option<Instant>> = const { Cell::new(None) };
    /// This thread's VM, reused from call to call.
    static VM: RefCell<Option<Vm<'static>>> = const { RefCell::new(None) };
}

/// The shared sandboxed engine.
pub fn engine() -> &'static Engine {
    static ENGINE: OnceLock<Engine> = OnceLock::new();
    ENGINE.get_or_init(build_engine)
}

fn build_engine() -> Engine {
    let mut engine = Engine::new();
    engine
        .set_module_resolver(DummyModuleResolver::new())
        .disable_symbol("import")
        .disable_symbol("eval")
        .set_strict_variables(true)
        // `p.nn` for `p.n` is an error naming `nn`, not `()` failing later in `**`.
        .set_fail_on_invalid_map_property(true)
        .set_max_call_levels(MAX_CALL_LEVELS)
        .set_max_expr_depths(MAX_EXPR_DEPTHS.0, MAX_EXPR_DEPTHS.1)
        .set_max_string_size(MAX_STRING_SIZE)
        .set_max_array_size(MAX_ARRAY_SIZE)
        .set_max_map_size(MAX_MAP_SIZE)
        .set_max_modules(0)
        // The VM is reused, so rhai's own counter never resets; the budget is per call here.
        .set_max_operations(0)
        .on_progress(|count| {
            OPS_LAST.with(|last| last.set(count));
            let used = count.saturating_sub(OPS_BASE.with(Cell::get));
            let (limit, from_run) = LIMIT.with(Cell::get);
            if used > limit {
                let token = if from_run {
                    RUN_BUDGET_TOKEN
                } else {
                    BUDGET_TOKEN
                };
                return Some(Dynamic::from(token));
            }
            past_deadline(count).then(|| Dynamic::from(DEADLINE_TOKEN))
        })
        .on_print(|_| {})
        .on_debug(|_, _, _| {});
    // Registered in the engine's own namespace, these are found before rhai's packages.
    engine
        .register_fn("sleep", |_: rhai::INT| -> Result<(), Box<EvalAltResult>> {
            Err(no_clock("sleep"))
        })
        .register_fn(
            "sleep",
            |_: rhai::FLOAT| -> Result<(), Box<EvalAltResult>> { Err(no_clock("sleep")) },
        )
        .register_fn("timestamp", || -> Result<(), Box<EvalAltResult>> {
            Err(no_clock("timestamp"))
        });
    engine
}

/// Why a script may not call `name`.
pub(crate) fn no_clock_message(name: &str) -> String {
    format!(
        "`{name}` is not available to scripts: a model has no sleeping or clock functions \
         (its force depends on its arguments alone)"
    )
}

fn no_clock(name: &str) -> Box<EvalAltResult> {
    no_clock_message(name).into()
}

/// The first call in `ast` of a function of [`NO_CLOCK`] that the script does not define
/// itself, with its line.
pub(crate) fn clock_call(ast: &rhai::AST) -> Option<(&'static str, Option<usize>)> {
    let own = |name: &str| ast.iter_functions().any(|f| f.name == name);
    let mut found = None;
    ast.walk(&mut |path: &[rhai::ASTNode]| {
        // A call is an expression, or a statement of its own (`sleep(12);`).
        if let Some(
            rhai::ASTNode::Expr(rhai::Expr::FnCall(call, pos) | rhai::Expr::MethodCall(call, pos))
            | rhai::ASTNode::Stmt(rhai::Stmt::FnCall(call, pos)),
        ) = path.last()
        {
            if let Some(name) = NO_CLOCK.iter().find(|n| call.name.as_str() == **n) {
                if !own(name) {
                    found = Some((*name, pos.line()));
                }
            }
        }
        found.is_none()
    });
    found
}

/// Whether the current call is past its deadline; looks at the clock only once every
/// [`DEADLINE_CHECK_EVERY`] operations (`count` is the VM's operation counter).
fn past_deadline(count: u64) -> bool {
    if count < NEXT_CLOCK_CHECK.with(Cell::get) {
        return false;
    }
    NEXT_CLOCK_CHECK.with(|next| next.set(count.saturating_add(DEADLINE_CHECK_EVERY)));
    DEADLINE
        .with(Cell::get)
        .is_some_and(|deadline| Instant::now() > deadline)
}

/// What one call may use.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CallBudget {
    /// Operations.
    pub operations: u64,
    /// Whether `operations` is what is left of the script's run budget (else the call's own).
    pub from_run: bool,
    /// Wall-clock seconds, the last resort.
    pub seconds: f64,
}

/// Run `f` with this thread's VM under `budget`; returns its result and the operations the
/// call used.
///
/// Returns `None` if the VM is already in use on this thread (a script model called from
/// inside a script call, which the host never does).
pub(crate) fn with_vm<R>(
    budget: CallBudget,
    f: impl FnOnce(&mut Vm<'static>) -> R,
) -> Option<(R, u64)> {
    VM.with(|cell| {
        let mut slot = cell.try_borrow_mut().ok()?;
        let vm = slot.get_or_insert_with(|| {
            OPS_LAST.with(|last| last.set(0));
            Vm::new(engine())
        });
        let base = OPS_LAST.with(Cell::get);
        OPS_BASE.with(|b| b.set(base));
        LIMIT.with(|l| l.set((budget.operations, budget.from_run)));
        NEXT_CLOCK_CHECK.with(|next| next.set(base.saturating_add(DEADLINE_CHECK_EVERY)));
        let deadline = Duration::try_from_secs_f64(budget.seconds)
            .ok()
            .and_then(|d| Instant::now().checked_add(d));
        DEADLINE.with(|d| d.set(deadline));
        let result = f(vm);
        let used = OPS_LAST.with(Cell::get).saturating_sub(base);
        Some((result, used))
    })
}
