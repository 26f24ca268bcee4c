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
