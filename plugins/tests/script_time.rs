//! Time in scripts: no sleeping or clock functions, a run's time budget said and checked
//! before the run (the cost of a call measured at load, times the calls the run needs), and
//! the other ways a script's call can end badly named with the script and line (`exit`, a
//! force that is not a finite number).

use stf_core::physics::force_model::{ForceModel, ModelState};
use stf_plugins::{ScriptError, ScriptLimits, ScriptModel, ScriptRun};

const PARAMS: &str = "fn params() { #{ c: [1.0, 0.0, 10.0, \"N s/m\"] } }\n";

fn load(body: &str) -> Result<ScriptModel, ScriptError> {
    ScriptModel::from_source("timed.rhai", &format!("{PARAMS}{body}"))
}

fn load_err(body: &str) -> String {
    match load(body) {
        Ok(_) => panic!("loaded: {body}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn sleeping_and_the_clock_are_refused_at_load_with_the_line() {
    // The script slept 12 s in every call and hung `models --check` and `fit`.
    for (body, name) in [
        (
            "fn force(p, t, x, v, z) {\n  sleep(12);\n  p.c * v\n}\n",
            "sleep",
        ),
        (
            "fn force(p, t, x, v, z) {\n  sleep(0.5);\n  p.c * v\n}\n",
            "sleep",
        ),
        (
            "fn force(p, t, x, v, z) {\n  let s = timestamp();\n  p.c * v\n}\n",
            "timestamp",
        ),
    ] {
        // Refused when loaded (a contract error), not when a call reaches it.
        let e = load(body).err().unwrap();
        assert!(matches!(e, ScriptError::Contract { .. }), "{e}");
        let msg = e.to_string();
        assert!(
            msg.starts_with("timed.rhai:3: `")
                && msg.contains(&format!("`{name}` is not available to scripts"))
                && msg.contains("no sleeping or clock functions"),
            "{msg}"
        );
    }
    // Reached by name at run time, it fails the call instead of sleeping.
    let msg =
        load_err("fn force(p, t, x, v, z) {\n  Fn(\"sl\" + \"eep\").call(12);\n  p.c * v\n}\n");
    assert!(
        msg.starts_with("timed.rhai:") && msg.contains("`sleep` is not available"),
        "{msg}"
    );
    // A script's own function of that name is its own business.
    assert!(load("fn sleep(v) { v }\nfn force(p, t, x, v, z) { sleep(p.c * v) }\n").is_ok());
}

/// A script whose every call does real work on the VM (a sort of 2 000 numbers).
const SLOW: &str = "fn force(p, t, x, v, z) {\n  let a = [];\n  a.pad(2000, 1.0);\n  \
                    a.sort();\n  p.c * v + a[0] - 1.0\n}\n";

#[test]
fn a_run_whose_plan_exceeds_the_time_budget_is_refused_before_it_starts() {
    let run = ScriptRun::new(ScriptLimits::default());
    let model = ScriptModel::from_source_in("slow.rhai", &format!("{PARAMS}{SLOW}"), &run).unwrap();
    assert!(!model.is_compiled());
    assert!(model.call_seconds() > 0.0);
    // 10¹² calls of a VM script (at least 0.1 µs each) are days, whatever the machine.
    let e = run.plan(1e12, "a fit").unwrap_err();
    assert!(matches!(e, ScriptError::Budget { .. }), "{e}");
    let msg = e.to_string();
    assert!(
        msg.starts_with("slow.rhai: this script costs ~")
            && msg.contains(" a call: a fit needs ~1.0e12 calls, ~")
            && msg.contains("the limit is 10.0 min of script calls a run")
            && msg.contains("`[scripts] run_seconds`"),
        "{msg}"
    );
    // Raised, the same plan is said and allowed.
    let generous = ScriptRun::new(ScriptLimits {
        run_seconds: f64::INFINITY,
        ..ScriptLimits::default()
    });
    ScriptModel::from_source_in("slow.rhai", &format!("{PARAMS}{SLOW}"), &generous).unwrap();
    let lines = generous.plan(1e12, "a fit").unwrap();
    assert_eq!(lines.len(), 1);
    assert!(lines[0].1 > 1e4, "{lines:?}");
    assert!(
        lines[0].0.starts_with("slow.rhai: this script costs ~") && lines[0].0.contains("1.0e12"),
        "{lines:?}"
    );
    // A run of no scripts plans nothing.
    assert!(ScriptRun::default().plan(1e12, "a fit").unwrap().is_empty());
}

#[test]
fn the_time_budget_stops_a_run_whose_calls_take_longer() {
    // Any call takes more than a nanosecond: the load's own calls use the budget up.
    let run = ScriptRun::new(ScriptLimits {
        run_seconds: 1e-9,
        ..ScriptLimits::default()
    });
    let msg = match ScriptModel::from_source_in("slow.rhai", &format!("{PARAMS}{SLOW}"), &run) {
        Ok(_) => panic!("loaded"),
        Err(e) => e.to_string(),
    };
    assert!(
        msg.starts_with("slow.rhai:")
            && msg.contains("stopped by its run time budget")
            && msg.contains("`[scripts] run_seconds`"),
        "{msg}"
    );
}

#[test]
fn exit_in_a_script_is_named_as_such() {
    let msg = load_err("fn force(p, t, x, v, z) {\n  exit(3);\n}\n");
    assert!(
        // The line of the function: rhai gives `exit` no position.
        msg.starts_with("timed.rhai:2: ")
            && msg.contains("the script called exit(3)")
            && !msg.contains("NOT AN ERROR"),
        "{msg}"
    );
}

#[test]
fn a_force_that_is_not_a_number_names_the_script_line_and_arguments() {
    for body in [
        // On the compiled path and on the VM.
        "fn force(p, t, x, v, z) {\n  if t > 1.0 { (-p.c).sqrt() } else { p.c * v }\n}\n",
        "fn force(p, t, x, v, z) {\n  let a = [1.0];\n  if t > 1.0 { (-p.c).sqrt() } else { p.c * v * a[0] }\n}\n",
    ] {
        let model = load(body).unwrap();
        let s = ModelState {
            t: 2.0,
            x: 0.01,
            v: 0.5,
            z: &[],
        };
        let msg = model.force(&[4.0], &s, &mut []).unwrap_err().to_string();
        assert!(
            msg.contains("timed.rhai")
                && msg.contains("line 2")
                && msg.contains("fn force returned NaN, not a finite number, at t = 2, x = 0.01, v = 0.5 with c = 4"),
            "{msg}"
        );
        let ok = ModelState { t: 0.5, ..s };
        assert_eq!(model.force(&[4.0], &ok, &mut []).unwrap(), 2.0);
    }
}
