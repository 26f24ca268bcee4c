//! End-to-end test of `stf-lab discover` on the bundled example.

mod common;

use common::{read_json, root, run_ok};

#[test]
fn discovery_names_the_hidden_cubic_spring_and_the_gap_shrinks_to_the_noise() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("disc");
    let _ = run_ok("discover", &root().join("experiments/discovery.toml"), &dir);
    let doc = read_json(&dir.join("discovery.json"));
    assert_eq!(doc["effects"], serde_json::json!(["cubic_stiffness"]));
    let before = doc["gap_before"].as_f64().unwrap();
    let after = doc["gap_after"].as_f64().unwrap();
    let floor = doc["noise_floor"].as_f64().unwrap();
    assert!(after < before / 3.0, "gap {before} → {after}");
    assert!(after <= 1.2 * floor, "gap after {after}, floor {floor}");
    // The floor's parts, and every step's evidence with its effective sample size: blocks of
    // held-out samples, far fewer than the samples.
    let parts = &doc["noise_floor_parts"];
    let (measured, propagated) = (
        parts["measured"].as_f64().unwrap(),
        parts["propagated"].as_f64().unwrap(),
    );
    assert!(measured > 0.0 && propagated > 0.0, "{parts}");
    assert!(
        (measured.hypot(propagated) - floor).abs() < 1e-12,
        "{parts}"
    );
    let held_out = doc["holdout_cycles"].as_u64().unwrap();
    for step in doc["steps"].as_array().unwrap() {
        let blocks = step["effective_n"].as_u64().unwrap();
        let length = step["block_samples"].as_u64().unwrap();
        assert!(
            blocks >= held_out && length >= 10,
            "{blocks} blocks of {length}"
        );
        assert!(step["floor"]["sigma"].as_f64().unwrap() > 0.0, "{step}");
        for c in step["candidates"].as_array().unwrap() {
            assert!(
                c["explained_share"].is_number() || c["failure"].is_string(),
                "{c}"
            );
        }
    }
    let k3 = doc["final_model"]["params"]["k3"].as_f64().unwrap();
    assert!((k3 / 2e4 - 1.0).abs() < 0.05, "k3 = {k3}");
    // The final model is an experiment entry that `fit` accepts as it is.
    let entry = doc["final_model"]["experiment_entry"].as_str().unwrap();
    assert!(entry.contains("plus = [\"cubic_stiffness\"]"), "{entry}");
    assert!(dir.join("report.html").exists());

    let record = root().join("experiments/records/discovery_sweep.csv");
    let exp = out.path().join("refit.toml");
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = {:?}\n\n{entry}",
            record.display().to_string()
        ),
    )
    .unwrap();
    let _ = run_ok("fit", &exp, &out.path().join("refit"));
}

/// The bundled discovery record for estimation, and a validation record of the same truth
/// (power law K 4, n 1.5 and a cubic spring k3 2e4) on another sweep (ω 3.5 → 9.5 rad/s over
/// 40 s) with another noise seed, made by `stf-lab simulate`; the experiment discovers from
/// the power law with `[validate]`.
fn validated_discovery(dir: &std::path::Path) -> std::path::PathBuf {
    let sim = dir.join("validation.toml");
    std::fs::write(
        &sim,
        "[simulate]\nsweep = { w0 = 3.5, alpha = 0.15, t0 = 0.0, t1 = 40.0 }\nrate = 200.0\n\
         seed = 12\n\n[[simulate.truth]]\nname = \"power_law\"\nplus = [\"cubic_stiffness\"]\n\
         params = { K = 4.0, n = 1.5, k3 = 2e4 }\n",
    )
    .unwrap();
    common::simulate_ok(&sim, &dir.join("validation.csv"));
    let exp = dir.join("exp.toml");
    let record = root().join("experiments/records/discovery_sweep.csv");
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = {:?}\n\n[validate]\nfile = \"validation.csv\"\n\n\
             [discover]\nbase = \"power_law\"\n",
            record.display().to_string()
        ),
    )
    .unwrap();
    exp
}

#[test]
fn discovery_is_validated_on_a_second_record_and_its_json_redraws_its_curves() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = validated_discovery(tmp.path());
    let out = tmp.path().join("disc");
    let stdout = String::from_utf8_lossy(&run_ok("discover", &exp, &out).stdout).into_owned();
    let doc = read_json(&out.join("discovery.json"));
    assert_eq!(doc["effects"], serde_json::json!(["cubic_stiffness"]));
    let v = &doc["validation"];
    assert_eq!(v["file"], "validation.csv");
    let (before, after) = (
        v["rms_before"].as_f64().unwrap(),
        v["rms_after"].as_f64().unwrap(),
    );
    // The final model predicts the other record to the force sensor's noise (σ 0.02 N); the
    // base misses the spring there too.
    let floor = doc["noise_floor"].as_f64().unwrap();
    eprintln!("validation RMS {before} → {after} N, floor {floor} N");
    assert!(after < 1.15 * floor, "{after} against a floor of {floor}");
    assert!(before > 4.0 * after, "{before} → {after}");
    assert!(stdout.contains("held out: 14 cycles of the record; validation on validation.csv"));
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("validation on validation.csv (8001 samples)"));

    // The fitted values alone, with the record's kinematics read as the experiment reads
    // them, predict the curves discovered.csv holds.
    let mut experiment = stf_lab::experiment::Experiment::load(&exp).unwrap();
    let data = stf_lab::fitting::load_data(&mut experiment).unwrap();
    let csv = out.join("discovered.csv");
    for (which, column) in [("base", "f_stf_base"), ("final", "f_stf_final")] {
        let entry = &doc["fitted"][which];
        let (model, mut values) = common::fitted_model(entry);
        let mut fit = stf_core::fit::ForceFit::new(model);
        if let Some(off) = entry["offset"]["value"].as_f64() {
            fit = fit.offset(stf_core::fit::FitParam::new("f_off", off));
            values.push(off);
        }
        let redrawn = fit.predict(&data.force_data(), &values).unwrap();
        let written = common::csv_column(&csv, column);
        let diff = common::max_difference(&redrawn, &written);
        assert!(diff < 1e-12, "{which}: redrawn differs by {diff} N");
    }
    let entry = &doc["fitted"]["final"];
    assert_eq!(entry["name"], "power_law + cubic_stiffness");
    assert_eq!(entry["params"]["k3"], doc["final_model"]["params"]["k3"]);
}

/// Script effects are printed by their paths: a discovery from the bundled power-law script
/// with a cubic spring written as a script among the candidates names the spring, and the
/// entry it prints (on the terminal and in `discovery.json`) names both scripts by the paths
/// the experiment gave; pasted as it is into an experiment beside it, that entry fits. (It
/// printed the spring by its name, `plus = ["stiff"]`: "unknown model `stiff`".)
#[test]
fn a_script_effect_is_printed_by_its_path_and_the_entry_pasted_back_fits() {
    let out = tempfile::tempdir().unwrap();
    let scripts = out.path().join("scripts");
    std::fs::create_dir(&scripts).unwrap();
    std::fs::copy(
        root().join("models/scripts/power_law.rhai"),
        scripts.join("power_law.rhai"),
    )
    .unwrap();
    std::fs::write(
        scripts.join("stiff.rhai"),
        "fn params() {\n    #{ k3: [1e4, 0.0, 1e7, \"N/m^3\"] }\n}\n\n\
         fn force(p, t, x, v, z) {\n    p.k3 * x * x * x\n}\n",
    )
    .unwrap();
    let record = root().join("experiments/records/discovery_sweep.csv");
    let data = format!("[data]\nfile = {:?}\n\n", record.display().to_string());
    let exp = out.path().join("discover.toml");
    std::fs::write(
        &exp,
        format!(
            "{data}[discover]\nbase = \"scripts/power_law.rhai\"\n\
             candidates = [\"viscous\", \"scripts/stiff.rhai\"]\n"
        ),
    )
    .unwrap();
    let dir = out.path().join("disc");
    let printed = run_ok("discover", &exp, &dir);
    let doc = read_json(&dir.join("discovery.json"));
    assert_eq!(doc["effects"], serde_json::json!(["stiff"]), "{doc}");
    let entry = doc["final_model"]["experiment_entry"].as_str().unwrap();
    assert!(
        entry.contains("name = \"scripts/power_law.rhai\"")
            && entry.contains("plus = [\"scripts/stiff.rhai\"]"),
        "{entry}"
    );
    let stdout = String::from_utf8_lossy(&printed.stdout);
    let shown = stdout
        .split("final model, as an experiment entry:\n")
        .nth(1)
        .unwrap_or_else(|| panic!("no entry printed: {stdout}"));
    assert!(shown.starts_with(entry), "{shown}");
    let refit = out.path().join("refit.toml");
    std::fs::write(&refit, format!("{data}{}", &shown[..entry.len()])).unwrap();
    let _ = run_ok("fit", &refit, &out.path().join("refit"));
    let fitted = read_json(&out.path().join("refit/fit.json"));
    let k3 = fitted["models"][0]["params"]["k3"].as_f64().unwrap();
    assert!((k3 / 2e4 - 1.0).abs() < 0.05, "k3 = {k3}");
}
