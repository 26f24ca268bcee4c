//! End-to-end tests of `stf-lab fit` on the bundled examples.

mod common;

use common::{read_json, root, run, run_ok};

#[test]
fn power_law_example_recovers_the_truth_natively_and_as_a_script() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("fit");
    let _ = run_ok("fit", &root().join("experiments/power_law_fit.toml"), &dir);
    let fit: serde_json::Value = read_json(&dir.join("fit.json"));
    let models = fit["models"].as_array().unwrap();
    assert_eq!(models.len(), 4);
    let power = &models[1];
    assert_eq!(power["name"], "power_law");
    let k = power["params"]["K"].as_f64().unwrap();
    let n = power["params"]["n"].as_f64().unwrap();
    assert!((k / 4.0 - 1.0).abs() < 0.02, "K = {k}");
    assert!((n / 1.5 - 1.0).abs() < 0.02, "n = {n}");
    assert!(power["rms"].as_f64().unwrap() < 0.021);
    // The viscous model fits worse than the truth.
    assert!(models[0]["rms"].as_f64().unwrap() > power["rms"].as_f64().unwrap());
    // The script twin recovers the same values.
    let script = &models[3];
    let ks = script["params"]["K"].as_f64().unwrap();
    assert!((ks / k - 1.0).abs() < 1e-6, "script K = {ks}, native {k}");
    // The CSV has the measured force and one column per model.
    let csv = std::fs::read_to_string(dir.join("fitted.csv")).unwrap();
    assert!(csv
        .lines()
        .next()
        .unwrap()
        .starts_with("t,f_stf,f_stf_viscous"));

    // A second run into the same folder refuses without --force.
    let again = run("fit", &root().join("experiments/power_law_fit.toml"), &dir);
    assert!(!again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("--force"));
}

#[test]
fn paper_identification_finds_k_and_f0() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("id");
    let _ = run_ok(
        "fit",
        &root().join("experiments/paper_identification.toml"),
        &dir,
    );
    let fit: serde_json::Value = read_json(&dir.join("fit.json"));
    let system = &fit["system"];
    let k = system["k"].as_f64().unwrap();
    let f0 = system["F0"].as_f64().unwrap();
    assert!((k / 269.9346 - 1.0).abs() < 0.005, "k = {k}");
    assert!((f0 / 0.0462 - 1.0).abs() < 0.005, "F0 = {f0}");
    assert_eq!(fit["stages"].as_array().unwrap().len(), 2);
    // Stage 2 starts from the free-vibration values (c 17 % high, T 22 % low), from where the
    // refinement drives ΔT onto its bound; released, it reaches the optimum: S no worse than
    // at the truth (the forced preset, with only F0 refitted), and c, T, ΔT near the truth.
    let s_fit = fit["stages"][1]["s_mm2"].as_f64().unwrap();
    let truth = out.path().join("truth.toml");
    let record = root().join("experiments/records/forced_sweep.csv");
    std::fs::write(
        &truth,
        format!(
            "[system]\npreset = \"forced\"\n\n[[identify]]\ndata = {:?}\nfree = [\"F0\"]\n",
            record.display().to_string()
        ),
    )
    .unwrap();
    let _ = run_ok("fit", &truth, &out.path().join("truth"));
    let at_truth: serde_json::Value = read_json(&out.path().join("truth/fit.json"));
    let s_truth = at_truth["stages"][0]["s_mm2"].as_f64().unwrap();
    assert!(
        s_fit <= 1.01 * s_truth,
        "S {s_fit} mm² against {s_truth} at the truth"
    );
    let near = |name: &str, truth: f64, within: f64| {
        let v = system[name].as_f64().unwrap();
        assert!(
            (v / truth - 1.0).abs() < within,
            "{name} = {v}, truth {truth}"
        );
    };
    near("c", 3.6839, 0.01);
    near("T", 0.5424, 0.01);
    near("delta_T", 0.0947, 0.03);
    // Stage 1 against the free-vibration truth the bundled record was made with.
    let stage1 = &fit["stages"][0]["params"];
    for (name, truth) in [("k", 267.9245), ("c", 4.3736), ("T", 0.4190)] {
        let v = stage1[name].as_f64().unwrap();
        assert!(
            (v / truth - 1.0).abs() < 0.03,
            "stage 1 {name} = {v}, truth {truth}"
        );
    }
}

#[test]
fn the_same_experiment_gives_byte_identical_results() {
    let out = tempfile::tempdir().unwrap();
    let mut outputs = Vec::new();
    for name in ["a", "b"] {
        let dir = out.path().join(name);
        let _ = run_ok("fit", &root().join("experiments/power_law_fit.toml"), &dir);
        outputs.push((
            std::fs::read(dir.join("fit.json")).unwrap(),
            std::fs::read(dir.join("fitted.csv")).unwrap(),
        ));
    }
    assert!(outputs[0] == outputs[1], "two runs differ");
}

#[test]
fn output_report_false_writes_only_the_results() {
    let out = tempfile::tempdir().unwrap();
    let record = root().join("experiments/records/power_law_sweep.csv");
    let exp = out.path().join("exp.toml");
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = {:?}\n\n[output]\nreport = false\n\n[[models]]\nname = \"viscous\"\n",
            record.display().to_string()
        ),
    )
    .unwrap();
    let dir = out.path().join("fit");
    let _ = run_ok("fit", &exp, &dir);
    assert!(dir.join("fit.json").exists() && dir.join("fitted.csv").exists());
    assert!(!dir.join("report.html").exists() && !dir.join("figures").exists());
}

/// Write `experiment` (with `[simulate]`) into `dir`, simulate its record `record`, fit it with
/// `stf-lab fit` and return fit.json and the terminal output.
fn simulate_and_fit(
    dir: &std::path::Path,
    name: &str,
    experiment: &str,
) -> (serde_json::Value, String) {
    let exp = dir.join(format!("{name}.toml"));
    std::fs::write(&exp, experiment).unwrap();
    common::simulate_ok(&exp, &dir.join(format!("{name}.csv")));
    let out = dir.join(format!("{name}_fit"));
    let output = run_ok("fit", &exp, &out);
    (
        read_json(&out.join("fit.json")),
        String::from_utf8_lossy(&output.stdout).into_owned(),
    )
}

/// The kinds of a model's warnings in fit.json; every warning has a message.
fn warning_kinds(model: &serde_json::Value) -> Vec<String> {
    model["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| {
            assert!(!w["message"].as_str().unwrap().is_empty(), "{w}");
            w["kind"].as_str().unwrap().to_string()
        })
        .collect()
}

/// A short sweep through resonance with sensor noise; the STF force is `truth`.
fn record_of(truth: &str, models: &str) -> String {
    format!(
        "[data]\nfile = \"{{name}}.csv\"\n\n[simulate]\n\
         sweep = {{ w0 = 4.0, alpha = 0.2, t0 = 0.0, t1 = 20.0 }}\nrate = 200.0\nnoise = true\n\
         seed = 11\n\n[[simulate.truth]]\n{truth}\n\n{models}"
    )
}

#[test]
fn a_fit_that_misses_an_effect_or_sits_on_a_bound_warns() {
    let dir = tempfile::tempdir().unwrap();
    // Strong thickening (n = 2.5): a viscous model misses it; a power law whose n may not
    // exceed 1.5 ends on that bound; the true model does neither.
    let exp = record_of(
        "name = \"power_law\"\nparams = { K = 20.0, n = 2.5 }",
        "[[models]]\nname = \"viscous\"\n\n[[models]]\nname = \"power_law\"\n\
         params = { K = 5.0, n = { value = 1.2, min = 1.0, max = 1.5 } }\n\n\
         [[models]]\nname = \"power_law\"\n",
    )
    .replace("{name}", "thick");
    let (fit, stdout) = simulate_and_fit(dir.path(), "thick", &exp);
    let models = fit["models"].as_array().unwrap();
    let viscous = &models[0];
    assert!(warning_kinds(viscous).contains(&"above_noise_floor".to_string()));
    let w = &viscous["warnings"][0];
    let floor = viscous["noise_floor"]["sigma"].as_f64().unwrap();
    assert!((w["ratio"].as_f64().unwrap() - viscous["rms"].as_f64().unwrap() / floor).abs() < 1e-9);
    assert!(w["message"].as_str().unwrap().contains("stf-lab discover"));
    // The floor is the sensor's noise (σ 0.02 N) with a little derivative noise.
    assert!(floor > 0.019 && floor < 0.025, "floor {floor}");

    let capped = &models[1];
    let on_bound: Vec<&serde_json::Value> = capped["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|w| w["kind"] == "on_bound")
        .collect();
    assert_eq!(on_bound.len(), 1, "{}", capped["warnings"]);
    assert_eq!(on_bound[0]["param"], "n");
    assert_eq!(on_bound[0]["side"], "upper");
    assert!(on_bound[0]["message"]
        .as_str()
        .unwrap()
        .contains("widen the bound of n or fix it"));

    let truth = warning_kinds(&models[2]);
    for kind in [
        "above_noise_floor",
        "on_bound",
        "undetermined",
        "not_converged",
    ] {
        assert!(
            !truth.contains(&kind.to_string()),
            "the true model: {truth:?}"
        );
    }
    // Existing keys stay; the terminal prints the warnings under the model's line.
    assert!(capped["params"]["n"].is_number() && capped["rms"].is_number());
    assert_eq!(capped["name"], "power_law");
    let lines: Vec<&str> = stdout.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.trim_start().starts_with("viscous"))
        .unwrap();
    assert!(
        lines[at + 1].contains("warning: the residual is"),
        "{stdout}"
    );
}

#[test]
fn the_true_model_on_its_own_record_draws_no_warning_and_a_cut_fit_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let exp = record_of(
        "name = \"viscous\"\nparams = { c_s = 3.0 }",
        "[[models]]\nname = \"viscous\"\n",
    )
    .replace("{name}", "visc");
    let (fit, stdout) = simulate_and_fit(dir.path(), "visc", &exp);
    let model = &fit["models"][0];
    assert_eq!(
        warning_kinds(model),
        Vec::<String>::new(),
        "{}",
        model["warnings"]
    );
    assert!(!stdout.contains("warning:"), "{stdout}");

    // The same fit stopped after one iteration says it did not converge.
    let cut = exp.replace("[[models]]", "[fit]\nmax_iters = 1\n\n[[models]]");
    let (fit, stdout) = simulate_and_fit(
        dir.path(),
        "visc_cut",
        &cut.replace("visc.csv", "visc_cut.csv"),
    );
    let kinds = warning_kinds(&fit["models"][0]);
    assert_eq!(
        kinds.first().map(String::as_str),
        Some("not_converged"),
        "{kinds:?}"
    );
    assert!(
        stdout.contains("warning: the fit ran out of iterations"),
        "{stdout}"
    );
}
