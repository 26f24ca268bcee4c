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
    near("delta_T", 0.0947, 0.1);
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
