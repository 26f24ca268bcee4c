//! Trajectory-level discovery with the hysteretic element and the linear spring in its
//! vocabulary, on records made by `simulate` with the rig's sensors: a Bouc–Wen loop hidden
//! beside the base is named `bouc_wen` with its parameters within 5 %; a linear spring is not
//! tried while the oscillator's `k` is refitted (the two are the same term), a note says so,
//! and the refitted k carries the spring.

mod common;

use std::path::Path;

use common::{read_json, run_ok, simulate_ok};

/// Simulate a 200 Hz sweep through resonance (seed `seed`) hiding `truth`, then discover from
/// `base` at trajectory level; discovery.json.
fn discover(dir: &Path, seed: u64, truth: &str, base: &str) -> serde_json::Value {
    let exp = dir.join(format!("d{seed}.toml"));
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = \"r{seed}.csv\"\n\n[fit]\nlevel = \"trajectory\"\n\n[simulate]\n\
             sweep = {{ w0 = 4.0, alpha = 0.2, t0 = 0.0, t1 = 20.0 }}\nrate = 200.0\n\
             noise = true\nseed = {seed}\n\n{truth}\n\n[discover]\nbase = \"{base}\"\n"
        ),
    )
    .unwrap();
    simulate_ok(&exp, &dir.join(format!("r{seed}.csv")));
    let out = dir.join(format!("o{seed}"));
    run_ok("discover", &exp, &out);
    read_json(&out.join("discovery.json"))
}

#[test]
fn a_hidden_bouc_wen_loop_is_named_at_trajectory_level() {
    let dir = tempfile::tempdir().unwrap();
    let d = discover(
        dir.path(),
        1,
        "[[simulate.truth]]\nname = \"bouc_wen\"\nparams = { F_bw = 1.0, x_bw = 3e-3, beta = 0.7 }",
        "viscous",
    );
    assert_eq!(
        d["effects"],
        serde_json::json!(["bouc_wen"]),
        "{}",
        d["notes"]
    );
    for (name, truth) in [("F_bw", 1.0), ("x_bw", 3e-3), ("beta", 0.7)] {
        let got = d["final_model"]["params"][name]
            .as_f64()
            .unwrap_or_else(|| {
                panic!("no {name} in {}", d["final_model"]);
            });
        assert!((got - truth).abs() < 0.05 * truth, "{name} = {got}");
    }
}

#[test]
fn a_linear_spring_is_not_tried_while_k_is_refitted_and_k_carries_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = discover(
        dir.path(),
        7,
        "[[simulate.truth]]\nname = \"power_law\"\nparams = { K = 20.0, n = 1.5 }\n\n\
         [[simulate.truth]]\nname = \"linear_spring\"\nparams = { k_s = 30.0 }",
        "power_law",
    );
    assert_eq!(d["effects"], serde_json::json!([]), "{}", d["notes"]);
    let notes = d["notes"].to_string();
    assert!(
        notes.contains("`linear_spring` not tried: its `k_s` is the same term"),
        "{notes}"
    );
    // The rig's k (269.93 N/m) plus the hidden spring.
    let k = d["system"]["k"].as_f64().unwrap();
    assert!((k - 299.93).abs() < 0.02 * 299.93, "k = {k}");
}
