//! End-to-end tests of `stf-lab simulate` and `stf-lab models`.

use std::path::Path;

mod common;
use common::{root, simulate, stf_lab, succeeded};

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
    succeeded(simulate(&exp, &out, &[]));
    let first = std::fs::read(&out).unwrap();
    let sidecar: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("rec.json")).unwrap()).unwrap();
    assert_eq!(sidecar["seed"], 3);
    assert_eq!(sidecar["truth"][0]["params"]["c_s"], 5.0);
    assert_eq!(sidecar["summary"]["samples"], 801);

    // A second run refuses to clobber, and with --force gives the same bytes.
    let again = simulate(&exp, &out, &[]);
    assert!(!again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("--force"));
    let forced = simulate(&exp, &out, &["--force"]);
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
    let out = simulate(&exp, &dir.path().join("unused.csv"), &[]);
    assert!(!out.status.success());
    let msg = String::from_utf8_lossy(&out.stderr);
    assert!(msg.contains("bad.toml:4"), "{msg}");
    assert!(msg.contains("viscuos") && msg.contains("viscous"), "{msg}");
    assert!(!dir.path().join("unused.csv").exists());
}

#[test]
fn models_lists_the_builtins_with_parameters() {
    let out = stf_lab().arg("models").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("viscous") && text.contains("c_s"), "{text}");
}

#[test]
fn the_readme_example_prints_the_reference_figures() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("paper_sweep.csv");
    let run = succeeded(simulate(
        &root().join("experiments/paper_sweep.toml"),
        &out,
        &[],
    ));
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(
        text.contains("peak |x| = 41.69 mm at ω = 6.22 rad/s"),
        "{text}"
    );
    assert!(
        text.contains("breakaway (|x| first above 0.1 mm) at ω = 3.79 rad/s"),
        "{text}"
    );
}

#[test]
fn a_run_too_long_for_memory_is_refused_before_it_starts() {
    // The issue's case: 10⁹ s at 1 MHz aborted with a failed 8 PB allocation.
    let dir = tempfile::tempdir().unwrap();
    let exp = write(
        dir.path(),
        "huge.toml",
        "[simulate]\nconstant = { omega = 6.0, t1 = 1e9 }\nrate = 1e6\n",
    );
    let out = dir.path().join("rec.csv");
    let run = simulate(&exp, &out, &[]);
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("huge.toml:1: `simulate.rate`")
            && stderr.contains("asks for 1.00e15 samples, over the limit of 10000000")
            && stderr.contains("`simulate.max_samples`"),
        "{stderr}"
    );
    assert!(!out.exists());
}

#[test]
fn bundled_records_regenerate_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let mut stale = Vec::new();
    // The bundled campaign's records: `experiments/campaign/records/<name>.toml` makes
    // `<name>.csv`.
    let campaign: Vec<(String, String)> = ["a1", "a2", "a3"]
        .iter()
        .flat_map(|a| ["c1", "c2", "c3"].map(|c| format!("experiments/campaign/records/{a}_{c}")))
        .chain(["experiments/campaign/records/a2_c4".to_string()])
        .map(|stem| (format!("{stem}.toml"), format!("{stem}.csv")))
        .collect();
    let campaign = campaign.iter().map(|(e, r)| (e.as_str(), r.as_str()));
    for (exp, record) in [
        (
            "experiments/discovery.toml",
            "experiments/records/discovery_sweep.csv",
        ),
        (
            "experiments/power_law_fit.toml",
            "experiments/records/power_law_sweep.csv",
        ),
        (
            "experiments/jamming_compare.toml",
            "experiments/records/jamming_sweep.csv",
        ),
        (
            "experiments/records/free_vibration.toml",
            "experiments/records/free_vibration.csv",
        ),
        (
            "experiments/records/forced_sweep.toml",
            "experiments/records/forced_sweep.csv",
        ),
        (
            "experiments/trajectory_discovery.toml",
            "experiments/records/trajectory_discovery.csv",
        ),
    ]
    .into_iter()
    .chain(campaign)
    {
        let out = dir.path().join("again.csv");
        let run = simulate(&root().join(exp), &out, &["--force"]);
        assert!(
            run.status.success(),
            "{exp}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        if std::fs::read(&out).unwrap() != std::fs::read(root().join(record)).unwrap() {
            stale.push(format!("{record} is not what {exp} makes"));
        }
    }
    assert!(stale.is_empty(), "{}", stale.join("\n"));
}
