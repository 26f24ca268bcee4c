//! A record's own units and words that fit its rig, in everything the lab shows: a record
//! whose x is a voltage (an electronic oscillator's output, `units = { x = "V" }`) is shown in
//! mV, never mm, in the terminal, the JSON's units, the reports and the figures' columns; a
//! record without a rotor (here the bundled shaker chirp, driven by a measured `u`) is cut into
//! periods of its motion, not rotor cycles, and is not grouped by regimes.

mod common;

use std::path::{Path, PathBuf};

use common::{bundled_experiment, read_json, root, run_ok, terminal, write_file};

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

/// The shaker's experiment with `models`, on its record read in volts
/// ([`volt_experiment`]) and as bundled, in metres.
fn volts_and_metres(dir: &Path, models: &str) -> (PathBuf, PathBuf) {
    let volts = volt_experiment(dir, models);
    let metres = write_file(
        dir,
        "metres.toml",
        &format!(
            "{}\n{models}",
            bundled_experiment("trajectory_discovery.toml")
        ),
    );
    (volts, metres)
}

/// A trajectory-level fit that misses an effect (viscous alone on the shaker) is warned
/// about in mV on a record in volts — the residual and the floor as the summary shows them,
/// in the terminal and in `fit.json`'s stored message — and in mm on the same record in
/// metres.
#[test]
fn a_fit_warning_on_a_record_in_volts_is_in_millivolts() {
    let tmp = tempfile::tempdir().unwrap();
    let models = "[fit]\nlevel = \"trajectory\"\n\n[[models]]\nname = \"viscous\"\n";
    let (volts, metres) = volts_and_metres(tmp.path(), models);
    for (exp, unit) in [(volts, "mV"), (metres, "mm")] {
        let out = tmp.path().join(unit);
        let said = terminal(&run_ok("fit", &exp, &out));
        let warning = said
            .lines()
            .find(|l| l.contains("warning: the residual is"))
            .unwrap_or_else(|| panic!("viscous alone leaves no warning in\n{said}"));
        assert!(warning.contains(&format!(" {unit} against ")), "{warning}");
        assert!(warning.contains(&format!(" {unit}): ")), "{warning}");
        if unit == "mV" {
            assert!(wrong_words(&said).is_empty(), "{said}");
        }
        let message = read_json(&out.join("fit.json"))["models"][0]["warnings"][0]["message"]
            .as_str()
            .unwrap()
            .to_string();
        assert!(warning.trim_start().ends_with(&message), "{message}");
    }
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
    let units = param_units(&out.join("params.csv"));
    assert!(
        units.iter().any(|(p, u)| p == "c_s" && u == "N·s/m"),
        "{units:?}"
    );
    assert!(
        units.iter().any(|(p, u)| p == "x0" && u == "m"),
        "{units:?}"
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
    // The final model's parameters in the record's units: k3 in 1/V², m in s².
    assert!(said.contains(" 1/V²") && !said.contains("N/m"), "{said}");
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

/// A scouted trajectory-level discovery (the search on short pieces of the record) on a
/// record in volts: the reasons a candidate was not fitted on the whole record are in mV too.
#[test]
fn a_scouted_discovery_on_a_record_in_volts_says_why_in_millivolts() {
    let tmp = tempfile::tempdir().unwrap();
    // The shaker's chirp ten times as long at half the rate (20 000 samples: past the
    // default `scout_from`, and long enough for pieces of six periods), simulated into a
    // record of its own.
    let record = tmp.path().join("long.csv");
    let exp = volt_experiment(tmp.path(), "");
    let text = std::fs::read_to_string(&exp).unwrap();
    let bundled = text
        .split('"')
        .find(|s| s.ends_with("trajectory_discovery.csv"));
    let text = text
        .replace(
            bundled.unwrap(),
            &record.display().to_string().replace('\\', "/"),
        )
        .replace("t1 = 20.0", "t1 = 200.0")
        .replace("rate = 200.0", "rate = 100.0");
    std::fs::write(&exp, text).unwrap();
    run_ok("simulate", &exp, &record);
    let out = tmp.path().join("disc");
    let output = run_ok("discover", &exp, &out);
    let said = terminal(&output);
    let doc = read_json(&out.join("discovery.json"));
    assert!(
        doc["notes"]
            .as_array()
            .unwrap()
            .iter()
            .any(|n| n.as_str().unwrap().starts_with("scouted")),
        "{:?}",
        doc["notes"]
    );
    let why: Vec<&str> = doc["steps"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|s| s["candidates"].as_array().unwrap())
        .filter_map(|c| c["failure"].as_str())
        .collect();
    assert!(
        why.iter()
            .any(|w| w.contains("not fitted on the whole record")),
        "{why:?}"
    );
    for w in &why {
        assert!(wrong_words(w).is_empty(), "{w}");
    }
    assert!(
        wrong_words(&said).is_empty(),
        "{:?} in\n{said}",
        wrong_words(&said)
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

/// `(parameter, unit)` of every row of a `params.csv`.
fn param_units(path: &Path) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (p, u) = (at("parameter"), at("unit"));
    lines
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            (cells[p].to_string(), cells[u].to_string())
        })
        .collect()
}

/// The symbols of a unit (`N·s/V` → N, s, V).
fn symbols(unit: &str) -> Vec<&str> {
    unit.split(|c: char| !c.is_alphanumeric() || "ⁿ⁰¹²³⁴⁵⁶⁷⁸⁹".contains(c))
        .filter(|s| !s.is_empty())
        .collect()
}

/// On a record whose x and drive are both voltages read as they are (an electronic
/// oscillator), lengths are V and forces V: no parameter's unit says m, mm, N or kg, and the
/// oscillator's equation fixes each (c_s in s, k3 in 1/V², the initial state in V and V/s).
#[test]
fn parameters_on_a_record_in_volts_are_in_volts_not_metres() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = volt_experiment(
        tmp.path(),
        "[fit]\nlevel = \"trajectory\"\n\n[[models]]\nname = \"viscous\"\nplus = [\"cubic_stiffness\"]\n\n[output]\nreport = true\n",
    );
    let out = tmp.path().join("fit");
    let said = terminal(&run_ok("fit", &exp, &out));
    let units = param_units(&out.join("params.csv"));
    for (p, u) in &units {
        let wrong: Vec<&str> = symbols(u)
            .into_iter()
            .filter(|s| ["m", "mm", "N", "kg"].contains(s))
            .collect();
        assert!(wrong.is_empty(), "{p} in {u}: {units:?}");
    }
    let expected = [("c_s", "s"), ("k3", "1/V²"), ("x0", "V"), ("v0", "V/s")];
    for (p, u) in expected {
        assert!(
            units.iter().any(|(q, v)| q == p && v == u),
            "{p} not in {u}: {units:?}"
        );
    }
    assert!(said.contains(" 1/V²") && said.contains(" V/s"), "{said}");
    assert!(!said.contains("N·s/m") && !said.contains("N/m"), "{said}");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("| k3 | ") && md.contains(" | 1/V² |"), "{md}");
    assert!(!md.contains("N/m") && !md.contains("| m |"), "{md}");
}

/// At force level the force is the STF force's own unit (N here, x still in volts): a power
/// law's K is in N·(s/V)ⁿ, a viscous term in N·s/V, and the RMS in N.
#[test]
fn force_level_parameters_on_a_record_in_volts_keep_newtons_for_the_force() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = volt_experiment(
        tmp.path(),
        "[fit]\nlevel = \"force\"\n\n[[models]]\nname = \"viscous\"\nplus = [\"cubic_stiffness\"]\n\n[[models]]\nname = \"power_law\"\n",
    );
    let out = tmp.path().join("fit");
    let said = terminal(&run_ok("fit", &exp, &out));
    let units = param_units(&out.join("params.csv"));
    for (p, u) in [("c_s", "N·s/V"), ("k3", "N/V³"), ("K", "N·(s/V)ⁿ")] {
        assert!(
            units.iter().any(|(q, v)| q == p && v == u),
            "{p} not in {u}: {units:?}"
        );
    }
    assert!(said.contains("N·(s/V)ⁿ") && !said.contains("s/m"), "{said}");
    assert_eq!(
        read_json(&out.join("fit.json"))["models"][0]["rms_unit"],
        "N"
    );
}

/// A campaign of records in volts: the joint fit's RMS in mV (its RSS in V²), each record's
/// RMS in mV and its parameters' units in volts, in the JSON, the table and the report.
#[test]
fn a_campaign_on_records_in_volts_speaks_of_millivolts_and_volts() {
    let tmp = tempfile::tempdir().unwrap();
    let record = root().join("experiments/records/trajectory_discovery.csv");
    for name in ["a.csv", "b.csv", "c.csv"] {
        std::fs::copy(&record, tmp.path().join(name)).unwrap();
    }
    let exp = volt_experiment(
        tmp.path(),
        "[fit]\nlevel = \"trajectory\"\n\n[[models]]\nname = \"viscous\"\nplus = [\"cubic_stiffness\"]\n",
    );
    let campaign = tmp.path().join("campaign.toml");
    std::fs::write(
        &campaign,
        format!(
            "[campaign]\nexperiment = \"{}\"\ncommand = \"fit\"\nconditions = [\"gain\"]\n\n\
             [[records]]\nfile = \"a.csv\"\ngain = 1.0\n\n[[records]]\nfile = \"b.csv\"\ngain = 1.1\n\n\
             [[records]]\nfile = \"c.csv\"\ngain = 1.2\n\n\
             [global]\nmodel = \"viscous + cubic_stiffness\"\nshared = [\"c_s\", \"k3\"]\n\
             holdout = \"c.csv\"\nlevel = \"trajectory\"\n",
            exp.display()
        ),
    )
    .unwrap();
    let out = tmp.path().join("out");
    let run = common::stf_lab()
        .args(["campaign", "--jobs", "1", "--out"])
        .arg(&out)
        .arg(&campaign)
        .output()
        .unwrap();
    let said = terminal(&run);
    assert!(run.status.success(), "{said}");
    assert!(
        wrong_words(&said).is_empty(),
        "{:?} in\n{said}",
        wrong_words(&said)
    );
    let g = read_json(&out.join("global.json"));
    assert_eq!(g["rms_unit"], "mV");
    assert!(
        g["verdict"].as_str().unwrap().contains(" mV"),
        "{}",
        g["verdict"]
    );
    let table = read_json(&out.join("campaign.json"));
    let row = &table["rows"][0];
    assert_eq!(row["params"]["k3"]["unit"], "1/V²", "{row}");
    assert_eq!(row["params"]["x0"]["unit"], "V", "{row}");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("| RSS, V² |") && md.contains(" mV |"), "{md}");
    assert!(
        wrong_words(&md).is_empty() && !md.contains("m²"),
        "{:?} in report.md",
        wrong_words(&md)
    );
}

/// A `[global]` law over records read in different units (one in metres, one in volts) is
/// refused, naming both records and their units, instead of reporting one law in a mixture.
#[test]
fn a_joint_fit_over_records_in_metres_and_volts_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let record = root().join("experiments/records/trajectory_discovery.csv");
    for name in ["a.csv", "b.csv", "c.csv"] {
        std::fs::copy(&record, tmp.path().join(name)).unwrap();
    }
    let models = "[fit]\nlevel = \"trajectory\"\n\n[[models]]\nname = \"viscous\"\nplus = [\"cubic_stiffness\"]\n";
    let (volts, metres) = volts_and_metres(tmp.path(), models);
    let campaign = write_file(
        tmp.path(),
        "campaign.toml",
        &format!(
            "[campaign]\nexperiment = \"{}\"\ncommand = \"fit\"\nconditions = [\"gain\"]\n\n\
             [[records]]\nfile = \"a.csv\"\ngain = 1.0\n\n[[records]]\nfile = \"b.csv\"\ngain = 1.1\n\n\
             [[records]]\nfile = \"c.csv\"\ngain = 1.2\nexperiment = \"{}\"\n\n\
             [global]\nmodel = \"viscous + cubic_stiffness\"\nshared = [\"c_s\", \"k3\"]\n\
             level = \"trajectory\"\n",
            metres.display(),
            volts.display()
        ),
    );
    let out = tmp.path().join("out");
    let run = common::stf_lab()
        .args(["campaign", "--jobs", "1", "--out"])
        .arg(&out)
        .arg(&campaign)
        .output()
        .unwrap();
    let said = terminal(&run);
    assert!(!run.status.success(), "{said}");
    assert!(
        said.contains("record a.csv is in m and N while record c.csv is in V and V"),
        "{said}"
    );
    assert!(!out.join("global.json").exists(), "{said}");
}
