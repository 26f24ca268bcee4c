//! End-to-end test of `stf-lab compare` on the bundled on–off jamming example.

use std::path::Path;
use std::process::Command;

#[test]
fn the_truth_ranks_first_and_viscous_misses_the_on_off_force() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("cmp");
    let run = Command::new(env!("CARGO_BIN_EXE_stf-lab"))
        .args(["compare", "--quiet", "--out"])
        .arg(&dir)
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/jamming_compare.toml"))
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("compare.json")).unwrap()).unwrap();
    assert_eq!(doc["best"]["overall"], "jamming_on_off");
    assert_eq!(doc["best"]["post_resonance"], "jamming_on_off");
    assert_eq!(doc["measured"]["no_stf"], false);
    let models = doc["models"].as_array().unwrap();
    let viscous = models.iter().find(|m| m["name"] == "viscous").unwrap();
    let duty_error = viscous["regimes"]["post_resonance"]["duty_error"]
        .as_f64()
        .unwrap();
    assert!(
        duty_error > 0.2,
        "viscous post-resonance duty error {duty_error}"
    );
    let md = std::fs::read_to_string(dir.join("compare.md")).unwrap();
    assert!(
        md.contains("viscous misses the on–off behaviour in post-resonance"),
        "{md}"
    );
    assert!(dir.join("compare.csv").exists());
}
