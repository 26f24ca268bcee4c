//! The limits a script runs under: its size (refused before compiling, the limit named), the
//! operation budget of one call (deterministic: the verdict follows the operation count, not
//! the clock) and the budget of all its calls in one run.

use std::sync::Arc;

use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::Simulation;
use stf_plugins::{ScriptError, ScriptLimits, ScriptModel, ScriptRun};

const PARAMS: &str = "fn params() { #{ c: [1.0, 0.0, 10.0, \"N s/m\"] } }\n";

/// A script of `n` one-line helper functions.
fn many_functions(n: usize) -> String {
    let mut src = PARAMS.to_string();
    for i in 0..n {
        src.push_str(&format!("fn h{i}(v) {{ v * {i}.0 + 1.0 }}\n"));
    }
    src + "fn force(p, t, x, v, z) { h0(p.c * v) }\n"
}

fn run_with(limits: ScriptLimits) -> ScriptRun {
    ScriptRun::new(limits)
}

fn load_err(src: &str, run: &ScriptRun) -> String {
    match ScriptModel::from_source_in("big.rhai", src, run) {
        Ok(_) => panic!("loaded"),
        Err(e) => {
            assert!(matches!(e, ScriptError::TooLarge { .. }), "{e}");
            e.to_string()
        }
    }
}

#[test]
fn a_script_of_many_functions_is_refused_before_compiling_with_the_limit_named() {
    let run = run_with(ScriptLimits {
        max_functions: 10,
        ..ScriptLimits::default()
    });
    let msg = load_err(&many_functions(50), &run);
    assert!(
        msg.starts_with("big.rhai: the script is too large to load")
            && msg.contains("52 functions")
            && msg.contains("the limit is 10")
            && msg.contains("max_functions"),
        "{msg}"
    );
    // At the limit it loads.
    assert!(ScriptModel::from_source_in("ok.rhai", &many_functions(8), &run).is_ok());
}

#[test]
fn the_issue_s_twenty_thousand_helpers_are_refused_by_size_with_the_default_limits() {
    let src = many_functions(20_000);
    let msg = match ScriptModel::from_source("huge.rhai", &src) {
        Ok(_) => panic!("loaded"),
        Err(e) => e.to_string(),
    };
    assert!(
        msg.starts_with("huge.rhai:") && msg.contains("bytes") && msg.contains("max_bytes"),
        "{msg}"
    );
    // Under the byte limit, the function limit refuses 2 000 helpers.
    let small = ScriptLimits {
        max_bytes: usize::MAX,
        ..ScriptLimits::default()
    };
    let msg = load_err(&many_functions(2_000), &run_with(small));
    assert!(msg.contains("max_functions"), "{msg}");
}

#[test]
fn many_constants_or_nodes_are_refused_with_their_limit_named() {
    let mut body = String::from("let s = 0.0;\n");
    for i in 0..200 {
        body.push_str(&format!("s += {i}.5 * v;\n"));
    }
    let src = format!("{PARAMS}fn force(p, t, x, v, z) {{\n{body}s\n}}\n");
    let msg = load_err(
        &src,
        &run_with(ScriptLimits {
            max_constants: 100,
            ..ScriptLimits::default()
        }),
    );
    assert!(
        msg.contains("more than 100 constants") && msg.contains("max_constants"),
        "{msg}"
    );
    let msg = load_err(
        &src,
        &run_with(ScriptLimits {
            max_nodes: 300,
            ..ScriptLimits::default()
        }),
    );
    assert!(
        msg.contains("more than 300") && msg.contains("max_nodes"),
        "{msg}"
    );
    assert!(ScriptModel::from_source("fine.rhai", &src).is_ok());
}

/// A script whose force call performs a fixed number of slow operations (each `contains`
/// scans 100 elements).
const SLOW: &str = "fn force(p, t, x, v, z) {\n  let a = [];\n  a.pad(100, 1.0);\n  \
                    for i in 0..20 { a.contains(2.0); }\n  p.c * v\n}\n";

#[test]
fn a_slow_script_s_verdict_follows_its_operations_not_the_clock() {
    let src = format!("{PARAMS}{SLOW}");
    // Its operation count at the defaults is a property of the script, the same every load.
    let ops = ScriptModel::from_source("slow.rhai", &src)
        .unwrap()
        .force_operations();
    assert!(ops > 20, "{ops}");
    assert_eq!(
        ScriptModel::from_source("slow.rhai", &src)
            .unwrap()
            .force_operations(),
        ops
    );
    // A budget of exactly that many operations passes, one fewer stops it — whatever the
    // wall-clock limit (none at all, or generous), every time.
    for seconds in [f64::INFINITY, 1000.0] {
        for _ in 0..2 {
            let limits = |call_operations| ScriptLimits {
                call_operations,
                call_seconds: seconds,
                ..ScriptLimits::default()
            };
            assert!(ScriptModel::from_source_in("slow.rhai", &src, &run_with(limits(ops))).is_ok());
            let msg = ScriptModel::from_source_in("slow.rhai", &src, &run_with(limits(ops - 1)))
                .err()
                .unwrap()
                .to_string();
            assert!(
                msg.starts_with("slow.rhai:")
                    && msg.contains("operation budget")
                    && msg.contains(&format!("more than {} operations", ops - 1))
                    && msg.contains("call_operations")
                    && !msg.contains("wall-clock"),
                "{msg}"
            );
        }
    }
}

#[test]
fn the_run_budget_stops_a_simulation_and_is_shared_by_every_load_of_the_script() {
    let src = format!("{PARAMS}{SLOW}");
    let ops = ScriptModel::from_source("slow.rhai", &src)
        .unwrap()
        .force_operations();
    // Room for the load-time checks of two loads and a few hundred calls, not a simulation.
    let run = run_with(ScriptLimits {
        run_operations: 600 * ops,
        ..ScriptLimits::default()
    });
    let first = ScriptModel::from_source_in("slow.rhai", &src, &run).unwrap();
    let after_one = run.operations_used("slow.rhai");
    assert!(after_one >= 2 * ops, "{after_one}");
    let second = ScriptModel::from_source_in("slow.rhai", &src, &run).unwrap();
    assert_eq!(run.operations_used("slow.rhai"), 2 * after_one);
    drop(first);

    let osc = Oscillator::new(
        OscillatorParams::FORCED,
        Excitation::Rotor(RotorAngle::sweep(2.35, 0.047, 50.0)),
    )
    .with_model(Arc::new(second), vec![1.0])
    .unwrap();
    let err = Simulation::new(&osc)
        .rate(100.0)
        .run(50.0, 60.0)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("slow.rhai")
            && err.contains("run budget")
            && err.contains(&format!("more than {} operations", 600 * ops))
            && err.contains("run_operations"),
        "{err}"
    );
    assert!(run.operations_used("slow.rhai") > 600 * ops);
}
