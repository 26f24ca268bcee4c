//! A record's own units and words that fit its rig, in everything the lab shows: a record
//! whose x is a voltage (an electronic oscillator's output, `units = { x = "V" }`) is shown in
//! mV, never mm, in the terminal, the JSON's units, the reports and the figures' columns; a
//! record without a rotor (here the bundled shaker chirp, driven by a measured `u`) is cut into
//! periods of its motion, not rotor cycles, and is not grouped by regimes.

mod common;

use std::path::Path;

use common::{bundled_experiment, read_json, run_ok, write_file};

/// The bundled shaker experiment with its record read in volts (x in V, u in V read as N),
/// and `extra` appended; written in `dir`.
fn volt_experiment(dir: &Path, extra: &str) -> std::path::PathBuf {
    let text = bundled_experiment("trajectory_discovery.toml").replace(
        "trajectory_discovery.csv\"",
        "trajectory_discovery.csv\"\nunits = { x = \"V\", u = { unit = \"V\", gain = 1.0 } }",
    );
    write_file(dir, "volts.toml", &format!("{text}\n{extra}"))
}

/// Every word of `text` that names a length unit or a rotor's regime.
fn wrong_words(text: &str) -> Vec<String> {
    text.split(|c: char| !(c.is_alphanumeric() || c == '-' || c == '²' || c == '/'))
        .filter(|w| {
            let w = w.to_lowercase();
            w == "mm" || w.starts_with("mm/") || w == "mm²" || w.starts_with("regime")
        })
        .map(str::to_string)
        .collect()
}

/// Terminal text of a run (stdout and stderr).
fn terminal(output: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

#[test]
fn a_record_in_volts_is_shown_in_millivolts_everywhere() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = volt_experiment(
        tmp.path(),
        "[fit]\nlevel = \"trajectory\"\n\n[[models]]\nname = \"viscous\"\nplus = [\"cubic_stiffness\"]\n\n[output]\nreport = true\n",
    );
    let out = tmp.path().join("fit");
    let output = run_ok("fit", &exp, &out);
    let said = terminal(&output);
    assert!(said.contains(" mV"), "{said}");
    assert!(
        wrong_words(&said).is_empty(),
        "{:?} in\n{said}",
        wrong_words(&said)
    );
    let doc = read_json(&out.join("fit.json"));
    assert_eq!(doc["models"][0]["rms_unit"], "V");
    let verdict = doc["verdict"]["text"].as_str().unwrap();
    assert!(verdict.contains(" mV"), "{verdict}");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("RMS, mV"), "{md}");
    assert!(
        wrong_words(&md).is_empty(),
        "{:?} in report.md",
        wrong_words(&md)
    );
    let csv = std::fs::read_to_string(out.join("figures/measured_vs_fitted.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.contains("x, mV") && !header.contains("mm"),
        "{header}"
    );
}

#[test]
fn a_record_in_metres_is_still_shown_in_millimetres() {
    let tmp = tempfile::tempdir().unwrap();
    let text = bundled_experiment("trajectory_discovery.toml")
        + "\n[fit]\nlevel = \"trajectory\"\n\n[[models]]\nname = \"viscous\"\n";
    let exp = write_file(tmp.path(), "metres.toml", &text);
    let out = tmp.path().join("fit");
    let said = terminal(&run_ok("fit", &exp, &out));
    assert!(said.contains(" mm"), "{said}");
    assert!(!said.contains("mV"), "{said}");
    assert_eq!(
        read_json(&out.join("fit.json"))["models"][0]["rms_unit"],
        "m"
    );
}

#[test]
fn discovery_on_a_rotorless_record_in_volts_speaks_of_periods_and_millivolts() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = volt_experiment(tmp.path(), "[output]\nreport = true\n");
    let out = tmp.path().join("disc");
    let output = run_ok("discover", &exp, &out);
    let said = terminal(&output);
    assert!(said.contains("periods of the record"), "{said}");
    assert!(!said.contains("cycles"), "{said}");
    assert!(
        wrong_words(&said).is_empty(),
        "{:?} in\n{said}",
        wrong_words(&said)
    );
    let doc = read_json(&out.join("discovery.json"));
    assert_eq!(doc["gap_unit"], "V");
    assert_eq!(doc["effects"], serde_json::json!(["cubic_stiffness"]));
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("mV"), "{md}");
    assert!(
        wrong_words(&md).is_empty(),
        "{:?} in report.md",
        wrong_words(&md)
    );
    let csv = std::fs::read_to_string(out.join("figures/discovery_x.csv")).unwrap();
    assert!(
        csv.lines().next().unwrap().contains("x, mV"),
        "{}",
        csv.lines().next().unwrap()
    );
}

#[test]
fn compare_on_a_rotorless_record_ranks_over_the_whole_record() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = volt_experiment(tmp.path(), "[[models]]\nname = \"viscous\"\n");
    let out = tmp.path().join("cmp");
    // `cycles.csv` is a file's name (a contract), not a word said of the record.
    let said = terminal(&run_ok("compare", &exp, &out)).replace("cycles.csv", "");
    assert!(said.contains("whole record"), "{said}");
    assert!(!said.contains("cycles"), "{said}");
    assert!(
        wrong_words(&said).is_empty(),
        "{:?} in\n{said}",
        wrong_words(&said)
    );
    let md = std::fs::read_to_string(out.join("compare.md")).unwrap();
    assert!(
        md.contains("| model | whole record | peak x (mV) |"),
        "{md}"
    );
    assert!(
        wrong_words(&md).is_empty(),
        "{:?} in compare.md",
        wrong_words(&md)
    );
    let verdict = read_json(&out.join("compare.json"))["verdict"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(verdict.contains("over the whole record"), "{verdict}");
}
