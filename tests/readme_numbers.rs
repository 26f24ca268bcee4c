//! The figures README.md and the docs/ pages quote about the bundled examples, rerun: each
//! example is run as the page says, each figure is formatted from the JSON the run wrote (as
//! the page writes it) and must appear on that page. A page whose example has moved on fails
//! here, naming the page and the figure the example now gives. Figures from slow runs
//! (benchmarks, coverage over many seeds, long records) are not rerun here: the page names the
//! command that regenerates them beside them.

mod common;

use std::path::{Path, PathBuf};

use common::{read_json, root, run_json, simulate_ok, stf_lab, succeeded};
use serde_json::Value;

/// A page of the documentation, relative to the project folder.
fn page(name: &str) -> String {
    std::fs::read_to_string(root().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// `text` with every run of white space one space: a quote may wrap across lines.
fn flat(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Asserts that `page` quotes `text` (line breaks aside).
fn quoted(name: &str, text: &str) {
    assert!(
        flat(&page(name)).contains(&flat(text)),
        "{name} no longer quotes `{text}`, which its example gives now: update the page"
    );
}

/// `value ± error` as the terminal and the pages write them (`stf_core::digits::with_error`:
/// `4.08 ± 0.05`, `19 987 ± 11`).
fn pm(value: f64, error: f64) -> String {
    stf_core::digits::with_error(value, error)
}

/// A whole number with its thousands grouped by spaces and a minus sign (`−32 557`).
fn grouped(x: f64) -> String {
    let digits = format!("{}", x.abs().round() as i64);
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(' ');
        }
        out.push(c);
    }
    if x < 0.0 {
        format!("−{out}")
    } else {
        out
    }
}

/// `v` at a `/`-separated path of keys and array indices.
fn at<'a>(v: &'a Value, path: &str) -> &'a Value {
    path.split('/')
        .fold(v, |v, key| match key.parse::<usize>() {
            Ok(i) => &v[i],
            Err(_) => &v[key],
        })
}

fn num(v: &Value, path: &str) -> f64 {
    at(v, path)
        .as_f64()
        .unwrap_or_else(|| panic!("no number at {path}"))
}

/// A fresh output folder for one example.
fn out(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    (dir, path)
}

fn example(file: &str) -> PathBuf {
    root().join("experiments").join(file)
}

/// `stf-lab COMMAND` on the bundled example `file` into a fresh folder: the folder's guard,
/// the folder and its JSON result `result`.
fn example_result(command: &str, file: &str, result: &str) -> (tempfile::TempDir, PathBuf, Value) {
    let (guard, dir) = out(command);
    let value = run_json(command, &example(file), &dir, result);
    (guard, dir, value)
}

#[test]
fn the_first_command_prints_what_the_readme_shows() {
    let (_dir, record) = out("sweep.csv");
    simulate_ok(&example("paper_sweep.toml"), &record);
    let sidecar = read_json(&record.with_extension("json"));
    let s = &sidecar["summary"];
    let peak = format!(
        "peak |x| = {:.2} mm at ω = {:.2} rad/s (t = {:.1} s)",
        num(s, "peak_x_m") * 1e3,
        num(s, "peak_omega_rad_s"),
        num(s, "peak_t_s")
    );
    let breakaway = format!(
        "at ω = {:.2} rad/s (t = {:.1} s)",
        num(s, "breakaway_omega_rad_s"),
        num(s, "breakaway_t_s")
    );
    quoted("README.md", &peak);
    quoted("README.md", &breakaway);
    quoted("experiments/paper_sweep.toml", "alpha = 0.047");
    // The check against the independent implementation quotes the same run to more digits.
    let reference = format!(
        "peak {:.3} mm at {:.3} rad/s",
        num(s, "peak_x_m") * 1e3,
        num(s, "peak_omega_rad_s")
    );
    quoted("docs/accuracy.md", &reference);
    quoted(
        "docs/accuracy.md",
        &format!("breakaway {:.2} rad/s", num(s, "breakaway_omega_rad_s")),
    );
}

#[test]
fn the_fit_walk_through_shows_the_fitted_values() {
    let (_dir, _, fit) = example_result("fit", "power_law_fit.toml", "fit.json");
    let models = fit["models"].as_array().unwrap();
    let pl = models
        .iter()
        .find(|m| m["label"] == "power_law")
        .expect("a power_law fit");
    let k = pm(num(pl, "params/K"), num(pl, "std_errors/K"));
    let n = pm(num(pl, "params/n"), num(pl, "std_errors/n"));
    let line = format!(
        "rms {:.4} N  AIC {:.1}  K = {k} N·(s/m)ⁿ, n = {n}",
        num(pl, "rms"),
        num(pl, "aic")
    );
    quoted("README.md", &line);
    quoted("docs/commands.md", &format!("K = {k} N·(s/m)ⁿ"));
    // The truth the README names for the record.
    let truth = read_json(&root().join("experiments/records/power_law_sweep.json"));
    let text = truth.to_string();
    assert!(
        text.contains("\"K\":4.0") && text.contains("\"n\":1.5"),
        "{text}"
    );
    quoted("README.md", "(the record's truth: K 4, n 1.5)");
}

#[test]
fn the_compare_example_s_regimes_and_z_values_are_the_pages() {
    let (_dir, dir, c) = example_result("compare", "jamming_compare.toml", "compare.json");
    let cycles = &c["measured"]["cycles_per_regime"];
    assert_eq!(
        num(cycles, "post_resonance"),
        0.0,
        "the pages say: no post-resonance"
    );
    assert!(c["measured"]["boundaries"]["resonance_post"].is_null());
    let onset = &c["measured"]["boundaries"]["pre_resonance"];
    let onset = format!(
        "{:.2} ± {:.2} rad/s",
        num(onset, "omega"),
        num(onset, "uncertainty")
    );
    quoted("README.md", &format!("ω {onset}"));
    quoted("docs/compare.md", &format!("pre → resonance at {onset}"));
    for (regime, label) in [
        ("pre_resonance", "pre-resonance"),
        ("resonance", "resonance"),
    ] {
        let ranking: Vec<String> = c["ranking"]["per_regime"][regime]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| format!("`{}` {:.3}", r["model"].as_str().unwrap(), num(r, "score")))
            .collect();
        let n = num(cycles, regime);
        let row = format!("| {label} | {n} | {} |", ranking.join(", "));
        quoted("README.md", &row);
    }
    let overall = &c["ranking"]["overall"][0];
    quoted(
        "README.md",
        &format!(
            "Best over the regimes: `{}` ({:.3})",
            overall["model"].as_str().unwrap(),
            num(overall, "score")
        ),
    );
    // The paired z of the first two of each regime, from the force ranking's test.
    let force = c["loop_rankings"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["metric"] == "force")
        .expect("a force ranking");
    let z = |regime: &str| -> f64 { num(&force["per_regime"][regime], "test/z") };
    let (z_pre, z_res) = (z("pre_resonance"), z("resonance"));
    quoted("README.md", &format!("| {z_pre:.1}: not told apart |"));
    quoted("README.md", &format!("| {z_res:.1} |"));
    quoted(
        "docs/commands.md",
        &format!(
            "over {} pre-resonance cycles, z {z_pre:.1}",
            num(cycles, "pre_resonance")
        ),
    );
    quoted(
        "docs/commands.md",
        &format!(
            "at z {z_res:.1} over {} resonance cycles",
            num(cycles, "resonance")
        ),
    );
    // The warning example of docs/commands.md is this run's `viscous`.
    let viscous = c["models"]
        .as_array()
        .unwrap()
        .iter()
        .find(|m| m["label"] == "viscous")
        .unwrap();
    let fit = &viscous["fit"];
    quoted(
        "docs/commands.md",
        &format!(
            "c_s = {} N·s/m",
            pm(num(fit, "params/c_s"), num(fit, "std_errors/c_s"))
        ),
    );
    let message = fit["warnings"][0]["message"].as_str().unwrap();
    quoted("docs/commands.md", &format!("warning: {message}"));
    // After the amplitude peak the plug rests at zero for less than half of each cycle.
    let duties = resonance_duties_after_peak(&dir.join("cycles.csv"));
    assert!(!duties.is_empty());
    assert!(duties.iter().all(|d| *d > 0.5), "{duties:?}");
    quoted("docs/compare.md", "`duty` stays above 0.5");
}

/// The measured duty of each resonance cycle after the largest amplitude, from `cycles.csv`.
fn resonance_duties_after_peak(cycles: &Path) -> Vec<f64> {
    let mut reader = csv::Reader::from_path(cycles).unwrap();
    let header = reader.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (source, regime, amp, duty) = (
        col("source"),
        col("regime"),
        col("amplitude_m"),
        col("duty"),
    );
    let rows: Vec<(f64, f64)> = reader
        .records()
        .map(Result::unwrap)
        .filter(|r| &r[source] == "measured" && &r[regime] == "resonance")
        .map(|r| (r[amp].parse().unwrap(), r[duty].parse().unwrap()))
        .collect();
    let peak = (0..rows.len())
        .max_by(|&a, &b| rows[a].0.total_cmp(&rows[b].0))
        .unwrap();
    rows[peak + 1..].iter().map(|r| r.1).collect()
}

#[test]
fn the_discovery_examples_name_what_the_pages_say() {
    let (_dir, _, d) = example_result("discover", "discovery.toml", "discovery.json");
    assert_eq!(d["effects"], serde_json::json!(["cubic_stiffness"]));
    let gap = format!(
        "went from {:.4} to {:.4} N against a noise floor of {:.4} N",
        num(&d, "gap_before"),
        num(&d, "gap_after"),
        num(&d, "noise_floor")
    );
    quoted("README.md", &gap);
    let f = &d["final_model"];
    let values = format!(
        "K = {} N·(s/m)ⁿ, n = {}, k3 = {} N/m³",
        pm(num(f, "values/K"), num(f, "std_errors/K")),
        pm(num(f, "values/n"), num(f, "std_errors/n")),
        pm(num(f, "values/k3"), num(f, "std_errors/k3"))
    );
    quoted("README.md", &values);
    let step = &d["steps"][0];
    let best = &step["candidates"][0];
    assert_eq!(best["name"], "cubic_stiffness");
    assert_eq!(step["tie_with"], serde_json::json!(["wall_impact"]));
    let z = format!(
        "paired z {:.1} over {} blocks",
        num(best, "gain_z"),
        num(step, "effective_n")
    );
    quoted("README.md", &z);
    quoted(
        "docs/discovery.md",
        &format!("{z} of {} held-out samples", num(step, "block_samples")),
    );
    quoted(
        "docs/discovery.md",
        &format!("ΔBIC\n{}", grouped(num(best, "delta_bic"))),
    );
    quoted(
        "docs/discovery.md",
        &format!(
            "gap {:.4} N → {:.4} N\nagainst a floor of {:.4} N (sensor {:.4} N, kinematics {:.4} N)",
            num(&d, "gap_before"),
            num(&d, "gap_after"),
            num(&d, "noise_floor"),
            num(&d, "noise_floor_parts/measured"),
            num(&d, "noise_floor_parts/propagated")
        ),
    );

    let (_dir, _, t) = example_result("discover", "trajectory_discovery.toml", "discovery.json");
    assert_eq!(t["effects"], serde_json::json!(["cubic_stiffness"]));
    let s = format!(
        "S(μ) {:.4} → {:.4} mm²",
        num(&t, "s_before_mm2"),
        num(&t, "s_after_mm2")
    );
    quoted("README.md", &s);
    let step = &t["steps"][0];
    let best = &step["candidates"][0];
    let f = &t["final_model"];
    quoted(
        "docs/discovery.md",
        &format!(
            "paired z {:.1} over {} held-out cycles, ΔBIC {}, final\nk3 = {} N/m³",
            num(best, "gain_z"),
            num(step, "effective_n"),
            grouped(num(best, "delta_bic")),
            pm(num(f, "values/k3"), num(f, "std_errors/k3"))
        ),
    );
    quoted(
        "docs/discovery.md",
        &format!(
            "S {:.4} → {:.4} mm²",
            num(&t, "s_before_mm2"),
            num(&t, "s_after_mm2")
        ),
    );
}

#[test]
fn the_identification_example_gives_the_benchmark_page_s_figures() {
    let (_dir, _, id) = example_result("fit", "paper_identification.toml", "fit.json");
    let stages = id["stages"].as_array().unwrap();
    let (s1, s2) = (num(&stages[0], "s_mm2"), num(&stages[1], "s_mm2"));
    let dt = num(&stages[1], "params/delta_T");
    quoted(
        "docs/benchmarks.md",
        &format!("S(μ) {s1:.4} mm²; stage 2 ΔT {dt:.4}"),
    );
    quoted("docs/benchmarks.md", &format!("S(μ) = {s2:.4} mm²"));
}

/// A campaign run into a fresh folder; its `global.json` and `campaign.json`.
fn campaign(file: &str) -> (Value, Value) {
    let (_dir, dir) = out("campaign");
    succeeded(
        stf_lab()
            .args(["campaign", "--quiet", "--jobs", "2", "--out"])
            .arg(&dir)
            .arg(root().join("experiments/campaign").join(file))
            .output()
            .unwrap(),
    );
    (
        read_json(&dir.join("global.json")),
        read_json(&dir.join("campaign.json")),
    )
}

/// `name = value ± error` of a global fit's parameter.
fn global(g: &Value, name: &str) -> String {
    let p = g["params"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("no {name}"));
    format!("{name} = {}", pm(num(p, "value"), num(p, "std_error")))
}

#[test]
fn the_campaign_examples_global_fits_are_the_pages() {
    let (g, table) = campaign("campaign.toml");
    let line = format!(
        "{} (law coefficient), {} (law exponent), {} (shared)",
        global(&g, "K0"),
        global(&g, "K_p"),
        global(&g, "n")
    );
    quoted("README.md", &line);
    let held = &g["holdout"];
    quoted(
        "README.md",
        &format!(
            "(ΔBIC −{:.1}; held-out RMS {:.5} N against {:.5} N",
            -num(&g, "delta_bic"),
            num(held, "global_rms"),
            num(held, "per_record_rms")
        ),
    );
    let docs = format!(
        "{}\n(truth 6), {} (4), {} (1.5);\nΔBIC = −{:.1}; held-out RMS {:.5} N (global) against {:.5} N (per record: the records\nat 0.44; the record's own fit {:.5} N)",
        global(&g, "K_p"),
        global(&g, "K0"),
        global(&g, "n"),
        -num(&g, "delta_bic"),
        num(held, "global_rms"),
        num(held, "per_record_rms"),
        num(held, "own_fit_rms")
    );
    quoted("docs/campaigns.md", &docs);
    // The per-record alternative for the held-out record: the records at 0.44.
    for file in held["per_record_from"].as_array().unwrap() {
        let row = table["rows"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["record"] == *file)
            .unwrap();
        assert_eq!(num(row, "conditions/concentration"), 0.44, "{file}");
    }
    // Every record's K against the truth's law K = 4·(c/0.40)⁶, in its standard errors.
    let worst = table["rows"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["model"] == "power_law")
        .map(|r| {
            let c = num(r, "conditions/concentration");
            let law = 4.0 * (c / 0.40f64).powi(6);
            (num(r, "params/K/value") - law).abs() / num(r, "params/K/std_error")
        })
        .fold(0.0, f64::max);
    quoted(
        "docs/campaigns.md",
        &format!("every record's K lies within {worst:.2}\n  standard errors of the law"),
    );

    let (g, _) = campaign("trajectory_campaign.toml");
    let held = &g["holdout"];
    let docs = format!(
        "{}\n  (truth 6), {} (4), {} (1.5); ΔBIC = −{:.1}; held-out\n  RMS {:.5} mm (global) against {:.4} mm (per record), its own fit {:.5} mm",
        global(&g, "K_p"),
        global(&g, "K0"),
        global(&g, "n"),
        -num(&g, "delta_bic"),
        num(held, "global_rms"),
        num(held, "per_record_rms"),
        num(held, "own_fit_rms")
    );
    assert_eq!(
        g["rms_unit"], "mm",
        "the page quotes the trajectory level's RMS in mm"
    );
    quoted("docs/campaigns.md", &docs);
    let joint = &g["global"];
    quoted(
        "docs/campaigns.md",
        &format!(
            "The joint fit ({} parameters, {} samples, {} evaluations)",
            num(joint, "n_params"),
            grouped(num(joint, "n_points")).replace('−', "-"),
            num(&g, "joint_fit_evaluations")
        ),
    );
}
