//! The compiled fast path of a script model: `force`, `rates` and `added_mass` translated at
//! load from rhai's AST into a tree of Rust closures that runs without the rhai engine.
//!
//! The translation covers the loop-free subset force models are written in: number and bool
//! literals; the arguments (`t`, `x`, `v` as numbers, `p.NAME` resolved at load to a parameter
//! index, `z[i]` with a constant `i`); `let`/`const` bindings and plain assignments to them;
//! `+ - * / % **`, unary minus, comparisons, `&& || !`; `if`/`else` as expression or statement;
//! blocks; `return`; calls of rhai's float and integer math (`abs`, `sign`, `sqrt`, `exp`, `ln`,
//! `log`, trigonometric and hyperbolic functions, `floor`, `ceiling`, `round`, `int`,
//! `fraction`, `min`, `max`, `hypot`, `to_float`, `to_int`, `is_nan`, `PI()`, `E()`, …), as
//! functions or methods; and an array literal as the value of `rates`. Anything else (loops,
//! strings, maps, user functions, closures, `switch`, `throw`, op-assignments, …) makes the
//! translation decline, and the model keeps rhai's VM for every call.
//!
//! Each operation reproduces what rhai's built-in operators and packages compute (rhai 1.27,
//! checked arithmetic): integers stay integers and overflow-checked, integer/float mixing
//! promotes to float, float comparisons use rhai's relative-epsilon rule, `sign` returns an
//! integer. Whenever rhai would raise an error, or meets value types the translation does not
//! model (e.g. a bool in arithmetic), the compiled call *bails out* and the caller re-runs that
//! call on the VM: errors and messages are rhai's own, and a result the closures give is
//! always one rhai gives. Script functions are pure, so a re-run is safe.

use std::collections::HashSet;

use rhai::{ASTFlags, ASTNode, Expr, FnCallExpr, Position, Stmt, Token, AST};
use stf_core::physics::force_model::ModelState;

use crate::script_params::to_f64;

/// A value inside a compiled call: the rhai types the subset can produce.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Val {
    Unit,
    Bool(bool),
    Int(i64),
    Float(f64),
    /// An array literal has been written to the output slots (the value of `rates`).
    Written,
}

impl Val {
    /// A number as `f64` (an integer converted as the VM path does).
    fn number(self) -> Option<f64> {
        match self {
            Val::Float(x) => Some(x),
            Val::Int(i) => Some(i as f64),
            _ => None,
        }
    }
}

/// Why evaluation left the normal flow.
enum Flow {
    /// `return value`.
    Return(Val),
    /// The VM must run this call (an error, or types outside the subset).
    Bail,
}

/// State of one compiled call.
struct Frame<'a> {
    p: &'a [f64],
    z: &'a [f64],
    /// Local variables; slots 0, 1, 2 hold the arguments t, x, v.
    locals: &'a mut [Val],
    /// Where an array literal returned by `rates` is written.
    out: &'a mut [f64],
}

type Node = Box<dyn Fn(&mut Frame<'_>) -> Result<Val, Flow> + Send + Sync>;

/// One script function translated to closures.
pub(crate) struct CompiledFn {
    body: Node,
    n_locals: usize,
}

/// Most local variables kept on the stack in a call; more go to the heap.
const STACK_LOCALS: usize = 16;

impl CompiledFn {
    /// Run with the arguments; `None` means "run this call on the VM".
    fn run(&self, p: &[f64], s: &ModelState, out: &mut [f64]) -> Option<Val> {
        let mut stack = [Val::Unit; STACK_LOCALS];
        let mut heap = Vec::new();
        let locals: &mut [Val] = if self.n_locals <= STACK_LOCALS {
            &mut stack[..self.n_locals]
        } else {
            heap.resize(self.n_locals, Val::Unit);
            &mut heap
        };
        if let [lt, lx, lv, ..] = locals {
            (*lt, *lx, *lv) = (Val::Float(s.t), Val::Float(s.x), Val::Float(s.v));
        }
        let z = s.z;
        let mut frame = Frame { p, z, locals, out };
        match (self.body)(&mut frame) {
            Ok(v) | Err(Flow::Return(v)) => Some(v),
            Err(Flow::Bail) => None,
        }
    }

    /// A number result (float, or integer converted as the VM path does); `None`: use the VM.
    pub(crate) fn number(&self, p: &[f64], s: &ModelState) -> Option<f64> {
        self.run(p, s, &mut [])?.number()
    }

    /// Write an array result into `out` (all of it, lengths equal); `None`: use the VM.
    pub(crate) fn array(&self, p: &[f64], s: &ModelState, out: &mut [f64]) -> Option<()> {
        (self.run(p, s, out)? == Val::Written).then_some(())
    }
}

/// Where a name points.
#[derive(Clone, Copy)]
enum Binding {
    Local(usize),
    Params,
    State,
}

/// The translator of one function body.
struct Translator<'a> {
    /// Parameter names in index order.
    params: &'a [String],
    /// Names of the functions the script defines (a call to one declines).
    script_fns: &'a HashSet<String>,
    /// Visible names, innermost last.
    names: Vec<(String, Binding)>,
    n_locals: usize,
    /// May an array literal be the function's value (`rates`)?
    arrays: bool,
}

/// Translate script function `name` (arity 5) of `ast`; `None` if it is outside the subset.
pub(crate) fn translate(
    ast: &AST,
    name: &str,
    params: &[String],
    arrays: bool,
) -> Option<CompiledFn> {
    let script_fns: HashSet<String> = ast.iter_fn_def().map(|f| f.name.to_string()).collect();
    let def = ast
        .iter_fn_def()
        .find(|f| f.name == name && f.params.len() == 5)?;
    let body = body_of(ast, (def.body.start_position(), def.body.end_position()))?;
    // p, then t, x, v in local slots 0, 1, 2, then z.
    let bindings = std::iter::once(Binding::Params)
        .chain((0..3).map(Binding::Local))
        .chain([Binding::State]);
    let names = def.params.iter().map(|s| s.to_string()).zip(bindings);
    let mut tr = Translator {
        params,
        script_fns: &script_fns,
        names: names.collect(),
        n_locals: 3,
        arrays,
    };
    let body = tr.statements(&body, true)?;
    Some(CompiledFn {
        body,
        n_locals: tr.n_locals,
    })
}

/// The top-level statements of the function whose body spans `span`.
///
/// rhai does not export the type of a function's body, so the statements are found by
/// walking the AST (main statements first, then each function's) and placing every
/// top-level statement of a function in the body whose source span contains it. A
/// statement that no span contains, or a position that is unknown or saturated, declines.
fn body_of(ast: &AST, span: (Position, Position)) -> Option<Vec<Stmt>> {
    let spans: Vec<(Position, Position)> = ast
        .iter_fn_def()
        .map(|f| (f.body.start_position(), f.body.end_position()))
        .collect();
    let known = |p: Position| {
        p.line().is_some_and(|l| l < usize::from(u16::MAX))
            && p.position().is_none_or(|c| c < usize::from(u16::MAX))
    };
    if !spans.iter().all(|&(a, b)| known(a) && known(b)) {
        return None;
    }
    let mut main_left = ast.statements().len();
    let mut body = Vec::new();
    let mut placed = true;
    let _ = ast.walk(&mut |path: &[ASTNode]| {
        if let [ASTNode::Stmt(stmt)] = path {
            if main_left > 0 {
                main_left -= 1;
                return true;
            }
            let at = stmt.position();
            let inside = |&(a, b): &(Position, Position)| a <= at && at <= b;
            if !known(at) || spans.iter().filter(|s| inside(s)).count() != 1 {
                placed = false;
                return false;
            }
            if inside(&span) {
                body.push((*stmt).clone());
            }
        }
        true
    });
    placed.then_some(body)
}

fn constant(v: Val) -> Node {
    Box::new(move |_| Ok(v))
}

/// The values of `nodes` written to the output slots (the value of `rates`; lengths equal).
fn write_array(nodes: Vec<Node>) -> Node {
    Box::new(move |f| {
        if nodes.len() != f.out.len() {
            return Err(Flow::Bail);
        }
        for (i, node) in nodes.iter().enumerate() {
            let x = node(f)?.number().ok_or(Flow::Bail)?;
            *f.out.get_mut(i).ok_or(Flow::Bail)? = x;
        }
        Ok(Val::Written)
    })
}

/// `value` evaluated into local `slot`.
fn store(slot: usize, value: Node) -> Node {
    Box::new(move |f| {
        let v = value(f)?;
        *f.locals.get_mut(slot).ok_or(Flow::Bail)? = v;
        Ok(Val::Unit)
    })
}

impl Translator<'_> {
    /// What a plain (un-namespaced) variable expression is bound to.
    fn variable(&self, expr: &Expr) -> Option<Binding> {
        let Expr::Variable(var, _, _) = expr else {
            return None;
        };
        let name = var.2.is_empty().then_some(&var.1)?;
        self.names
            .iter()
            .rev()
            .find(|(n, _)| n == name)
            .map(|&(_, b)| b)
    }

    /// Statements in a scope of their own; their value is the last one's.
    fn statements(&mut self, stmts: &[Stmt], tail: bool) -> Option<Node> {
        let mark = self.names.len();
        let mut nodes = Vec::with_capacity(stmts.len());
        for (i, stmt) in stmts.iter().enumerate() {
            nodes.push(self.stmt(stmt, tail && i + 1 == stmts.len())?);
        }
        self.names.truncate(mark);
        Some(match nodes.len() {
            0 => constant(Val::Unit),
            1 => nodes.pop()?,
            _ => {
                let last = nodes.pop()?;
                Box::new(move |f| {
                    for node in &nodes {
                        node(f)?;
                    }
                    last(f)
                })
            }
        })
    }

    fn stmt(&mut self, stmt: &Stmt, tail: bool) -> Option<Node> {
        match stmt {
            Stmt::Noop(_) => Some(constant(Val::Unit)),
            Stmt::Var(var, flags, _) => {
                if !(*flags - ASTFlags::CONSTANT).is_empty() {
                    return None;
                }
                let (ident, init, _) = &**var;
                let init = self.expr(init, false)?;
                let slot = self.n_locals;
                self.n_locals += 1;
                self.names
                    .push((ident.name.to_string(), Binding::Local(slot)));
                Some(store(slot, init))
            }
            Stmt::Assignment(assign) => {
                let (op, target) = &**assign;
                if op.is_op_assignment() {
                    return None;
                }
                let Binding::Local(slot) = self.variable(&target.lhs)? else {
                    return None;
                };
                Some(store(slot, self.expr(&target.rhs, false)?))
            }
            Stmt::If(flow, _) => {
                let cond = self.expr(&flow.expr, false)?;
                let then = self.statements(flow.body.statements(), tail)?;
                let other = self.statements(flow.branch.statements(), tail)?;
                Some(Box::new(move |f| match cond(f)? {
                    Val::Bool(true) => then(f),
                    Val::Bool(false) => other(f),
                    _ => Err(Flow::Bail),
                }))
            }
            Stmt::Expr(e) => self.expr(e, tail),
            Stmt::FnCall(call, _) => self.call(call, None),
            Stmt::Block(block) => self.statements(block.statements(), tail),
            Stmt::Return(value, flags, _) => {
                if !flags.is_empty() {
                    return None; // `throw`
                }
                let value = value
                    .as_ref()
                    .map_or(Some(constant(Val::Unit)), |e| self.expr(e, true))?;
                Some(Box::new(move |f| Err(Flow::Return(value(f)?))))
            }
            _ => None,
        }
    }

    fn expr(&mut self, expr: &Expr, tail: bool) -> Option<Node> {
        match expr {
            Expr::IntegerConstant(i, _) => Some(constant(Val::Int(*i))),
            Expr::FloatConstant(x, _) => Some(constant(Val::Float(**x))),
            Expr::BoolConstant(b, _) => Some(constant(Val::Bool(*b))),
            Expr::Unit(_) => Some(constant(Val::Unit)),
            Expr::DynamicConstant(d, _) if d.is_array() => {
                if !(tail && self.arrays) {
                    return None;
                }
                // A literal array the optimizer folded: numbers only, else decline.
                let items = d.clone().into_array().ok()?;
                let nodes = items
                    .iter()
                    .map(|item| Some(constant(Val::Float(to_f64(item)?))))
                    .collect::<Option<Vec<_>>>()?;
                Some(write_array(nodes))
            }
            Expr::DynamicConstant(d, _) => {
                let v = d
                    .as_int()
                    .map(Val::Int)
                    .or_else(|_| d.as_float().map(Val::Float));
                Some(constant(v.or_else(|_| d.as_bool().map(Val::Bool)).ok()?))
            }
            Expr::Variable(..) => match self.variable(expr)? {
                Binding::Local(slot) => Some(Box::new(move |f| {
                    f.locals.get(slot).copied().ok_or(Flow::Bail)
                })),
                Binding::Params | Binding::State => None,
            },
            Expr::Dot(bin, flags, _) | Expr::Index(bin, flags, _) => {
                let is_dot = matches!(expr, Expr::Dot(..));
                self.chain(&bin.lhs, is_dot, *flags, &bin.rhs)
            }
            Expr::FnCall(call, _) => self.call(call, None),
            Expr::Stmt(block) => self.statements(block.statements(), tail),
            Expr::And(items, _) | Expr::Or(items, _) => {
                let stop_at = matches!(expr, Expr::Or(..));
                let nodes = self.exprs(items)?;
                Some(Box::new(move |f| {
                    for node in &nodes {
                        match node(f)? {
                            Val::Bool(b) if b == stop_at => return Ok(Val::Bool(stop_at)),
                            Val::Bool(_) => {}
                            _ => return Err(Flow::Bail),
                        }
                    }
                    Ok(Val::Bool(!stop_at))
                }))
            }
            Expr::Array(items, _) if tail && self.arrays => Some(write_array(self.exprs(items)?)),
            _ => None,
        }
    }

    /// Expressions that are not the function's value (the items of a list, arguments).
    fn exprs(&mut self, items: &[Expr]) -> Option<Vec<Node>> {
        items.iter().map(|e| self.expr(e, false)).collect()
    }

    /// A chain `base.step…` or `base[step]…`: rhai nests the rest of the chain in the step.
    /// `flags` are those of the node holding `rest`: `BREAK` ends the chain there, `NEGATED`
    /// (`?.`, `?[`) declines.
    fn chain(&mut self, base: &Expr, is_dot: bool, flags: ASTFlags, rest: &Expr) -> Option<Node> {
        let (step, next) = split_chain(flags, rest)?;
        let binding = self.variable(base);
        let head: Node = match (binding, is_dot, step) {
            (Some(Binding::Params), true, Expr::Property(prop, _)) => {
                let index = self.params.iter().position(|n| *n == prop.2.as_str())?;
                Box::new(move |f| f.p.get(index).map(|&x| Val::Float(x)).ok_or(Flow::Bail))
            }
            (Some(Binding::State), false, Expr::IntegerConstant(i, _)) => {
                let i = *i;
                Box::new(move |f| {
                    let n = f.z.len() as i64;
                    let at = if i < 0 { n + i } else { i };
                    usize::try_from(at)
                        .ok()
                        .and_then(|at| f.z.get(at))
                        .map(|&x| Val::Float(x))
                        .ok_or(Flow::Bail)
                })
            }
            (Some(Binding::Params | Binding::State), _, _) => return None,
            (_, true, Expr::MethodCall(call, _)) => {
                let receiver = self.expr(base, false)?;
                self.call(call, Some(receiver))?
            }
            _ => return None,
        };
        self.chain_on(head, next)
    }

    /// The rest of a chain applied to an already translated value (only method calls).
    fn chain_on(&mut self, mut head: Node, mut next: ChainRest<'_>) -> Option<Node> {
        while let Some((is_dot, flags, rest)) = next {
            let (step, after) = split_chain(flags, rest)?;
            let (true, Expr::MethodCall(call, _)) = (is_dot, step) else {
                return None;
            };
            head = self.call(call, Some(head))?;
            next = after;
        }
        Some(head)
    }

    /// An operator or function call; `receiver` is the object of a method call.
    fn call(&mut self, call: &FnCallExpr, receiver: Option<Node>) -> Option<Node> {
        if !call.namespace.is_empty() || call.capture_parent_scope {
            return None;
        }
        let mut args: Vec<Node> = receiver.into_iter().collect();
        args.extend(self.exprs(&call.args)?);
        if let Some(token) = &call.op_token {
            return operator(token, args);
        }
        if self.script_fns.contains(call.name.as_str()) {
            return None;
        }
        function(call.name.as_str(), args)
    }
}

/// The first step of a chain and the rest, if any: `(is_dot, flags, rest)`.
type ChainRest<'e> = Option<(bool, ASTFlags, &'e Expr)>;

/// Split the `rest` of a chain held by a node with `flags`; `None` for `?.`/`?[`.
fn split_chain(flags: ASTFlags, rest: &Expr) -> Option<(&Expr, ChainRest<'_>)> {
    if flags.contains(ASTFlags::NEGATED) {
        return None;
    }
    if flags.contains(ASTFlags::BREAK) {
        return Some((rest, None));
    }
    Some(match rest {
        Expr::Dot(bin, f, _) => (&bin.lhs, Some((true, *f, &bin.rhs))),
        Expr::Index(bin, f, _) => (&bin.lhs, Some((false, *f, &bin.rhs))),
        step => (step, None),
    })
}

/// Binary operators rhai evaluates with its built-in fast path.
#[derive(Clone, Copy)]
enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Rem,
    Pow,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

fn operator(token: &Token, mut args: Vec<Node>) -> Option<Node> {
    if args.len() == 1 {
        let a = args.pop()?;
        return match token {
            Token::Minus | Token::UnaryMinus => Some(Box::new(move |f| match a(f)? {
                Val::Int(i) => i.checked_neg().map(Val::Int).ok_or(Flow::Bail),
                Val::Float(x) => Ok(Val::Float(-x)),
                _ => Err(Flow::Bail),
            })),
            Token::Bang => Some(Box::new(move |f| match a(f)? {
                Val::Bool(b) => Ok(Val::Bool(!b)),
                _ => Err(Flow::Bail),
            })),
            _ => None,
        };
    }
    let op = match token {
        Token::Plus => BinOp::Add,
        Token::Minus => BinOp::Sub,
        Token::Multiply => BinOp::Mul,
        Token::Divide => BinOp::Div,
        Token::Modulo => BinOp::Rem,
        Token::PowerOf => BinOp::Pow,
        Token::EqualsTo => BinOp::Eq,
        Token::NotEqualsTo => BinOp::Ne,
        Token::LessThan => BinOp::Lt,
        Token::LessThanEqualsTo => BinOp::Le,
        Token::GreaterThan => BinOp::Gt,
        Token::GreaterThanEqualsTo => BinOp::Ge,
        _ => return None,
    };
    if args.len() != 2 {
        return None;
    }
    let b = args.pop()?;
    Some(binary_node(args.pop()?, b, move |x, y| binary(op, x, y)))
}

/// A node applying `op` to the values of `a` and `b`; `None` from `op` bails out.
#[inline]
fn binary_node(
    a: Node,
    b: Node,
    op: impl Fn(Val, Val) -> Option<Val> + Send + Sync + 'static,
) -> Node {
    Box::new(move |f| {
        let x = a(f)?;
        let y = b(f)?;
        op(x, y).ok_or(Flow::Bail)
    })
}

/// rhai's built-in binary operators on the subset's types; `None` where rhai errs or
/// dispatches to a registered function.
#[inline]
fn binary(op: BinOp, a: Val, b: Val) -> Option<Val> {
    match (a, b) {
        (Val::Float(x), Val::Float(y)) => float_op(op, x, y),
        (Val::Int(x), Val::Int(y)) => int_op(op, x, y),
        (Val::Bool(x), Val::Bool(y)) => compare(op, x, y).map(Val::Bool),
        // An integer with a float is promoted; other types are not operands.
        _ => float_op(op, a.number()?, b.number()?),
    }
}

/// A comparison on integers or bools (`false < true`); `None` for an arithmetic `op`.
#[inline]
fn compare<T: PartialOrd>(op: BinOp, x: T, y: T) -> Option<bool> {
    Some(match op {
        BinOp::Eq => x == y,
        BinOp::Ne => x != y,
        BinOp::Lt => x < y,
        BinOp::Le => x <= y,
        BinOp::Gt => x > y,
        BinOp::Ge => x >= y,
        _ => return None,
    })
}

/// rhai's float operators (checked build: comparisons with a relative epsilon).
#[inline]
#[allow(clippy::float_cmp)]
fn float_op(op: BinOp, x: f64, y: f64) -> Option<Val> {
    let cmp = |zero: bool, test: fn(f64, f64, f64) -> bool| {
        let m = if x * y == 0.0 {
            1.0
        } else {
            x.abs().max(y.abs())
        };
        Val::Bool(if m == 0.0 { zero } else { test(x, y, m) })
    };
    Some(match op {
        BinOp::Add => Val::Float(x + y),
        BinOp::Sub => Val::Float(x - y),
        BinOp::Mul => Val::Float(x * y),
        BinOp::Div => Val::Float(x / y),
        BinOp::Rem => Val::Float(x % y),
        BinOp::Pow => Val::Float(x.powf(y)),
        BinOp::Eq => cmp(true, |x, y, m| (x - y).abs() / m <= f64::EPSILON),
        BinOp::Ne => cmp(false, |x, y, m| (x - y).abs() / m > f64::EPSILON),
        BinOp::Gt => cmp(false, |x, y, m| (x - y) / m > f64::EPSILON),
        BinOp::Ge => cmp(true, |x, y, m| (x - y) / m > -f64::EPSILON),
        BinOp::Lt => cmp(false, |x, y, m| (y - x) / m > f64::EPSILON),
        BinOp::Le => cmp(true, |x, y, m| (y - x) / m > -f64::EPSILON),
    })
}

/// rhai's checked integer operators; `None` where rhai raises an error.
#[inline]
fn int_op(op: BinOp, x: i64, y: i64) -> Option<Val> {
    Some(match op {
        BinOp::Add => Val::Int(x.checked_add(y)?),
        BinOp::Sub => Val::Int(x.checked_sub(y)?),
        BinOp::Mul => Val::Int(x.checked_mul(y)?),
        BinOp::Div => Val::Int(if y == 0 { None } else { x.checked_div(y) }?),
        BinOp::Rem => Val::Int(x.checked_rem(y)?),
        BinOp::Pow => Val::Int(x.checked_pow(u32::try_from(y).ok()?)?),
        _ => Val::Bool(compare(op, x, y)?),
    })
}

/// A function of rhai's standard packages, on the argument types it is registered for.
fn function(name: &str, mut args: Vec<Node>) -> Option<Node> {
    match args.len() {
        0 => {
            let v = match name {
                "PI" => std::f64::consts::PI,
                "E" => std::f64::consts::E,
                _ => return None,
            };
            Some(constant(Val::Float(v)))
        }
        1 => {
            let (a, op) = (args.pop()?, unary_fn(name)?);
            Some(Box::new(move |f| op(a(f)?).ok_or(Flow::Bail)))
        }
        2 => {
            let b = args.pop()?;
            Some(binary_node(args.pop()?, b, binary_fn(name)?))
        }
        _ => None,
    }
}

type UnaryFn = fn(Val) -> Option<Val>;
type BinaryFn = fn(Val, Val) -> Option<Val>;

/// A float method as a function of the subset: `float_fn!(sin)` (a float result),
/// `float_fn!(is_nan, Bool)` (another result type), `float_fn!(2 hypot)` (two floats).
macro_rules! float_fn {
    ($method:ident) => {
        float_fn!($method, Float)
    };
    ($method:ident, $result:ident) => {
        (|v| match v {
            Val::Float(x) => Some(Val::$result(x.$method())),
            _ => None,
        }) as UnaryFn
    };
    (2 $method:ident) => {
        (|a, b| match (a, b) {
            (Val::Float(x), Val::Float(y)) => Some(Val::Float(x.$method(y))),
            _ => None,
        }) as BinaryFn
    };
}

/// One-argument functions: rhai's float math takes floats only (an integer argument is a
/// "function not found" error, left to the VM).
fn unary_fn(name: &str) -> Option<UnaryFn> {
    Some(match name {
        "sin" => float_fn!(sin),
        "cos" => float_fn!(cos),
        "tan" => float_fn!(tan),
        "sinh" => float_fn!(sinh),
        "cosh" => float_fn!(cosh),
        "tanh" => float_fn!(tanh),
        "asin" => float_fn!(asin),
        "acos" => float_fn!(acos),
        "atan" => float_fn!(atan),
        "asinh" => float_fn!(asinh),
        "acosh" => float_fn!(acosh),
        "atanh" => float_fn!(atanh),
        "to_radians" => float_fn!(to_radians),
        "to_degrees" => float_fn!(to_degrees),
        "sqrt" => float_fn!(sqrt),
        "exp" => float_fn!(exp),
        "ln" => float_fn!(ln),
        "log" => float_fn!(log10),
        "floor" => float_fn!(floor),
        "ceiling" => float_fn!(ceil),
        "round" => float_fn!(round),
        "int" => float_fn!(trunc),
        "fraction" => float_fn!(fract),
        "is_nan" => float_fn!(is_nan, Bool),
        "is_finite" => float_fn!(is_finite, Bool),
        "is_infinite" => float_fn!(is_infinite, Bool),
        "abs" => |v| match v {
            Val::Float(x) => Some(Val::Float(x.abs())),
            Val::Int(i) => i.checked_abs().map(Val::Int),
            _ => None,
        },
        // rhai: 0 for ±0.0, an error for NaN, else signum as an integer.
        #[allow(clippy::redundant_guards)]
        "sign" => |v| match v {
            Val::Float(x) if x == 0.0 => Some(Val::Int(0)),
            Val::Float(x) if x.is_nan() => None,
            Val::Float(x) => Some(Val::Int(x.signum() as i64)),
            Val::Int(i) => Some(Val::Int(i.signum())),
            _ => None,
        },
        "to_float" => |v| v.number().map(Val::Float),
        "to_int" => |v| match v {
            Val::Int(i) => Some(Val::Int(i)),
            Val::Float(x) if x > i64::MAX as f64 || x < i64::MIN as f64 => None,
            Val::Float(x) => Some(Val::Int(x.trunc() as i64)),
            _ => None,
        },
        _ => return None,
    })
}

/// Two-argument functions.
fn binary_fn(name: &str) -> Option<BinaryFn> {
    Some(match name {
        "atan" => float_fn!(2 atan2),
        "hypot" => float_fn!(2 hypot),
        "log" => float_fn!(2 log),
        "max" => |a, b| pick(a, b, |x, y| x >= y, |x, y| x >= y),
        "min" => |a, b| pick(a, b, |x, y| x <= y, |x, y| x <= y),
        _ => return None,
    })
}

/// rhai's `max`/`min`: `if keep_first(x, y) { x } else { y }`, integers mixed with floats
/// converted to float first.
fn pick(a: Val, b: Val, int: fn(i64, i64) -> bool, float: fn(f64, f64) -> bool) -> Option<Val> {
    if let (Val::Int(x), Val::Int(y)) = (a, b) {
        return Some(Val::Int(if int(x, y) { x } else { y }));
    }
    let (x, y) = (a.number()?, b.number()?);
    Some(Val::Float(if float(x, y) { x } else { y }))
}
