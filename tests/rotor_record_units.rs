//! A rotor's record whose x is a voltage (`[data] units = { x = "V" }`) is labelled in its
//! own units in everything only a rotor's record gets: the frequency response, the regime
//! windows and their placement, compare's peak and loop table (energy, c_eq = force per
//! velocity), the identification's stages, and the JSON's unit fields; no `mm`, `mm/s`,
//! `m/s²`, `mJ`, `N·s/m` or `N/m` is left where the record is in volts.

mod common;

use std::path::Path;

use common::{bundled_experiment, read_json, root, run_ok, write_file};

/// Every label of `text` that says a length (or a unit derived from one) in metres.
fn metre_labels(text: &str) -> Vec<String> {
    // An SVG's print size (`width="170mm"`) is paper, not the record.
    let text = text
        .split('"')
        .filter(|w| !(w.ends_with("mm") && w[..w.len() - 2].parse::<f64>().is_ok()))
        .collect::<Vec<_>>()
        .join("\"");
    text.split(|c: char| !(c.is_alphanumeric() || "·/²³ⁿ()".contains(c)))
        .filter(|w| {
            ["mm", "mJ", "m/s²", "N/m", "kg"].contains(w)
                || w.starts_with("mm/")
                || w.starts_with("mm²")
                || w.starts_with("N·s/m")
                || w.ends_with("/m")
        })
        .map(str::to_string)
        .collect()
}

/// Every file under `dir` (recursively) whose name ends with one of `exts`, with its text.
fn texts(dir: &Path, exts: &[&str]) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(texts(&path, exts));
        } else if exts.iter().any(|e| path.to_string_lossy().ends_with(e)) {
            out.push((
                path.display().to_string(),
                std::fs::read_to_string(&path).unwrap(),
            ));
        }
    }
    out
}

/// No metre label in any report, table, figure (its SVG text and CSV) or JSON under `dir`.
fn assert_no_metre_labels(dir: &Path) {
    let files = texts(dir, &[".md", ".csv", ".svg", ".json", ".html"]);
    let names: Vec<&str> = files.iter().map(|(p, _)| p.as_str()).collect();
    assert!(files.len() > 3, "{names:?}");
    for (path, text) in files {
        // cycles.csv's and the JSON's key names (`amplitude_m`, `s_mm2`) are a contract; the
        // JSON's `units` say what they hold.
        let text = text
            .replace("s_mm2", "")
            .replace("floor_mm2", "")
            .replace("c_eq_ns_m", "");
        let wrong = metre_labels(&text);
        assert!(wrong.is_empty(), "{wrong:?} in {path}");
    }
}

#[test]
fn a_rotor_record_in_volts_is_compared_in_millivolts_and_volts() {
    let tmp = tempfile::tempdir().unwrap();
    let text = bundled_experiment("power_law_fit.toml").replace(
        "power_law_sweep.csv\"",
        "power_law_sweep.csv\"\nunits = { x = \"V\" }",
    );
    // The bundled experiment's models, minus its script (a script's unit is its own).
    let text = text
        .split("[[models]]                    # the same law")
        .next()
        .unwrap();
    let exp = write_file(
        tmp.path(),
        "volts.toml",
        &format!("{text}\n[output]\nreport = true\n"),
    );
    let out = tmp.path().join("cmp");
    let said = String::from_utf8_lossy(&run_ok("compare", &exp, &out).stdout).to_string();
    assert!(metre_labels(&said).is_empty(), "{said}");
    assert!(
        said.contains("N·s/V") || said.contains("N·(s/V)ⁿ"),
        "{said}"
    );
    assert_no_metre_labels(&out);
    let doc = read_json(&out.join("compare.json"));
    assert_eq!(
        doc["units"],
        serde_json::json!({"x": "V", "force": "N", "energy": "N·V", "c_eq": "N·s/V"})
    );
    assert_eq!(doc["models"][0]["fit"]["param_units"]["c_s"], "N·s/V");
    let md = std::fs::read_to_string(out.join("compare.md")).unwrap();
    assert!(md.contains("peak x (mV) at ω"), "{md}");
    assert!(
        md.contains(" mN·V · c_eq ") && md.contains("in N·s/V"),
        "{md}"
    );
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("mV at ω"),
        "the resonance window's amplitude:\n{report}"
    );
    let frf = std::fs::read_to_string(out.join("figures/frequency_response.csv")).unwrap();
    assert!(
        frf.contains("measured: local maximum of x, mV"),
        "{frf:.300}"
    );
    let svg = std::fs::read_to_string(out.join("figures/regime_windows.svg")).unwrap();
    assert!(
        svg.contains("mV/s") && svg.contains("V/s²"),
        "regime windows' axes"
    );
}

#[test]
fn a_rotor_record_in_metres_keeps_millimetres_and_newton_seconds_per_metre() {
    let tmp = tempfile::tempdir().unwrap();
    let text = bundled_experiment("power_law_fit.toml");
    let text = text.split("[[models]]").next().unwrap();
    let exp = write_file(
        tmp.path(),
        "metres.toml",
        &format!("{text}\n[[models]]\nname = \"viscous\"\n"),
    );
    let out = tmp.path().join("cmp");
    run_ok("compare", &exp, &out);
    let doc = read_json(&out.join("compare.json"));
    assert_eq!(
        doc["units"],
        serde_json::json!({"x": "m", "force": "N", "energy": "J", "c_eq": "N·s/m"})
    );
    let md = std::fs::read_to_string(out.join("compare.md")).unwrap();
    assert!(
        md.contains("peak x (mm) at ω") && md.contains(" mJ · c_eq "),
        "{md}"
    );
}

#[test]
fn an_identification_on_records_in_volts_is_in_millivolts() {
    let tmp = tempfile::tempdir().unwrap();
    let records = root().join("experiments/records");
    let text = std::fs::read_to_string(root().join("experiments/paper_identification.toml"))
        .unwrap()
        .replace(
            "data = \"records/",
            &format!(
                "data = \"{}/",
                records.display().to_string().replace('\\', "\\\\")
            ),
        );
    let exp = write_file(
        tmp.path(),
        "ident.toml",
        &format!("{text}\n[data]\nunits = {{ x = \"V\" }}\n\n[output]\nreport = true\n"),
    );
    let out = tmp.path().join("ident");
    let said = String::from_utf8_lossy(&run_ok("fit", &exp, &out).stdout).to_string();
    assert!(metre_labels(&said).is_empty(), "{said}");
    assert_no_metre_labels(&out);
    let doc = read_json(&out.join("fit.json"));
    assert_eq!(doc["units"]["x"], "V");
    assert_eq!(doc["units"]["s_mm2"], "mV²");
    assert_eq!(doc["units"]["system"]["k"], "N/V");
    assert_eq!(doc["units"]["system"]["c"], "N·s/V");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains(" mV², "), "{md}");
    let frf = std::fs::read_to_string(out.join("figures/frequency_response_stage_2.csv")).unwrap();
    assert!(frf.contains("local maximum of x, mV"), "{frf:.300}");
}
