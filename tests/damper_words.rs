//! A damper's record (t, x and the force only: no rotor angle, no drive) through `fit`,
//! `compare` and `discover` with reports: nothing the lab says of it (terminal, reports,
//! figures' titles and columns, the JSON's verdicts) assumes a rotor — no regimes, no
//! resonance, no rotor cycles; its pieces are periods of the motion and thirds of the record.

mod common;

use std::path::Path;

use common::{damper_only_record, read_json, run_ok, write_file};

/// Every phrase of `text` that assumes a rotor (`cycles.csv` is a file's name, a contract,
/// and "no rotor" says the record has none).
fn rotor_words(text: &str) -> Vec<String> {
    let text = text
        .replace("cycles.csv", "")
        .replace("cycles_csv", "")
        .replace("no rotor", "");
    text.split(|c: char| !(c.is_alphanumeric() || c == '-' || c == '_'))
        .filter(|w| {
            let w = w.to_lowercase();
            ["regime", "resonan", "rotor", "cycle"]
                .iter()
                .any(|r| w.contains(r))
        })
        .map(str::to_string)
        .collect()
}

/// The damper record of `common::damper_record` with only t, x and the force (named `F`).
fn damper_only(dir: &Path) -> std::path::PathBuf {
    damper_only_record(dir, (5, 3.0), "damper.csv", |_, force| force);
    write_file(
        dir,
        "damper.toml",
        "[data]\nfile = \"damper.csv\"\ncolumns = { f_stf = \"F\" }\n\n\
         [[models]]\nname = \"viscous\"\n\n[[models]]\nname = \"viscous\"\nplus = [\"yield\"]\n\n\
         [discover]\nbase = \"viscous\"\n\n[output]\nreport = true\n",
    )
}

/// Every report, figure (SVG text, CSV columns) and terminal line of `command` on the damper.
fn said_of(command: &str, exp: &Path, out: &Path) -> Vec<(String, String)> {
    let run = run_ok(command, exp, out);
    let mut said = vec![(
        format!("{command}: terminal"),
        format!(
            "{}{}",
            String::from_utf8_lossy(&run.stdout),
            String::from_utf8_lossy(&run.stderr)
        ),
    )];
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(out)
        .unwrap()
        .chain(std::fs::read_dir(out.join("figures")).unwrap())
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for path in files {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        if name.ends_with(".md") || name.ends_with(".svg") {
            said.push((name, text));
        } else if name.ends_with(".csv") && name.contains("figures") {
            // A figure's CSV header names what it holds; its numbers say nothing. (The
            // tables beside the JSON, `compare.csv` and `cycles.csv`, have fixed columns.)
            said.push((name, text.lines().next().unwrap_or("").to_string()));
        } else if name.ends_with(".json") {
            let doc = read_json(&path);
            let verdict = doc["verdict"]["text"]
                .as_str()
                .or(doc["verdict"].as_str())
                .unwrap_or("")
                .to_string();
            said.push((name, verdict));
        }
    }
    said
}

#[test]
fn a_damper_record_is_spoken_of_without_a_rotor() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = damper_only(tmp.path());
    for command in ["fit", "compare", "discover"] {
        let out = tmp.path().join(command);
        let said = said_of(command, &exp, &out);
        assert!(said.len() > 5, "{command}: {:?}", said.len());
        for (what, text) in &said {
            let wrong = rotor_words(text);
            assert!(wrong.is_empty(), "{wrong:?} in {what}");
        }
        let all: String = said.iter().map(|(_, t)| t.as_str()).collect();
        if command != "fit" || all.contains("third of the record") {
            assert!(
                all.contains("periods") || all.contains("whole record"),
                "{command}: the record's pieces are named"
            );
        }
    }
    let report = std::fs::read_to_string(tmp.path().join("compare/report.md")).unwrap();
    assert!(report.contains("Start, middle and end"), "{report}");
    let svg = std::fs::read_to_string(tmp.path().join("compare/figures/windows.svg")).unwrap();
    assert!(
        svg.contains("start, t ") && !svg.contains("start, ω"),
        "a window of a record without a rotor is named by its time"
    );
}

/// The check finds what it is for: a rotor's words in a rotor's record.
#[test]
fn the_check_finds_a_rotor_s_words() {
    assert_eq!(
        rotor_words("3 whole cycles of each regime; resonance at ω 6.4"),
        ["cycles", "regime", "resonance"]
    );
    assert!(rotor_words("see cycles.csv; the record has no rotor").is_empty());
}
