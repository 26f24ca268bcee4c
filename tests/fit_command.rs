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
    // Under the model's line: its force as an equation, then its warnings.
    assert!(
        lines[at + 1].trim_start().starts_with("F_STF = "),
        "{stdout}"
    );
    assert!(
        lines[at + 2].contains("warning: the residual is"),
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
    // No warning line under the model (the verdict above says it "carries no warning").
    assert!(
        !stdout
            .lines()
            .any(|l| l.trim_start().starts_with("warning:")),
        "{stdout}"
    );

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

/// Write `NAME.toml` simulating a sweep `sweep` (w0, alpha, t1) at 200 Hz with the rig's
/// sensors and seed `seed` through a power law K 150, n 2.5, and its record `NAME.csv`.
fn sweep_record(dir: &std::path::Path, name: &str, (w0, alpha, t1): (f64, f64, f64), seed: u64) {
    let exp = dir.join(format!("{name}.toml"));
    std::fs::write(
        &exp,
        format!(
            "[simulate]\nsweep = {{ w0 = {w0:?}, alpha = {alpha:?}, t0 = 0.0, t1 = {t1:?} }}\n\
             rate = 200.0\nseed = {seed}\n\n[[simulate.truth]]\nname = \"power_law\"\n\
             params = {{ K = 150.0, n = 2.5 }}\n"
        ),
    )
    .unwrap();
    common::simulate_ok(&exp, &dir.join(format!("{name}.csv")));
}

/// An estimation record (ω 4 → 8 rad/s over 20 s, seed 11) and a validation record of another
/// sweep (ω 3 → 9.3 rad/s over 18 s, seed 12) of the same truth, and the experiment fitting a
/// viscous model (wrong) and a power law (the truth) at `level` with `[validate]`.
fn validation_experiment(dir: &std::path::Path, level: &str) -> std::path::PathBuf {
    sweep_record(dir, "estimation", (4.0, 0.2, 20.0), 11);
    sweep_record(dir, "validation", (3.0, 0.35, 18.0), 12);
    let exp = dir.join(format!("fit_{level}.toml"));
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = \"estimation.csv\"\n\n[fit]\nlevel = \"{level}\"\n\n\
             [validate]\nfile = \"validation.csv\"\n\n[[models]]\nname = \"viscous\"\n\n\
             [[models]]\nname = \"power_law\"\n"
        ),
    )
    .unwrap();
    exp
}

/// The validation RMS of a model in fit.json, checked against its `validation` object.
fn validation_rms(model: &serde_json::Value) -> f64 {
    let rms = model["validation_rms"].as_f64().unwrap();
    let v = &model["validation"];
    assert_eq!(v["file"], "validation.csv");
    assert_eq!(v["rms"].as_f64().unwrap(), rms);
    let normalised = v["normalised"].as_f64().unwrap();
    assert!((normalised - rms / v["measured_rms"].as_f64().unwrap()).abs() < 1e-12);
    rms
}

#[test]
fn fit_scores_every_model_on_the_validation_record_at_force_level() {
    let dir = tempfile::tempdir().unwrap();
    let exp = validation_experiment(dir.path(), "force");
    let out = dir.path().join("fit");
    let stdout = String::from_utf8_lossy(&run_ok("fit", &exp, &out).stdout).into_owned();
    let fit = read_json(&out.join("fit.json"));
    let models = fit["models"].as_array().unwrap();
    let (wrong, truth) = (validation_rms(&models[0]), validation_rms(&models[1]));
    // The true model predicts the other record to its noise (the sensor's σ 0.02 N and a
    // little of the kinematics'); the viscous one misses by far more.
    let floor = models[1]["noise_floor"]["sigma"].as_f64().unwrap();
    eprintln!("validation RMS: viscous {wrong} N, power law {truth} N, floor {floor} N");
    assert!(truth < 1.15 * floor, "{truth} against a floor of {floor}");
    assert!(wrong > 3.0 * truth, "viscous {wrong}, power law {truth}");
    // Per regime of the rotor's cycles, all at the noise. By the study's definitions this
    // record has no post-resonance: it ends at 9.3 rad/s with the power law's force still on for
    // ≈ 0.7 of each cycle and above 0.2 N (the amplitude criterion, an option, had called its
    // last cycles post-resonance from their smaller amplitude).
    let per_regime = &models[1]["validation"]["per_regime"];
    for regime in ["pre_resonance", "resonance"] {
        let e = &per_regime[regime];
        assert!(e["cycles"].as_u64().unwrap() >= 3, "{per_regime}");
        assert!(e["rms"].as_f64().unwrap() < 1.3 * floor, "{per_regime}");
    }
    assert!(per_regime["post_resonance"].is_null(), "{per_regime}");
    assert_eq!(models[1]["validation"]["unit"], "N");
    // On the terminal, and first in the report.
    assert!(
        stdout.contains("validation on validation.csv (3601 samples)"),
        "{stdout}"
    );
    let line = stdout
        .lines()
        .rev()
        .find(|l| l.trim_start().starts_with("power_law"))
        .unwrap();
    assert!(line.contains("of the measured RMS"), "{stdout}");
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    // Under the results table (the fitted values), the validation comes first.
    let sections: Vec<&str> = report.lines().filter(|l| l.starts_with("## ")).collect();
    assert_eq!(
        sections[..2],
        ["## Results", "## Validation on a second record"]
    );
    assert!(out.join("figures/validation.csv").exists());
}

#[test]
fn fit_scores_every_model_on_the_validation_record_at_trajectory_level() {
    let dir = tempfile::tempdir().unwrap();
    let exp = validation_experiment(dir.path(), "trajectory");
    let out = dir.path().join("fit");
    run_ok("fit", &exp, &out);
    let fit = read_json(&out.join("fit.json"));
    let models = fit["models"].as_array().unwrap();
    let (wrong, truth) = (validation_rms(&models[0]), validation_rms(&models[1]));
    // x noise σ 0.05 mm (quantised 0.01 mm) on both records.
    let floor = models[1]["noise_floor"]["sigma"].as_f64().unwrap();
    eprintln!("validation RMS: viscous {wrong} m, power law {truth} m, floor {floor} m");
    assert!(truth < 1.15 * floor, "{truth} against a floor of {floor}");
    assert!(wrong > 5.0 * truth, "viscous {wrong}, power law {truth}");
    let v = &models[1]["validation"];
    assert_eq!(v["unit"], "m");
    // The record's own initial state is fitted, as the fit fits x0, v0.
    assert_eq!(v["initial_fitted"], true);
    assert_eq!(v["initial"].as_array().unwrap().len(), 2);
    assert!(v["per_regime"]["resonance"]["rms"].as_f64().unwrap() < 1.3 * floor);
}

#[test]
fn a_missing_validation_record_or_column_is_an_error_before_any_fit() {
    let dir = tempfile::tempdir().unwrap();
    let record = root().join("experiments/records/power_law_sweep.csv");
    // t, phi, x: no f_stf for a force-level fit.
    std::fs::write(dir.path().join("no_force.csv"), "t,phi,x\n0,0,0\n").unwrap();
    // A shaker's record (t, x, f_stf, u): no rotor angle to drive the estimation rig.
    let mut no_drive = String::from("t,x,f_stf,u\n");
    for i in 0..50 {
        no_drive.push_str(&format!("{},0,0,0\n", f64::from(i) * 0.01));
    }
    std::fs::write(dir.path().join("no_drive.csv"), no_drive).unwrap();
    for (level, file, expected) in [
        ("force", "nowhere.csv", "no such record"),
        ("force", "no_force.csv", "has no `f_stf` column"),
        (
            "trajectory",
            "no_drive.csv",
            "has no `phi` or `omega` column",
        ),
    ] {
        let exp = dir.path().join("exp.toml");
        std::fs::write(
            &exp,
            format!(
                "[data]\nfile = {:?}\n\n[fit]\nlevel = \"{level}\"\n\n[validate]\n\
                 window = [0.0, 10.0]\nfile = \"{file}\"\n\n[[models]]\nname = \"viscous\"\n",
                record.display().to_string()
            ),
        )
        .unwrap();
        let out = dir.path().join("fit");
        let started = std::time::Instant::now();
        let output = run("fit", &exp, &out);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success());
        assert!(
            stderr.contains("exp.toml:9: `validate.file`") && stderr.contains(expected),
            "{stderr}"
        );
        assert!(stderr.contains(file), "{stderr}");
        // Before any long work: nothing written, well under the time of a fit.
        assert!(!out.exists(), "{stderr}");
        assert!(started.elapsed().as_secs_f64() < 5.0);
    }
}
