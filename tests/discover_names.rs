//! Names that mean what they say: a candidate whose fitted values make it a simpler effect is
//! reported as that effect. On the bundled record (a cubic spring hidden under a power law),
//! `wall_impact` fits a gap of 0.36 mm (1 % of the stroke) and an exponent of 2.95: a cubic
//! spring.

mod common;

use common::{read_json, root, run_ok};

fn discover(candidates: &str, dir: &std::path::Path) -> serde_json::Value {
    let record = root().join("experiments/records/discovery_sweep.csv");
    let exp = dir.join(format!("d{}.toml", candidates.len()));
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = {:?}\n\n[discover]\nbase = \"power_law\"\ncandidates = [{candidates}]\n",
            record.display().to_string()
        ),
    )
    .unwrap();
    let out = dir.join(format!("o{}", candidates.len()));
    run_ok("discover", &exp, &out);
    read_json(&out.join("discovery.json"))
}

#[test]
fn a_wall_without_a_gap_is_named_a_cubic_spring() {
    let dir = tempfile::tempdir().unwrap();
    let alone = discover("\"wall_impact\", \"added_mass\"", dir.path());
    let verdict = alone["steps"][0]["verdict"].as_str().unwrap();
    assert!(
        verdict.contains("is in effect `cubic_stiffness`"),
        "{verdict}"
    );
    let both = discover(
        "\"wall_impact\", \"cubic_stiffness\", \"added_mass\"",
        dir.path(),
    );
    assert_eq!(
        both["effects"],
        serde_json::json!(["cubic_stiffness"]),
        "{both}"
    );
}
