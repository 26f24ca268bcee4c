//! End-to-end tests of `stf-lab discover` at trajectory level: `stf-lab simulate` writes a
//! shaker rig's record (x and the measured drive force `u`, a chirp), whose truth may hide a
//! cubic stiffness; `discover` works from x and u only, and `fit` accepts what it names.

mod common;

use std::path::{Path, PathBuf};

use common::{read_json, root, run_ok, simulate_ok};

/// A 20 s chirp 0.5 → 1.5 Hz of 2 N through resonance at 200 Hz on the frictionless forced
/// trolley, STF = 1·v + k3·x³, rig sensors; simulated by the program into `record.csv`.
fn write_record(dir: &Path, k3: f64) {
    let truth = if k3 > 0.0 {
        format!("name = \"viscous\"\nplus = [\"cubic_stiffness\"]\nparams = {{ c_s = 1.0, k3 = {k3:e} }}\n")
    } else {
        "name = \"viscous\"\nparams = { c_s = 1.0 }\n".to_string()
    };
    let exp = dir.join("sim.toml");
    std::fs::write(
        &exp,
        format!(
            "[system]\npreset = \"forced\"\nT = 0.0\ndelta_T = 0.0\n\n[simulate]\n\
             chirp = {{ f0 = 0.5, f1 = 1.5, amplitude = 2.0, t1 = 20.0 }}\nrate = 200.0\n\
             seed = 7\n\n[[simulate.truth]]\n{truth}"
        ),
    )
    .unwrap();
    simulate_ok(&exp, &dir.join("record.csv"));
}

/// The discovery experiment on `record.csv`: the oscillator 2 % off the truth; m, k, c refitted
/// (the default for a u-driven rig); trajectory level, as the record has an `f_stf` column too.
fn experiment(dir: &Path, k3: f64) -> PathBuf {
    write_record(dir, k3);
    let exp = dir.join("exp.toml");
    std::fs::write(
        &exp,
        "[data]\nfile = \"record.csv\"\n\n[system]\nm = 7.803\nk = 275.333\nc = 3.7576\n\
         T = 0.0\ndelta_T = 0.0\n\n[discover]\nbase = \"viscous\"\n\
         candidates = [\"cubic_stiffness\", \"power_law\"]\nlevel = \"trajectory\"\n\n\
         [output]\nreport = false\n",
    )
    .unwrap();
    exp
}

#[test]
fn the_program_simulates_a_chirp_rig_and_its_columns_are_t_x_f_stf_u() {
    let tmp = tempfile::tempdir().unwrap();
    write_record(tmp.path(), 1e4);
    let text = std::fs::read_to_string(tmp.path().join("record.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t,x,f_stf,u"));
    // u is the chirp at the sample times, written exact.
    for line in lines.take(4001).step_by(397) {
        let cells: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        let t = cells[0];
        let chirp = 2.0 * (std::f64::consts::TAU * (0.5 * t + 0.025 * t * t)).sin();
        assert!(
            (cells[3] - chirp).abs() < 1e-12,
            "t = {t}: u = {}",
            cells[3]
        );
    }
    assert_eq!(text.lines().count(), 4002);
    let sidecar = read_json(&tmp.path().join("record.json"));
    assert_eq!(sidecar["simulate"]["chirp"]["f1"], 1.5);
    assert!(sidecar["summary"]["motion_stops_t_s"].is_null());
}

#[test]
fn trajectory_discovery_names_cubic_stiffness_from_x_and_u_and_fit_accepts_the_result() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = experiment(tmp.path(), 1e4);
    let out = tmp.path().join("disc");
    let started = std::time::Instant::now();
    run_ok("discover", &exp, &out);
    eprintln!("discover took {:.1} s", started.elapsed().as_secs_f64());
    let doc = read_json(&out.join("discovery.json"));
    assert_eq!(doc["level"], "trajectory");
    assert_eq!(doc["effects"], serde_json::json!(["cubic_stiffness"]));
    let (before, after) = (
        doc["s_before_mm2"].as_f64().unwrap(),
        doc["s_after_mm2"].as_f64().unwrap(),
    );
    // S of a model that leaves only the sensor noise: the noise floor squared.
    let floor_mm2 = (doc["noise_floor"].as_f64().unwrap() * 1e3).powi(2);
    eprintln!("S {before} → {after} mm², noise floor's S {floor_mm2} mm²");
    assert!(after < 0.1 * before, "S {before} → {after} mm²");
    assert!(
        after < 2.0 * floor_mm2,
        "S after {after} mm², noise floor's S {floor_mm2} mm²"
    );
    assert!(doc["gap_after"].as_f64().unwrap() < doc["gap_before"].as_f64().unwrap());
    let k = doc["system"]["k"].as_f64().unwrap();
    assert!((k / 269.9346 - 1.0).abs() < 0.01, "k = {k}");
    // The final model and refitted oscillator are entries `fit` accepts as they are.
    let entry = doc["final_model"]["experiment_entry"].as_str().unwrap();
    let system = doc["final_model"]["system_entry"].as_str().unwrap();
    let refit = tmp.path().join("refit.toml");
    std::fs::write(
        &refit,
        format!(
            "[data]\nfile = \"record.csv\"\n\n{system}T = 0.0\ndelta_T = 0.0\n\n[fit]\n\
             level = \"trajectory\"\n\n[output]\nreport = false\n\n{entry}"
        ),
    )
    .unwrap();
    run_ok("fit", &refit, &tmp.path().join("fit"));
}

#[test]
fn trajectory_discovery_names_nothing_without_the_cubic_term() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = experiment(tmp.path(), 0.0);
    let out = tmp.path().join("disc");
    run_ok("discover", &exp, &out);
    let doc = read_json(&out.join("discovery.json"));
    assert_eq!(doc["effects"], serde_json::json!([]), "{:#}", doc["steps"]);
}

#[test]
fn the_bundled_example_names_the_cubic_spring() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("disc");
    run_ok(
        "discover",
        &root().join("experiments/trajectory_discovery.toml"),
        &out,
    );
    let doc = read_json(&out.join("discovery.json"));
    assert_eq!(doc["level"], "trajectory");
    assert_eq!(doc["effects"], serde_json::json!(["cubic_stiffness"]));
    let k3 = doc["final_model"]["params"]["k3"].as_f64().unwrap();
    assert!((k3 / 1e4 - 1.0).abs() < 0.05, "k3 = {k3}");
    // At trajectory level the lab reads no STF force (the record's column is the simulation's,
    // not a sensor's): the record's time history is its motion, with no F_STF panel, marks
    // or loops.
    let history = std::fs::read_to_string(out.join("figures/time_history.csv")).unwrap();
    let header = history.lines().next().unwrap();
    assert!(
        header.contains("x, mm") && !header.contains("F_STF"),
        "{header}"
    );
    let svg = std::fs::read_to_string(out.join("figures/time_history.svg")).unwrap();
    assert!(!svg.contains("F_STF maxima"));
    assert!(!out.join("figures/hysteresis_x.csv").exists());
    // The report shows the x residual before and after, in mm: the final one is smaller.
    let csv = std::fs::read_to_string(out.join("figures/discovery_x_residual.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "\"t, s\",\"base x residual, mm\",\"final: simulated x residual, mm\""
    );
    let (mut before, mut after, mut n) = (0.0, 0.0, 0.0);
    for line in lines {
        let v: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        before += v[1] * v[1];
        after += v[2] * v[2];
        n += 1.0;
    }
    let (before, after) = ((before / n).sqrt(), (after / n).sqrt());
    assert!(after < 0.1 * before, "x residual {before} → {after} mm RMS");
}

#[test]
fn trajectory_discovery_is_validated_on_a_second_record_and_its_json_redraws_its_curves() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = experiment(tmp.path(), 1e4);
    // The validation record: the same rig and truth under another chirp (0.6 → 1.4 Hz of
    // 1.8 N over 15 s) with another noise seed.
    let sim = tmp.path().join("validation.toml");
    std::fs::write(
        &sim,
        "[system]\npreset = \"forced\"\nT = 0.0\ndelta_T = 0.0\n\n[simulate]\n\
         chirp = { f0 = 0.6, f1 = 1.4, amplitude = 1.8, t1 = 15.0 }\nrate = 200.0\nseed = 8\n\n\
         [[simulate.truth]]\nname = \"viscous\"\nplus = [\"cubic_stiffness\"]\n\
         params = { c_s = 1.0, k3 = 1e4 }\n",
    )
    .unwrap();
    simulate_ok(&sim, &tmp.path().join("validation.csv"));
    let text = std::fs::read_to_string(&exp).unwrap();
    std::fs::write(
        &exp,
        format!("{text}\n[validate]\nfile = \"validation.csv\"\n"),
    )
    .unwrap();
    let out = tmp.path().join("disc");
    let stdout = String::from_utf8_lossy(&run_ok("discover", &exp, &out).stdout).into_owned();
    let doc = read_json(&out.join("discovery.json"));
    assert_eq!(doc["effects"], serde_json::json!(["cubic_stiffness"]));
    let v = &doc["validation"];
    assert_eq!(
        (&v["file"], &v["unit"]),
        (&"validation.csv".into(), &"m".into())
    );
    let (before, after) = (
        v["rms_before"].as_f64().unwrap(),
        v["rms_after"].as_f64().unwrap(),
    );
    // x noise σ 0.05 mm: the final model simulates the other record to it, the base does not.
    let floor = doc["noise_floor"].as_f64().unwrap();
    eprintln!("validation RMS {before} → {after} m, floor {floor} m");
    assert!(after < 1.15 * floor, "{after} against a floor of {floor}");
    assert!(before > 10.0 * after, "{before} → {after}");
    assert_eq!(v["initial_fitted"], true);
    assert!(
        stdout.contains("validation on validation.csv (3001 samples)"),
        "{stdout}"
    );

    // The fitted values alone — oscillator, model, offset, initial state — with the record's
    // drive read as the experiment reads it, simulate the curves discovered.csv holds.
    let mut experiment = stf_lab::experiment::Experiment::load(&exp).unwrap();
    let data = stf_lab::fitting::load_data(&mut experiment).unwrap();
    let drive = std::sync::Arc::new(data.kinematics.excitation());
    let csv = out.join("discovered.csv");
    for (which, column) in [("base", "x_base"), ("final", "x_final")] {
        let entry = &doc["fitted"][which];
        let (model, values) = common::fitted_model(entry);
        let system: stf_core::physics::oscillator_params::OscillatorParams =
            serde_json::from_value(entry["system"].clone()).unwrap();
        let osc = stf_core::physics::oscillator::Oscillator::with_shared_excitation(
            system,
            drive.clone(),
        )
        .with_model(model, values)
        .unwrap();
        let initial = &entry["initial"];
        let run = stf_core::simulate::Simulation::new(&osc)
            .settings(experiment.integrator.clone())
            .initial(
                initial["x0"].as_f64().unwrap(),
                initial["v0"].as_f64().unwrap(),
            )
            .run_at(&data.record.t)
            .unwrap();
        let offset = entry["offset"]["value"].as_f64().unwrap_or(0.0);
        let redrawn: Vec<f64> = run.x.iter().map(|x| x + offset).collect();
        let diff = common::max_difference(&redrawn, &common::csv_column(&csv, column));
        assert!(diff < 1e-12, "{which}: redrawn differs by {diff} m");
    }
    // The refitted oscillator is the one discovery.json reports.
    assert_eq!(doc["fitted"]["final"]["system"], doc["system"]);
}
