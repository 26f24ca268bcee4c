//! A run killed or interrupted mid-way leaves the previous results intact and no half-written
//! file under a final name; Ctrl-C says what had finished.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn fit(dir: &Path, experiment: &str) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_stf-lab"));
    c.args(["fit", "--quiet", "--force", "--out"])
        .arg(dir)
        .arg(root().join(experiment));
    c
}

/// The identification, signalled with `signal` (`-INT`, `-TERM`) `after_ms` after it
/// starts while it works: its exit code and its message.
fn signalled_identification(dir: &Path, signal: &str, after_ms: u64) -> (Option<i32>, String) {
    let child = fit(dir, "experiments/paper_identification.toml")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(after_ms));
    let status = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let result = child.wait_with_output().unwrap();
    let msg = String::from_utf8_lossy(&result.stderr).into_owned();
    (result.status.code(), msg)
}

/// The results in `dir` are whole: fit.json parses and fitted.csv has every row.
fn assert_whole(dir: &Path, rows: usize) {
    let json = std::fs::read(dir.join("fit.json")).unwrap();
    let doc: serde_json::Value = serde_json::from_slice(&json).expect("fit.json is whole");
    assert_eq!(doc["models"].as_array().unwrap().len(), 4);
    let csv = std::fs::read_to_string(dir.join("fitted.csv")).unwrap();
    assert_eq!(csv.lines().count(), rows + 1, "fitted.csv is whole");
    assert!(csv.ends_with('\n'));
}

#[test]
fn a_killed_fit_leaves_whole_results() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("fit");
    let first = fit(&dir, "experiments/power_law_fit.toml")
        .output()
        .unwrap();
    assert!(first.status.success());
    let rows = 12001;
    assert_whole(&dir, rows);
    // Kill re-runs at several moments: before, during and after the writes.
    for delay in [50, 200, 400, 700, 1000, 1500] {
        let mut child = fit(&dir, "experiments/power_law_fit.toml")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(delay));
        let _ = child.kill();
        let _ = child.wait();
        // A kill between the two renames of the folder swap leaves the old results beside
        // the folder's place; the next run puts them back first, as here.
        stf_lab::writing::results_dir::repair(&dir).unwrap();
        assert_whole(&dir, rows);
        let strays: Vec<_> = std::fs::read_dir(out.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n != "fit" && n != ".fit.lock")
            .collect();
        assert!(strays.is_empty(), "{strays:?}");
    }
}

#[test]
fn ctrl_c_says_what_had_finished_and_writes_nothing() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("id");
    // Stage 1 (free vibration) takes well under a second; stage 2 far longer.
    let (code, msg) = signalled_identification(&dir, "-INT", 2500);
    if code == Some(0) {
        // The machine was fast enough to finish first: nothing to check.
        return;
    }
    assert_eq!(code, Some(130), "{msg}");
    assert!(msg.contains("interrupted"), "{msg}");
    // Unless the signal came after the results were put in place, nothing is there.
    let written = msg.contains("the results were already written");
    assert_eq!(dir.join("fit.json").exists(), written, "{msg}");
}

#[test]
fn sigterm_removes_the_staged_folder_and_keeps_the_old_results() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().join("fit");
    let first = fit(&dir, "experiments/power_law_fit.toml")
        .output()
        .unwrap();
    assert!(first.status.success());
    let before = std::fs::read(dir.join("fit.json")).unwrap();
    // The identification's second stage takes seconds: the signal lands while it works.
    let (code, msg) = signalled_identification(&dir, "-TERM", 1500);
    if code == Some(0) {
        // The machine was fast enough to finish first: nothing to check.
        return;
    }
    assert_eq!(code, Some(130), "{msg}");
    if msg.contains("the results were already written") {
        // The signal came after the new results were put in place: they are whole and new.
        let now = std::fs::read(dir.join("fit.json")).unwrap();
        assert_ne!(now, before, "{msg}");
        let _: serde_json::Value = serde_json::from_slice(&now).expect("fit.json is whole");
    } else {
        assert!(msg.contains("no results were written"), "{msg}");
        assert_eq!(std::fs::read(dir.join("fit.json")).unwrap(), before);
    }
    let mut left: Vec<_> = std::fs::read_dir(out.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["fit"]);
}
