//! Helpers shared by the end-to-end tests: run the program, find the bundled examples, read
//! results. (Each test binary uses a part of them.)
#![allow(dead_code)]

pub mod slurm;

use std::path::{Path, PathBuf};
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

/// Terminal text of a run: its stdout, then its stderr.
pub fn terminal(output: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    )
}

/// The same, asserting success (the failure message is the program's).
pub fn run_ok(command: &str, experiment: &Path, out: &Path) -> Output {
    succeeded(run(command, experiment, out))
}

/// [`run_ok`], then the JSON result `file` of `out` (`fit.json`, `discovery.json`, …).
pub fn run_json(command: &str, experiment: &Path, out: &Path, file: &str) -> serde_json::Value {
    run_ok(command, experiment, out);
    read_json(&out.join(file))
}

/// The bundled experiment `experiments/NAME` as text, its record's path made absolute (so it
/// runs from any folder).
pub fn bundled_experiment(name: &str) -> String {
    let records = root().join("experiments/records").display().to_string();
    std::fs::read_to_string(root().join("experiments").join(name))
        .unwrap()
        .replace(
            "file = \"records/",
            &format!("file = \"{}/", records.replace('\\', "\\\\")),
        )
}

/// `text` written to `dir/name`: the file's path.
pub fn write_file(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// Simulate into `dir/r.csv` a damper-like shaker record: viscous + yield (`c_s` 800 N·s/m,
/// `F_y` 150 N: a force of hundreds of N), a chirp 0.5 → `f1` Hz over 10 s at 1 kHz, the
/// rig's sensors on with `seed`.
pub fn damper_record(dir: &Path, seed: u64, f1: f64) {
    let make = format!(
        "[data]\nfile = \"r.csv\"\n\n[system]\npreset = \"forced\"\nT = 0.0\ndelta_T = 0.0\n\n\
         [simulate]\nchirp = {{ f0 = 0.5, f1 = {f1}, amplitude = 600.0, t1 = 10.0 }}\n\
         rate = 1000.0\nnoise = true\nseed = {seed}\n\n[[simulate.truth]]\nname = \"viscous\"\n\
         params = {{ c_s = 800.0 }}\n\n[[simulate.truth]]\nname = \"yield\"\n\
         params = {{ F_y = {{ value = 150.0, max = 1000.0 }} }}\n"
    );
    simulate_ok(&write_file(dir, "make.toml", &make), &dir.join("r.csv"));
}

/// [`damper_record`] (`seed`, chirp to `f1` Hz) cut to what a damper rig measures, written to
/// `dir/name`: columns `t,x,F`, the force `force(t, F)` of the simulated one.
pub fn damper_only_record(
    dir: &Path,
    (seed, f1): (u64, f64),
    name: &str,
    force: impl Fn(f64, f64) -> f64,
) -> std::path::PathBuf {
    damper_record(dir, seed, f1);
    let text = std::fs::read_to_string(dir.join("r.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = |n: &str| header.iter().position(|h| *h == n).unwrap();
    let (t, x, f) = (at("t"), at("x"), at("f_stf"));
    let mut out = String::from("t,x,F\n");
    for line in lines {
        let c: Vec<&str> = line.split(',').collect();
        let (time, measured): (f64, f64) = (c[t].parse().unwrap(), c[f].parse().unwrap());
        let shown = force(time, measured);
        // The simulated text as it stands where the force is not changed.
        let cell = if shown == measured {
            c[f].to_string()
        } else {
            shown.to_string()
        };
        out.push_str(&format!("{},{},{cell}\n", c[t], c[x]));
    }
    write_file(dir, name, &out)
}

/// `stf-lab simulate EXPERIMENT --out RECORD`, then the `extra` flags.
pub fn simulate(experiment: &Path, record: &Path, extra: &[&str]) -> Output {
    stf_lab()
        .arg("simulate")
        .arg(experiment)
        .arg("--out")
        .arg(record)
        .args(extra)
        .output()
        .unwrap()
}

/// `output` of a run that must have succeeded (the failure message is the program's).
pub fn succeeded(output: Output) -> Output {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// `stf-lab simulate EXPERIMENT --out RECORD`, asserting success.
pub fn simulate_ok(experiment: &Path, record: &Path) {
    succeeded(simulate(experiment, record, &[]));
}

/// A JSON result file.
pub fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// A CSV of numbers with a header row: the column named `name`.
pub fn csv_column(path: &Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column `{name}` in {header:?}"));
    lines
        .map(|l| l.split(',').nth(at).unwrap().parse().unwrap())
        .collect()
}

/// The model of a `fitted` entry of discovery.json (`a + b`, built-ins) with its values in
/// the model's order.
pub fn fitted_model(
    entry: &serde_json::Value,
) -> (
    std::sync::Arc<dyn stf_core::physics::force_model::ForceModel>,
    Vec<f64>,
) {
    let parts = entry["name"]
        .as_str()
        .unwrap()
        .split(" + ")
        .map(|p| stf_lab::model_config::resolve(p, root(), &Default::default()).unwrap())
        .collect();
    let model: std::sync::Arc<dyn stf_core::physics::force_model::ForceModel> =
        std::sync::Arc::new(stf_core::physics::model_sum::ModelSum::new(parts).unwrap());
    let values = model
        .params()
        .iter()
        .map(|s| entry["params"][&s.name].as_f64().unwrap())
        .collect();
    (model, values)
}

/// The largest |a − b| over two equal-length series.
pub fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}
