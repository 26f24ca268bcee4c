//! End-to-end test of `stf-lab discover` on the bundled example.

use std::path::Path;
use std::process::Command;

#[test]
fn discovery_names_the_hidden_cubic_spring_and_the_gap_shrinks_to_the_noise() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("disc");
    let run = Command::new(env!("CARGO_BIN_EXE_stf-lab"))
        .args(["discover", "--quiet", "--out"])
        .arg(&dir)
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/discovery.toml"))
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("discovery.json")).unwrap()).unwrap();
    assert_eq!(doc["effects"], serde_json::json!(["cubic_stiffness"]));
    let before = doc["gap_before"].as_f64().unwrap();
    let after = doc["gap_after"].as_f64().unwrap();
    let floor = doc["noise_floor"].as_f64().unwrap();
    assert!(after < before / 3.0, "gap {before} → {after}");
    assert!(after <= 1.2 * floor, "gap after {after}, floor {floor}");
    let k3 = doc["final_model"]["params"]["k3"].as_f64().unwrap();
    assert!((k3 / 2e4 - 1.0).abs() < 0.05, "k3 = {k3}");
    // The final model is an experiment entry that `fit` accepts as it is.
    let entry = doc["final_model"]["experiment_entry"].as_str().unwrap();
    assert!(entry.contains("plus = [\"cubic_stiffness\"]"), "{entry}");
    assert!(dir.join("report.html").exists());

    let record =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/records/discovery_sweep.csv");
    let exp = out.path().join("refit.toml");
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = {:?}\n\n{entry}",
            record.display().to_string()
        ),
    )
    .unwrap();
    let fit = Command::new(env!("CARGO_BIN_EXE_stf-lab"))
        .args(["fit", "--quiet", "--out"])
        .arg(out.path().join("refit"))
        .arg(&exp)
        .output()
        .unwrap();
    assert!(
        fit.status.success(),
        "{}",
        String::from_utf8_lossy(&fit.stderr)
    );
}
