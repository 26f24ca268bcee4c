//! One ranking behind every "best" a comparison names: `compare.json`'s `best.overall` is the
//! first of its `ranking.overall`, the model the verdict names first, the lowest overall
//! score in the terminal's table and in `compare.md`; each `best.<regime>` is the model with
//! the lowest error in that regime. On a record with a rotor the overall score is the mean
//! over the regimes; on a damper's record (t, x and the force only: no sweep) it is the error
//! over the whole record, even when the record's periods fall under several of the force's
//! labels (here a damper disengaged for its first 3 s, its force negligible there).

mod common;

use std::path::Path;

use common::{damper_only_record, read_json, root, run_ok, simulate_ok, write_file};
use serde_json::Value;

/// A damper record of `common::damper_record` (`seed`, chirp to `f1` Hz) with only t, x and
/// the force, the force a 5000th of itself before t = 3 s (the damper disengaged), and an
/// experiment comparing `viscous`, `yield` and `viscous + yield` on it.
fn disengaged_damper(dir: &Path, seed: u64, f1: f64) -> std::path::PathBuf {
    damper_only_record(dir, (seed, f1), "damper.csv", |time, force| {
        if time < 3.0 {
            force * 2e-4
        } else {
            force
        }
    });
    write_file(
        dir,
        "damper.toml",
        "[data]\nfile = \"damper.csv\"\ncolumns = { f_stf = \"F\" }\n\n\
         [[models]]\nname = \"viscous\"\n\n[[models]]\nname = \"yield\"\n\n\
         [[models]]\nname = \"viscous\"\nplus = [\"yield\"]\n",
    )
}

/// `compare` on `exp` into `out`: its terminal text, `compare.json` and `compare.md`.
fn compared(exp: &Path, out: &Path) -> (String, Value, String) {
    let run = run_ok("compare", exp, out);
    let said = String::from_utf8_lossy(&run.stdout).to_string();
    let doc = read_json(&out.join("compare.json"));
    let md = std::fs::read_to_string(out.join("compare.md")).unwrap();
    (said, doc, md)
}

/// The model with the lowest of `scores` (finite only).
fn lowest(scores: &[(String, f64)]) -> Option<String> {
    scores
        .iter()
        .filter(|(_, s)| s.is_finite())
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(m, _)| m.clone())
}

/// Each model's relative force RMS error in `regime` (`overall`: over the whole record).
fn errors_in(doc: &Value, regime: Option<&str>) -> Vec<(String, f64)> {
    doc["models"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|m| {
            let metrics = match regime {
                Some(r) => &m["regimes"][r],
                None => &m["overall"],
            };
            let e = metrics["relative_rms_error"].as_f64()?;
            Some((m["label"].as_str().unwrap().to_string(), e))
        })
        .collect()
}

/// The number the terminal's table gives `label` in its last score column.
fn terminal_score(said: &str, label: &str, column: usize) -> f64 {
    let line = said
        .lines()
        .find(|l| l.trim_start().starts_with(&format!("{label} ")))
        .unwrap_or_else(|| panic!("no row of {label} in\n{said}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    words[1 + column].parse().unwrap_or(f64::NAN)
}

/// Every per-regime best is the lowest error in its regime and the first of its ranking.
fn assert_regime_bests(doc: &Value) {
    for regime in ["pre_resonance", "resonance", "post_resonance"] {
        let best = doc["best"][regime].as_str().map(str::to_string);
        let ranked = doc["ranking"]["per_regime"][regime][0]["model"]
            .as_str()
            .map(str::to_string);
        assert_eq!(best, ranked, "{regime}");
        assert_eq!(best, lowest(&errors_in(doc, Some(regime))), "{regime}");
    }
}

#[test]
fn a_damper_s_best_is_the_verdict_s_over_the_whole_record() {
    for (seed, f1) in [(5, 3.0), (6, 4.0)] {
        let tmp = tempfile::tempdir().unwrap();
        let exp = disengaged_damper(tmp.path(), seed, f1);
        let (said, doc, md) = compared(&exp, &tmp.path().join("cmp"));
        let per_regime = &doc["measured"]["cycles_per_regime"];
        let labels = ["pre_resonance", "resonance", "post_resonance"]
            .iter()
            .filter(|r| per_regime[**r].as_u64().unwrap() > 0)
            .count();
        assert!(labels > 1, "seed {seed}: one label only: {per_regime}");
        let best = doc["best"]["overall"].as_str().unwrap().to_string();
        assert_eq!(doc["ranking"]["overall"][0]["model"], best.as_str());
        assert_eq!(Some(best.clone()), lowest(&errors_in(&doc, None)));
        let verdict = doc["verdict"].as_str().unwrap();
        let first = verdict.split('`').nth(1).unwrap();
        assert_eq!(first, best, "seed {seed}: {verdict}");
        // The terminal's "whole record" column and compare.md's table.
        let shown: Vec<(String, f64)> = errors_in(&doc, None)
            .into_iter()
            .map(|(m, _)| {
                let s = terminal_score(&said, &m, 0);
                (m, s)
            })
            .collect();
        assert_eq!(Some(best.clone()), lowest(&shown), "seed {seed}:\n{said}");
        let row = md
            .lines()
            .find(|l| l.starts_with(&format!("| {best} |")))
            .unwrap();
        let score: f64 = row
            .split('|')
            .nth(2)
            .unwrap()
            .split_whitespace()
            .next()
            .unwrap()
            .parse()
            .unwrap();
        for (m, s) in &shown {
            assert!(
                score <= *s + 5e-4,
                "seed {seed}: {best} {score} against {m} {s}"
            );
        }
        assert_regime_bests(&doc);
        eprintln!("seed {seed}, f1 {f1}: best {best}; {verdict}");
    }
}

#[test]
fn a_rotor_s_best_is_the_verdict_s_over_the_regimes() {
    let tmp = tempfile::tempdir().unwrap();
    // The bundled jamming sweep, and the same truth on a faster sweep with another seed.
    let bundled = root().join("experiments/jamming_compare.toml");
    let text = std::fs::read_to_string(&bundled)
        .unwrap()
        .replace("records/jamming_sweep.csv", "fast.csv")
        .replace(
            "alpha = 0.0333, t0 = 90.0, t1 = 450.0",
            "alpha = 0.05, t0 = 60.0, t1 = 300.0",
        )
        .replace("seed = 5", "seed = 6");
    let fast = write_file(tmp.path(), "fast.toml", &text);
    simulate_ok(&fast, &tmp.path().join("fast.csv"));
    for (i, exp) in [bundled, fast].iter().enumerate() {
        let (said, doc, md) = compared(exp, &tmp.path().join(format!("cmp{i}")));
        let best = doc["best"]["overall"].as_str().unwrap().to_string();
        assert_eq!(doc["ranking"]["overall"][0]["model"], best.as_str());
        // The mean over the regimes the record has, each weighing the same.
        let means: Vec<(String, f64)> = doc["models"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| {
                let e: Vec<f64> = ["pre_resonance", "resonance", "post_resonance"]
                    .iter()
                    .filter_map(|r| m["regimes"][*r]["relative_rms_error"].as_f64())
                    .collect();
                let label = m["label"].as_str().unwrap().to_string();
                (label, e.iter().sum::<f64>() / e.len() as f64)
            })
            .collect();
        assert_eq!(Some(best.clone()), lowest(&means), "{means:?}");
        let verdict = doc["verdict"].as_str().unwrap();
        let named = verdict.split("Best over the regimes").nth(1).unwrap();
        assert_eq!(named.split('`').nth(1), Some(best.as_str()), "{verdict}");
        let column: Vec<(String, f64)> = means
            .iter()
            .map(|(m, _)| (m.clone(), terminal_score(&said, m, 3)))
            .collect();
        assert_eq!(Some(best.clone()), lowest(&column), "{said}");
        assert!(
            md.contains(&format!(
                "- best over the regimes (mean of the per-regime errors): **{best}**"
            )),
            "{md}"
        );
        assert_regime_bests(&doc);
    }
}
