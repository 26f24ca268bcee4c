//! The compiled fast path against rhai's VM: same bits, same errors, and scripts outside the
//! subset declining to the VM.

use std::path::Path;

use proptest::prelude::*;
use stf_core::physics::force_model::{ForceModel, ModelState};
use stf_plugins::ScriptModel;

/// Both paths of one script: (compiled, VM only).
fn both(name: &str, source: &str) -> (ScriptModel, ScriptModel) {
    let compiled = ScriptModel::from_source(name, source).unwrap();
    let vm = ScriptModel::from_source(name, source).unwrap().vm_only();
    (compiled, vm)
}

/// force (and rates) of both paths at one state: identical bits, or identical errors.
fn assert_same(c: &ScriptModel, vm: &ScriptModel, p: &[f64], t: f64, x: f64, v: f64, z: &[f64]) {
    let s = ModelState { t, x, v, z };
    let n = c.n_internal();
    let (mut dz_c, mut dz_vm) = (vec![0.0; n], vec![0.0; n]);
    let fc = c.force(p, &s, &mut dz_c).map_err(|e| e.to_string());
    let fv = vm.force(p, &s, &mut dz_vm).map_err(|e| e.to_string());
    match (&fc, &fv) {
        (Ok(a), Ok(b)) => {
            assert_eq!(a.to_bits(), b.to_bits(), "force at {s:?}: {a} vs {b}");
            for (a, b) in dz_c.iter().zip(&dz_vm) {
                assert_eq!(a.to_bits(), b.to_bits(), "rates at {s:?}: {a} vs {b}");
            }
        }
        _ => assert_eq!(fc, fv, "at {s:?}"),
    }
    let mc = c.added_mass(p, &s).map_err(|e| e.to_string());
    let mv = vm.added_mass(p, &s).map_err(|e| e.to_string());
    match (&mc, &mv) {
        (Ok(a), Ok(b)) => assert_eq!(a.to_bits(), b.to_bits()),
        _ => assert_eq!(mc, mv),
    }
}

const STATES: [f64; 9] = [0.0, -0.0, 1e-7, -1e-7, 0.3, -0.3, 2.5, -17.0, 1e6];

#[test]
fn bundled_scripts_compile_and_match_the_vm_bit_for_bit() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/scripts");
    for name in ["power_law.rhai", "structure_thickening.rhai"] {
        let source = std::fs::read_to_string(dir.join(name)).unwrap();
        let (c, vm) = both(name, &source);
        assert!(c.is_compiled(), "{name} is inside the subset");
        assert!(!vm.is_compiled());
        let p: Vec<f64> = c.params().iter().map(|s| s.default).collect();
        let z_len = c.n_internal();
        for &v in &STATES {
            for &zv in &STATES {
                let z = vec![zv; z_len];
                assert_same(&c, &vm, &p, 1.0, 0.01, v, &z);
            }
        }
    }
}

#[test]
fn integer_arithmetic_and_errors_follow_rhai() {
    let params = "fn params() { #{ c: [1.0, 0.0, 10.0, \"\"] } }\n";
    let bodies = [
        // 2/3 is the integer 0; mixing promotes to float.
        "2 / 3 + v * (7 % 4) - 1 ** 2",
        // integer division by zero where v = 0 (sign is an integer).
        "if t > 0.5 { 10 / v.sign() } else { 0 }",
        "let k = v.sign(); if t > 0.5 { 10 % k } else { k }",
        // integer overflow, negative integer power
        "let big = 9223372036854775807; if v > 0.0 { big + v.sign() } else { 0 }",
        "if t > 0.5 { 2 ** v.sign() } else { 0 }",
        // sign of NaN, a float function on an integer, a bool in arithmetic
        "if t > 0.5 { (v / v).sign() } else { 0 }",
        "if t > 0.5 { v.sign().sqrt() } else { 0 }",
        "if t > 0.5 { (v > 0.0) + 1 } else { 0 }",
        // comparisons with rhai's relative epsilon, && || !
        "if v == 0.3 && !(t != 1.0) || x >= 0.01 { 1.5 } else { -2 }",
        "if v < 1e-7 { v.max(2) } else { min(3, v) }",
        // returns and nested blocks
        "let a = v * 2.0; if a > 0.0 { return a.exp(); } { let a = 3; a * x }",
        // a non-number result is the VM's error
        "if v > 0.0 && t > 0.5 { true } else { 1.0 }",
        "if v > 0.0 || t < 0.5 { 1.0 }",
        "p.c.abs().sqrt() * v.abs().ln() + PI() + t.to_int() + x.floor() + hypot(v, t)",
    ];
    for body in bodies {
        let src = format!("{params}fn force(p, t, x, v, z) {{ {body} }}");
        let (c, vm) = both("ints", &src);
        assert!(c.is_compiled(), "{body} is inside the subset");
        for &v in &STATES {
            assert_same(&c, &vm, &[2.0], 1.0, 0.01, v, &[]);
        }
    }
}

#[test]
fn rates_arrays_and_added_mass_take_the_compiled_path() {
    let src = "fn params() { #{ a: [1.0, 0.0, 10.0, \"\"], b: [2.0, 0.0, 10.0, \"\"] } }\n\
               fn n_internal() { 2 }\n\
               fn force(p, t, x, v, z) { p.a * z[0] - z[-1] * v }\n\
               fn rates(p, t, x, v, z) { if v > 0.0 { [v - z[0], 1] } else { return [0, z[1] / p.b]; } }\n\
               fn added_mass(p, t, x, v, z) { p.b * 0.5 }";
    let (c, vm) = both("rates", src);
    assert!(c.is_compiled());
    for &v in &STATES {
        assert_same(&c, &vm, &[1.0, 3.0], 0.0, 0.0, v, &[0.25, -4.0]);
    }
    // A rates array of the wrong length is the VM's error on both paths.
    let bad = src.replace("[v - z[0], 1]", "[v]");
    let (c, vm) = both("rates", &bad);
    assert!(c.is_compiled());
    assert_same(&c, &vm, &[1.0, 3.0], 0.0, 0.0, 1.0, &[0.25, -4.0]);
}

#[test]
fn scripts_outside_the_subset_decline_and_run_on_the_vm() {
    let params = "fn params() { #{ c: [1.0, 0.0, 10.0, \"\"] } }\n";
    let outside = [
        "fn force(p, t, x, v, z) { let s = 0.0; for i in 0..3 { s = s + v; } s }",
        "fn twice(a) { a * 2.0 }\nfn force(p, t, x, v, z) { twice(v) * p.c }",
        "fn force(p, t, x, v, z) { let s = \"soft\"; if s.len() > 2 { v } else { 0.0 } }",
        "fn force(p, t, x, v, z) { let a = 1.0; a += v; a }",
        "fn force(p, t, x, v, z) { let m = p; m.c * v }",
    ];
    for rest in outside {
        let src = format!("{params}{rest}");
        let (c, vm) = both("outside", &src);
        assert!(!c.is_compiled(), "{rest} declines");
        for &v in &STATES {
            assert_same(&c, &vm, &[2.0], 0.0, 0.0, v, &[]);
        }
        let s = ModelState {
            t: 0.0,
            x: 0.0,
            v: 1.5,
            z: &[],
        };
        assert!(c.force(&[2.0], &s, &mut []).is_ok(), "{rest} still runs");
    }
}

/// A random expression of the subset, as rhai source, over p.a, p.b, t, x, v, z[0], z[1].
fn expr() -> impl Strategy<Value = String> {
    let leaf = prop_oneof![
        (-3i64..4).prop_map(|i| format!("{i}")),
        prop_oneof![Just(0.0), Just(0.5), Just(-1.25), Just(1e-9), Just(3.0)]
            .prop_map(|f: f64| format!("{f:?}")),
        prop_oneof![
            Just("t"),
            Just("x"),
            Just("v"),
            Just("p.a"),
            Just("p.b"),
            Just("z[0]"),
            Just("z[1]")
        ]
        .prop_map(String::from),
    ];
    leaf.prop_recursive(3, 16, 3, |inner| {
        let op = prop_oneof![
            Just("+"),
            Just("-"),
            Just("*"),
            Just("/"),
            Just("%"),
            Just("**")
        ];
        let cmp = prop_oneof![
            Just("<"),
            Just("<="),
            Just(">"),
            Just(">="),
            Just("=="),
            Just("!=")
        ];
        let f1 = prop_oneof![
            Just("abs"),
            Just("sign"),
            Just("sqrt"),
            Just("exp"),
            Just("ln"),
            Just("sin"),
            Just("tanh"),
            Just("floor"),
            Just("round"),
            Just("to_float"),
            Just("to_int")
        ];
        let f2 = prop_oneof![Just("min"), Just("max"), Just("atan"), Just("hypot")];
        prop_oneof![
            (inner.clone(), op, inner.clone()).prop_map(|(a, o, b)| format!("({a} {o} {b})")),
            inner.clone().prop_map(|a| format!("(-({a}))")),
            (inner.clone(), f1).prop_map(|(a, f)| format!("{a}.{f}()")),
            (f2, inner.clone(), inner.clone()).prop_map(|(f, a, b)| format!("{f}({a}, {b})")),
            (
                inner.clone(),
                cmp,
                inner.clone(),
                inner.clone(),
                inner.clone()
            )
                .prop_map(|(a, c, b, y, n)| format!("(if {a} {c} {b} {{ {y} }} else {{ {n} }})")),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("{{ let w = {a}; w * {b} }}")),
        ]
    })
}

fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(-0.0),
        Just(1.0),
        Just(2.0),
        Just(-3.0),
        -10.0..10.0,
        -1e-3..1e-3
    ]
}

/// True at the state of the load-time check (t = 0, v = 0), so that most random scripts load
/// and their errors show in the calls compared below.
const AT_LOAD: &str = "t == 0.0 && v == 0.0";

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    #[test]
    fn random_scripts_give_the_vm_bits_or_its_errors(
        body in expr(),
        states in prop::collection::vec((number(), number(), number(), number(), number(), number(), number()), 8),
    ) {
        let src = format!(
            "fn params() {{ #{{ a: [1.0, -100.0, 100.0, \"\"], b: [2.0, -100.0, 100.0, \"\"] }} }}\n\
             fn n_internal() {{ 2 }}\n\
             fn force(p, t, x, v, z) {{ if {AT_LOAD} {{ 0.0 }} else {{ {body} }} }}\n\
             fn rates(p, t, x, v, z) {{ if {AT_LOAD} {{ [0, 0] }} else {{ [{body}, v] }} }}"
        );
        // A script that fails its load-time check fails on both paths alike.
        let c = ScriptModel::from_source("random", &src).map_err(|e| e.to_string());
        let vm = ScriptModel::from_source("random", &src).map(ScriptModel::vm_only).map_err(|e| e.to_string());
        match (c, vm) {
            (Ok(c), Ok(vm)) => {
                prop_assert!(c.is_compiled(), "{} declined", body);
                for (a, b, t, x, v, z0, z1) in states {
                    assert_same(&c, &vm, &[a, b], t, x, v, &[z0, z1]);
                }
            }
            (c, vm) => prop_assert_eq!(c.err(), vm.err()),
        }
    }
}
