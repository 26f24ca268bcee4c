//! Script models against native twins, the sandbox rules, load-time checks and run-time
//! errors.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use stf_core::numerics::integrate::SimError;
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::force_model::{ForceModel, ModelState};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::physics::param_spec::defaults;
use stf_core::simulate::{Simulation, Trajectory};
use stf_plugins::registry::Registry;
use stf_plugins::{ScriptError, ScriptLimits, ScriptModel, ScriptRun};

mod support;
use support::NativePowerLaw;

fn scripts_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/scripts")
}

fn sweep(
    model: Arc<dyn ForceModel>,
    p: Vec<f64>,
    t0: f64,
    t1: f64,
) -> Result<Trajectory, SimError> {
    let osc = Oscillator::new(
        OscillatorParams::FORCED,
        Excitation::Rotor(RotorAngle::sweep(2.35, 0.047, 50.0)),
    )
    .with_model(model, p)
    .unwrap();
    Simulation::new(&osc).rate(1000.0).run(t0, t1)
}

fn load_err(name: &str, source: &str) -> String {
    match ScriptModel::from_source(name, source) {
        Ok(_) => panic!("{name} loaded"),
        Err(e) => e.to_string(),
    }
}

const PARAMS: &str = "fn params() { #{ c: [1.0, 0.0, 10.0, \"N s/m\"] } }\n";

#[test]
fn power_law_script_computes_the_native_bits() {
    let script = ScriptModel::load(scripts_dir().join("power_law.rhai")).unwrap();
    let names: Vec<_> = script.params().iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["K", "n"]);
    let native = NativePowerLaw(script.params().to_vec());
    for &v in &[0.0, 1e-9, -3e-7, 0.0123, -0.0456, 0.7, -1.3, 12.5] {
        for p in [[5.0, 1.6], [0.3, 2.7], [800.0, 1.0]] {
            let s = ModelState {
                t: 1.0,
                x: 0.01,
                v,
                z: &[],
            };
            let a = script.force(&p, &s, &mut []).unwrap();
            let b = native.force(&p, &s, &mut []).unwrap();
            assert!(
                a == b && (a.to_bits() == b.to_bits() || a == 0.0),
                "v {v}: {a} vs {b}"
            );
        }
    }
}

#[test]
fn native_and_script_power_law_simulate_the_same_sweep() {
    let script: Arc<dyn ForceModel> =
        Arc::new(ScriptModel::load(scripts_dir().join("power_law.rhai")).unwrap());
    let native: Arc<dyn ForceModel> = Arc::new(NativePowerLaw(script.params().to_vec()));
    let p = vec![20.0, 1.6];
    let a = sweep(script, p.clone(), 80.0, 84.0).unwrap();
    let b = sweep(native, p, 80.0, 84.0).unwrap();
    let scale = b.x.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(scale > 1e-4, "the blade should move: {scale}");
    for (xa, xb) in a.x.iter().zip(&b.x) {
        assert!((xa - xb).abs() <= 1e-9 * scale, "{xa} vs {xb}");
    }
    for (fa, fb) in a.f_stf.iter().zip(&b.f_stf) {
        assert!(
            (fa - fb).abs() <= 1e-9 * fb.abs().max(1e-12),
            "{fa} vs {fb}"
        );
    }
}

#[test]
fn style_example_loads_and_simulates() {
    let m = ScriptModel::load(scripts_dir().join("structure_thickening.rhai")).unwrap();
    assert_eq!(m.n_internal(), 1);
    assert!(m.summary().starts_with("Power-law thickening"));
    let names: Vec<_> = m.params().iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["K", "n", "tau"]);
    let p = defaults(m.params());
    let run = sweep(Arc::new(m), p, 80.0, 83.0).unwrap();
    let lambda = &run.z[0];
    let vmax = run.v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // λ relaxes towards |v| from 0: it grows, and never exceeds the largest |v|.
    assert!(lambda.iter().any(|&l| l > 0.0));
    assert!(
        lambda.iter().all(|&l| (0.0..=vmax * 1.0001).contains(&l)),
        "vmax {vmax}"
    );
    assert!(run.f_stf.iter().all(|f| f.is_finite()));
}

#[test]
fn runtime_error_in_a_simulation_names_script_line_and_time() {
    let src = format!(
        "{PARAMS}fn force(p, t, x, v, z) {{\n  if t > 80.5 {{ no_such_fn(v) }}\n  p.c * v\n}}"
    );
    let m = ScriptModel::from_source("fails_late.rhai", &src).unwrap();
    let err = sweep(Arc::new(m), vec![1.0], 80.0, 81.0).unwrap_err();
    let SimError::Model { time, source } = &err else {
        panic!("{err}");
    };
    assert!(*time >= 80.5 && *time < 80.6, "{err}");
    assert_eq!(source.model, "fails_late.rhai");
    assert!(source.message.contains("line 3"), "{err}");
    assert!(source.message.contains("no_such_fn"), "{err}");
}

#[test]
fn a_non_number_result_is_a_model_error() {
    let src =
        format!("{PARAMS}fn force(p, t, x, v, z) {{ if t > 1.0 {{ \"soft\" }} else {{ 0.0 }} }}");
    let m = ScriptModel::from_source("stringly.rhai", &src).unwrap();
    let s = ModelState {
        t: 2.0,
        x: 0.0,
        v: 0.0,
        z: &[],
    };
    let e = m.force(&[1.0], &s, &mut []).unwrap_err();
    assert_eq!(e.model, "stringly.rhai");
    assert!(e.message.contains("not a number"), "{e}");
}

#[test]
fn rates_of_the_wrong_length_are_a_model_error() {
    let src = format!(
        "{PARAMS}fn n_internal() {{ 2 }}\nfn force(p, t, x, v, z) {{ 0.0 }}\n\
         fn rates(p, t, x, v, z) {{ if t > 1.0 {{ [1.0] }} else {{ [0.0, 0.0] }} }}"
    );
    let m = ScriptModel::from_source("rates.rhai", &src).unwrap();
    let s = ModelState {
        t: 2.0,
        x: 0.0,
        v: 0.0,
        z: &[0.0, 0.0],
    };
    let e = m.force(&[1.0], &s, &mut [0.0, 0.0]).unwrap_err();
    assert!(e.message.contains("array of 2 numbers"), "{e}");
}

// ---- sandbox: every rule fails with a message naming the script (and line) ----

fn assert_names(err: &str, script: &str, line: Option<usize>, what: &str) {
    assert!(err.contains(script), "{err}");
    if let Some(line) = line {
        assert!(err.contains(&format!("{script}:{line}")), "{err}");
    }
    assert!(err.to_lowercase().contains(&what.to_lowercase()), "{err}");
}

#[test]
fn sandbox_has_no_file_access() {
    let src = format!(
        "{PARAMS}fn force(p, t, x, v, z) {{\n  let f = open_file(\"/etc/passwd\");\n  0.0\n}}"
    );
    assert_names(
        &load_err("reads.rhai", &src),
        "reads.rhai",
        Some(3),
        "open_file",
    );
    let src = format!("{PARAMS}fn force(p, t, x, v, z) {{\n  read_file(\"/etc/passwd\").len()\n}}");
    assert_names(
        &load_err("reads2.rhai", &src),
        "reads2.rhai",
        Some(3),
        "read_file",
    );
}

#[test]
fn sandbox_cannot_write_files_or_spawn_processes() {
    let src = format!(
        "{PARAMS}fn force(p, t, x, v, z) {{\n  write_file(\"/tmp/owned\", \"x\");\n  0.0\n}}"
    );
    assert_names(
        &load_err("writes.rhai", &src),
        "writes.rhai",
        Some(3),
        "write_file",
    );
    let src =
        format!("{PARAMS}fn force(p, t, x, v, z) {{\n  0.0\n}}\nfn rates(p, t, x, v, z) {{\n  system(\"rm -rf /\")\n}}\nfn n_internal() {{ 1 }}");
    assert_names(
        &load_err("spawns.rhai", &src),
        "spawns.rhai",
        Some(6),
        "system",
    );
}

#[test]
fn sandbox_stops_a_call_past_its_wall_clock_limit_as_a_last_resort() {
    // Each `contains` on a 10 000-element array is one operation of ~10 µs or more: the
    // operation budget alone would let this run for many seconds. The wall-clock limit (here
    // 0.05 s) stops it, and says that this verdict depends on the machine.
    let src = format!(
        "{PARAMS}fn force(p, t, x, v, z) {{\n  let a = [];\n  a.pad(10000, 1.0);\n  loop {{ a.contains(2.0); }}\n}}"
    );
    let run = ScriptRun::new(ScriptLimits {
        call_seconds: 0.05,
        ..ScriptLimits::default()
    });
    let err = ScriptModel::from_source_in("slow.rhai", &src, &run)
        .err()
        .unwrap()
        .to_string();
    assert_names(
        &err,
        "slow.rhai",
        Some(2),
        "wall-clock safety limit of 0.05 s",
    );
    assert!(
        err.contains("call_seconds") && err.contains("machine"),
        "{err}"
    );
}

#[test]
fn sandbox_refuses_import_and_eval() {
    let src = format!("import \"os\" as os;\n{PARAMS}fn force(p, t, x, v, z) {{ 0.0 }}");
    assert_names(
        &load_err("imports.rhai", &src),
        "imports.rhai",
        Some(1),
        "import",
    );
    let src = format!("{PARAMS}fn force(p, t, x, v, z) {{\n  eval(\"1.0\")\n}}");
    assert_names(&load_err("evals.rhai", &src), "evals.rhai", Some(3), "eval");
}

#[test]
fn sandbox_stops_endless_loops() {
    let src = format!("{PARAMS}fn force(p, t, x, v, z) {{\n  let i = 0;\n  loop {{ i += 1; }}\n}}");
    assert_names(
        &load_err("loops.rhai", &src),
        "loops.rhai",
        Some(2),
        "operations",
    );
    // Also when the loop only starts during a simulation.
    let src = format!("{PARAMS}fn force(p, t, x, v, z) {{\n  while t > 80.2 {{ }}\n  p.c * v\n}}");
    let m = ScriptModel::from_source("loops_late.rhai", &src).unwrap();
    let err = sweep(Arc::new(m), vec![1.0], 80.0, 81.0)
        .unwrap_err()
        .to_string();
    assert_names(&err, "loops_late.rhai", None, "operations");
    assert!(err.contains("line 2"), "{err}");
}

#[test]
fn sandbox_stops_endless_recursion() {
    let src = format!(
        "{PARAMS}fn deeper(n) {{ deeper(n + 1) }}\nfn force(p, t, x, v, z) {{ deeper(0) }}"
    );
    assert_names(
        &load_err("recurses.rhai", &src),
        "recurses.rhai",
        Some(3),
        "nested calls",
    );
}

#[test]
fn sandbox_limits_data_sizes() {
    let src = format!(
        "{PARAMS}fn force(p, t, x, v, z) {{\n  let a = [];\n  a.pad(100000000, 0.0);\n  0.0\n}}"
    );
    assert_names(
        &load_err("big_array.rhai", &src),
        "big_array.rhai",
        Some(2),
        "too large",
    );
    let src =
        format!("{PARAMS}fn force(p, t, x, v, z) {{\n  let s = \"x\";\n  loop {{ s += s; }}\n}}");
    assert_names(
        &load_err("big_string.rhai", &src),
        "big_string.rhai",
        Some(2),
        "too large",
    );
    let src =
        format!("{PARAMS}fn force(p, t, x, v, z) {{\n  let a = [];\n  loop {{ a.push(1.0); }}\n}}");
    assert_names(
        &load_err("growing_array.rhai", &src),
        "growing_array.rhai",
        Some(2),
        "too large",
    );
    // Object maps: rhai 1.27's grain VM does not check the map size limit on `m[k] = v` (the
    // AST walker does); such a map is still bounded by the operation budget.
}

#[test]
fn sandbox_rejects_undefined_variables_and_functions() {
    let src = format!("{PARAMS}fn force(p, t, x, v, z) {{\n  p.c * velocity\n}}");
    assert_names(
        &load_err("typo.rhai", &src),
        "typo.rhai",
        Some(3),
        "velocity",
    );
    let src = format!("{PARAMS}fn force(p, t, x, v, z) {{\n  p.c * speed(v)\n}}");
    assert_names(&load_err("nofn.rhai", &src), "nofn.rhai", Some(3), "speed");
}

// ---- load-time checks ----

#[test]
fn missing_or_ill_formed_functions_are_load_errors() {
    let e = load_err("no_force.rhai", PARAMS);
    assert_names(&e, "no_force.rhai", None, "fn force(p, t, x, v, z)");
    let e = load_err("no_params.rhai", "fn force(p, t, x, v, z) { 0.0 }");
    assert_names(&e, "no_params.rhai", None, "fn params()");
    let src = format!("{PARAMS}\n// comment\nfn force(p, t, x, v) {{ 0.0 }}");
    assert_names(
        &load_err("arity.rhai", &src),
        "arity.rhai",
        Some(4),
        "takes 4 argument",
    );
    let src = format!("{PARAMS}fn n_internal() {{ 1 }}\nfn force(p, t, x, v, z) {{ 0.0 }}");
    assert_names(
        &load_err("no_rates.rhai", &src),
        "no_rates.rhai",
        Some(2),
        "must define fn rates",
    );
    let src = format!("{PARAMS}fn n_internal() {{ -1 }}\nfn force(p, t, x, v, z) {{ 0.0 }}");
    assert_names(
        &load_err("neg.rhai", &src),
        "neg.rhai",
        Some(2),
        "integer from 0",
    );
    let e = load_err(
        "syntax.rhai",
        "fn params() { #{} }\nfn force(p, t, x, v, z) { 1.0 +* 2.0 }",
    );
    assert_names(&e, "syntax.rhai", Some(2), "syntax error");
}

#[test]
fn bad_params_maps_are_load_errors_at_the_params_line() {
    let force = "fn force(p, t, x, v, z) { 0.0 }";
    for (params, what) in [
        ("#{ c: [5.0, 6.0, 10.0, \"\"] }", "min <= default <= max"),
        ("#{ c: [5.0, 0.0, 10.0] }", "3 elements"),
        ("#{ c: [5.0, 0.0, \"ten\", \"\"] }", "max must be a number"),
        ("#{ c: [5.0, 0.0, 10.0, 1] }", "unit must be a string"),
        ("[1.0, 2.0]", "object map"),
    ] {
        let src = format!("// header\nfn params() {{ {params} }}\n{force}");
        assert_names(&load_err("params.rhai", &src), "params.rhai", Some(2), what);
    }
}

#[test]
fn unreadable_script_is_a_read_error() {
    let e = ScriptModel::load("/nonexistent/dir/model.rhai").unwrap_err();
    assert!(matches!(e, ScriptError::Read { .. }), "{e}");
    assert!(e.to_string().contains("/nonexistent/dir/model.rhai"), "{e}");
}

#[test]
fn a_script_over_the_cap_is_refused_with_its_size_and_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.rhai");
    let text = "// padding\n".repeat(100);
    std::fs::write(&path, &text).unwrap();
    let run = ScriptRun::new(ScriptLimits {
        max_bytes: 999,
        ..ScriptLimits::default()
    });
    let e = ScriptModel::load_in(&path, &run).unwrap_err();
    assert!(matches!(e, ScriptError::TooLarge { .. }), "{e}");
    assert_eq!(
        e.to_string(),
        format!(
            "{}: the script is too large to load: it is {} bytes, over the limit of 999 bytes \
             (`[scripts] max_bytes`)",
            path.display(),
            text.len()
        )
    );
    #[cfg(unix)]
    {
        let e = ScriptModel::load("/dev/zero").unwrap_err();
        assert_eq!(
            e.to_string(),
            "/dev/zero: the script is too large to load: it holds more than the limit of 65536 \
             bytes (`[scripts] max_bytes`)"
        );
    }
}

// ---- the VM is shared per thread by all scripts ----

#[test]
fn scripts_with_same_named_helpers_do_not_mix() {
    let a = ScriptModel::from_source(
        "a",
        &format!("{PARAMS}fn helper(v) {{ v * 2.0 }}\nfn force(p, t, x, v, z) {{ helper(v) }}"),
    )
    .unwrap();
    let b = ScriptModel::from_source(
        "b",
        &format!("{PARAMS}fn helper(v) {{ v * 3.0 }}\nfn force(p, t, x, v, z) {{ helper(v) }}"),
    )
    .unwrap();
    let s = ModelState {
        t: 0.0,
        x: 0.0,
        v: 1.0,
        z: &[],
    };
    for _ in 0..3 {
        assert_eq!(a.force(&[1.0], &s, &mut []).unwrap(), 2.0);
        assert_eq!(b.force(&[1.0], &s, &mut []).unwrap(), 3.0);
    }
}

#[test]
fn one_model_runs_on_several_threads() {
    let m = Arc::new(ScriptModel::load(scripts_dir().join("power_law.rhai")).unwrap());
    let results: Vec<Vec<f64>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..4)
            .map(|k| {
                let m = Arc::clone(&m);
                scope.spawn(move || {
                    (0..2000)
                        .map(|i| {
                            let s = ModelState {
                                t: 0.0,
                                x: 0.0,
                                v: 0.001 * i as f64,
                                z: &[],
                            };
                            m.force(&[1.0 + k as f64, 1.5], &s, &mut []).unwrap()
                        })
                        .collect()
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (k, r) in results.iter().enumerate() {
        for (i, f) in r.iter().enumerate() {
            let v = 0.001 * i as f64;
            assert_eq!(*f, (1.0 + k as f64) * v.abs().powf(1.5) * v.signum());
        }
    }
}

// ---- registry ----

#[test]
fn registry_resolves_scripts_relative_to_the_base_dir() {
    let reg = Registry::new();
    let m = reg.resolve("power_law.rhai", &scripts_dir()).unwrap();
    assert_eq!(m.name(), "power_law");
    let err = reg
        .resolve("missing.rhai", &scripts_dir())
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("missing.rhai"), "{err}");
}

#[test]
fn registry_lists_builtins_and_scripts() {
    let list = Registry::with_script_dir(scripts_dir()).list();
    let n = stf_models::BUILTINS.len();
    assert!(list[..n].iter().all(|e| !e.is_script));
    let scripts: Vec<_> = list[n..].iter().map(|e| e.name.clone()).collect();
    assert!(
        scripts.iter().any(|s| s.ends_with("power_law.rhai")),
        "{scripts:?}"
    );
    assert!(
        scripts
            .iter()
            .any(|s| s.ends_with("structure_thickening.rhai")),
        "{scripts:?}"
    );
    assert!(list[n..]
        .iter()
        .all(|e| !e.params.is_empty() && !e.summary.is_empty()));
}

#[test]
fn check_script_gives_params_or_the_error() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.rhai");
    std::fs::write(
        &good,
        format!("{PARAMS}fn force(p, t, x, v, z) {{ p.c * v }}"),
    )
    .unwrap();
    assert_eq!(ScriptModel::load(&good).unwrap().params()[0].name, "c");
    let bad = dir.path().join("bad.rhai");
    std::fs::write(&bad, format!("{PARAMS}fn force(p, t, x) {{ 0.0 }}")).unwrap();
    let e = ScriptModel::load(&bad).unwrap_err().to_string();
    assert!(e.contains("bad.rhai:2"), "{e}");
}
