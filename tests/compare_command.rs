//! End-to-end test of `stf-lab compare` on the bundled on–off jamming example.

mod common;

use common::{read_json, root, run_ok};

#[test]
fn the_truth_ranks_first_and_viscous_misses_the_on_off_force() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("cmp");
    let _ = run_ok(
        "compare",
        &root().join("experiments/jamming_compare.toml"),
        &dir,
    );
    let doc = read_json(&dir.join("compare.json"));
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
