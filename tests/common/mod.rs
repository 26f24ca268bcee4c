//! Helpers shared by the end-to-end tests: run the program, find the bundled examples, read
//! results. (Each test binary uses a part of them.)
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// The program under test.
pub fn stf_lab() -> Command {
    Command::new(env!("CARGO_BIN_EXE_stf-lab"))
}

/// The project folder (the bundled examples live in `experiments/`).
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// `stf-lab COMMAND --quiet --out OUT EXPERIMENT`.
pub fn run(command: &str, experiment: &Path, out: &Path) -> Output {
    stf_lab()
        .args([command, "--quiet", "--out"])
        .arg(out)
        .arg(experiment)
        .output()
        .unwrap()
}

/// The same, asserting success (the failure message is the program's).
pub fn run_ok(command: &str, experiment: &Path, out: &Path) -> Output {
    let output = run(command, experiment, out);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// `stf-lab simulate EXPERIMENT --out RECORD`, asserting success.
pub fn simulate_ok(experiment: &Path, record: &Path) {
    let sim = stf_lab()
        .arg("simulate")
        .arg(experiment)
        .arg("--out")
        .arg(record)
        .output()
        .unwrap();
    assert!(
        sim.status.success(),
        "{}",
        String::from_utf8_lossy(&sim.stderr)
    );
}

/// A JSON result file.
pub fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}
