//! End-to-end tests of `stf-lab simulate` and `stf-lab models`.

use std::path::Path;
use std::process::Command;

fn stf_lab() -> Command {
    Command::new(env!("CARGO_BIN_EXE_stf-lab"))
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const SHORT: &str = r#"
[simulate]
constant = { omega = 5.0, t1 = 4.0 }
rate = 200.0
noise = true
seed = 3

[[simulate.truth]]
name = "viscous"
params = { c_s = 5.0 }
"#;

#[test]
fn simulate_writes_a_record_and_a_reproducible_sidecar() {
    let dir = tempfile::tempdir().unwrap();
    let exp = write(dir.path(), "exp.toml", SHORT);
    let out = dir.path().join("rec.csv");
    let status = stf_lab()
        .args([
            "simulate",
            exp.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let first = std::fs::read(&out).unwrap();
    let sidecar: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("rec.json")).unwrap()).unwrap();
    assert_eq!(sidecar["seed"], 3);
    assert_eq!(sidecar["truth"][0]["params"]["c_s"], 5.0);
    assert_eq!(sidecar["summary"]["samples"], 801);

    // A second run refuses to clobber, and with --force gives the same bytes.
    let again = stf_lab()
        .args([
            "simulate",
            exp.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("--force"));
    let forced = stf_lab()
        .args([
            "simulate",
            exp.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--force",
        ])
        .output()
        .unwrap();
    assert!(forced.status.success());
    assert_eq!(std::fs::read(&out).unwrap(), first);
}

#[test]
fn an_unknown_model_is_named_with_file_line_and_the_known_models() {
    let dir = tempfile::tempdir().unwrap();
    let exp = write(
        dir.path(),
        "bad.toml",
        "[simulate]\nconstant = { omega = 5.0, t1 = 1.0 }\n\n[[simulate.truth]]\nname = \"viscuos\"\n",
    );
    let out = stf_lab()
        .args(["simulate", exp.to_str().unwrap(), "--out", "unused.csv"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let msg = String::from_utf8_lossy(&out.stderr);
    assert!(msg.contains("bad.toml:4"), "{msg}");
    assert!(msg.contains("viscuos") && msg.contains("viscous"), "{msg}");
    assert!(!Path::new("unused.csv").exists());
}

#[test]
fn models_lists_the_builtins_with_parameters() {
    let out = stf_lab().arg("models").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("viscous") && text.contains("c_s"), "{text}");
}
