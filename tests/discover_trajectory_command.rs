//! End-to-end test of `stf-lab discover` at trajectory level: a record with x and the
//! measured drive force `u` only (no `f_stf`), whose truth hides a cubic stiffness.

mod common;

use std::sync::Arc;

use common::{read_json, run_ok};
use stf_core::excitation::Excitation;
use stf_core::interpolate::Linear;
use stf_core::model_sum::ModelSum;
use stf_core::oscillator::Oscillator;
use stf_core::simulate::Simulation;
use stf_core::synthetic::{sample_record, SensorNoise};
use stf_core::system::OscillatorParams;

/// A 20 s chirp 0.5 → 1.5 Hz of 2 N through resonance at 200 Hz, STF = 1·v + k3·x³, rig
/// sensors; written as `t,x,u`.
fn write_record(path: &std::path::Path, k3: f64) {
    let system = OscillatorParams {
        t_friction: 0.0,
        delta_t: 0.0,
        ..OscillatorParams::FORCED
    };
    let t: Vec<f64> = (0..4001).map(|i| i as f64 / 200.0).collect();
    let u: Vec<f64> = t
        .iter()
        .map(|&t| 2.0 * (std::f64::consts::TAU * (0.5 * t + 0.025 * t * t)).sin())
        .collect();
    let truth = ModelSum::new(vec![
        stf_models::find("viscous").unwrap(),
        stf_models::find("cubic_stiffness").unwrap(),
    ])
    .unwrap();
    let osc = Oscillator::new(system, Excitation::Force(Linear::new(t.clone(), u)))
        .with_model(Arc::new(truth), vec![1.0, k3])
        .unwrap();
    let run = Simulation::new(&osc).run_at(&t).unwrap();
    let rec = sample_record(&run, &SensorNoise::RIG, 7, false);
    let u = rec.u.unwrap();
    let mut csv = String::from("t,x,u\n");
    for ((t, x), u) in rec.t.iter().zip(&rec.x).zip(&u) {
        csv.push_str(&format!("{t},{x},{u}\n"));
    }
    std::fs::write(path, csv).unwrap();
}

fn experiment(dir: &std::path::Path, k3: f64) -> std::path::PathBuf {
    write_record(&dir.join("record.csv"), k3);
    // The oscillator 2 % off the truth; m, k, c refitted (the default for a u-driven rig).
    let exp = dir.join("exp.toml");
    std::fs::write(
        &exp,
        "[data]\nfile = \"record.csv\"\n\n[system]\nm = 7.803\nk = 275.333\nc = 3.7576\n\
         T = 0.0\ndelta_T = 0.0\n\n[discover]\nbase = \"viscous\"\n\
         candidates = [\"cubic_stiffness\", \"power_law\"]\n\n[output]\nreport = false\n",
    )
    .unwrap();
    exp
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
    eprintln!("S {before} → {after} mm²");
    assert!(after < 0.1 * before, "S {before} → {after} mm²");
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
