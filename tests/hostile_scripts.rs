//! A hostile or broken script inside a fit or a simulation is stopped, and the command reports
//! the error with the script's name instead of a result.

mod common;

use std::path::Path;

use common::{root, run, stf_lab};

fn experiment(dir: &Path, script: &str, body: &str) -> std::path::PathBuf {
    std::fs::write(dir.join("hostile.rhai"), script).unwrap();
    let record = root().join("experiments/records/power_law_sweep.csv");
    let exp = dir.join("exp.toml");
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = {:?}\n\n{body}",
            record.display().to_string()
        ),
    )
    .unwrap();
    exp
}

const PARAMS: &str = "fn params() { #{ K: [1.0, 0.0, 10.0, \"N s/m\"] } }\n";

#[test]
fn a_script_that_loops_forever_once_the_blade_moves_stops_the_fit_with_its_name() {
    let dir = tempfile::tempdir().unwrap();
    let script = format!(
        "{PARAMS}fn force(p, t, x, v, z) {{ if v.abs() > 0.01 {{ loop {{ }} }} p.K * v }}\n"
    );
    let exp = experiment(
        dir.path(),
        &script,
        "[[models]]\nscript = \"hostile.rhai\"\n",
    );
    let out = run("fit", &exp, &dir.path().join("out"));
    assert!(!out.status.success());
    let msg = String::from_utf8_lossy(&out.stderr);
    assert!(msg.contains("hostile.rhai"), "{msg}");
    assert!(!dir.path().join("out/fit.json").exists());
}

#[test]
fn a_script_that_recurses_without_end_stops_a_simulation_with_its_name_and_time() {
    let dir = tempfile::tempdir().unwrap();
    let script = format!(
        "{PARAMS}fn deep(n) {{ deep(n + 1) }}\nfn force(p, t, x, v, z) {{ if t > 1.0 {{ deep(0) }} else {{ p.K * v }} }}\n"
    );
    let exp = experiment(
        dir.path(),
        &script,
        "[simulate]\nconstant = { omega = 6.0, t1 = 3.0 }\nrate = 100.0\n\n[[simulate.truth]]\nscript = \"hostile.rhai\"\n",
    );
    let out = stf_lab()
        .arg("simulate")
        .arg(&exp)
        .arg("--out")
        .arg(dir.path().join("rec.csv"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let msg = String::from_utf8_lossy(&out.stderr);
    assert!(
        msg.contains("hostile.rhai") && msg.contains("t = 1.0"),
        "{msg}"
    );
    assert!(!dir.path().join("rec.csv").exists());
}

#[test]
fn a_script_that_reads_a_file_is_refused_at_load() {
    let dir = tempfile::tempdir().unwrap();
    let script = format!(
        "{PARAMS}fn force(p, t, x, v, z) {{ let s = open_file(\"/etc/passwd\"); p.K * v }}\n"
    );
    let exp = experiment(
        dir.path(),
        &script,
        "[[models]]\nscript = \"hostile.rhai\"\n",
    );
    let out = run("fit", &exp, &dir.path().join("out"));
    assert!(!out.status.success());
    let msg = String::from_utf8_lossy(&out.stderr);
    assert!(msg.contains("hostile.rhai"), "{msg}");
}
