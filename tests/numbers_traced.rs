//! Every number a report opens with traces to its command's JSON: for each bundled example,
//! the verdict paragraph (the first under the title of `report.md`) and the report's first
//! table (the summary: the fits, a stage's values, the per-regime errors, a discovery step's
//! candidates) are parsed, and each number in them is found among the numbers of the JSON the
//! same run wrote (`fit.json`, `compare.json`, `discovery.json`), as shown: SI or in mm (×1e3)
//! or in % (×100), rounded to the digits printed; a relative standard error is traced to
//! `100·se/|value|` of a parameter both are in the JSON for. Names in backticks and ordinals that name a
//! stage or step are labels, not numbers, and are left out.

mod common;

use serde_json::Value;

/// Every number of `v`, depth first (strings are not parsed: a verdict's `text` is the
/// paragraph itself and proves nothing).
fn numbers(v: &Value, out: &mut Vec<f64>) {
    match v {
        Value::Number(n) => out.extend(n.as_f64()),
        Value::Array(a) => a.iter().for_each(|x| numbers(x, out)),
        Value::Object(o) => o.values().for_each(|x| numbers(x, out)),
        _ => {}
    }
}

/// Each relative standard error the reports' results tables show, in %: `100·se/|value|` of
/// every parameter with both a value and a standard error in `v` (a fit's `params` beside its
/// `std_errors`; a discovery's final `values` beside them).
fn relative_errors(v: &Value, out: &mut Vec<f64>) {
    match v {
        Value::Array(a) => a.iter().for_each(|x| relative_errors(x, out)),
        Value::Object(o) => {
            if let Some(Value::Object(se)) = o.get("std_errors") {
                for key in ["params", "values"] {
                    if let Some(Value::Object(values)) = o.get(key) {
                        for (name, value) in values {
                            let (Some(x), Some(e)) =
                                (value.as_f64(), se.get(name).and_then(Value::as_f64))
                            else {
                                continue;
                            };
                            out.push(100.0 * e / x.abs());
                        }
                    }
                }
            }
            o.values().for_each(|x| relative_errors(x, out));
        }
        _ => {}
    }
}

/// The numbers written in `text`, each with the half-width of the rounding it was shown with.
fn shown(text: &str) -> Vec<(String, f64, f64)> {
    let mut cleaned = String::new();
    for (i, part) in text.split('`').enumerate() {
        if i % 2 == 0 {
            cleaned.push_str(part);
            cleaned.push(' ');
        }
    }
    let ordinals = without_ordinals(&cleaned);
    let mut found = Vec::new();
    let bytes: Vec<char> = ordinals.chars().collect();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            && (i == 0 || !(bytes[i - 1].is_alphanumeric() || bytes[i - 1] == '_'));
        if !starts {
            i += 1;
            continue;
        }
        let from = if i > 0 && (bytes[i - 1] == '-' || bytes[i - 1] == '+') {
            i - 1
        } else {
            i
        };
        let mut j = i;
        while j < bytes.len() && (bytes[j].is_ascii_digit() || bytes[j] == '.') {
            j += 1;
        }
        // Digit groups of a long integer part, `19 987`: a space, three digits, then no digit.
        while !bytes[from..j].contains(&'.')
            && j + 3 < bytes.len()
            && bytes[j] == ' '
            && bytes[j + 1..j + 4].iter().all(char::is_ascii_digit)
            && bytes.get(j + 4).is_none_or(|c| !c.is_ascii_digit())
        {
            j += 4;
            while j < bytes.len() && (bytes[j].is_ascii_digit() || bytes[j] == '.') {
                j += 1;
            }
        }
        let mut exp = 0i32;
        let mantissa: String = bytes[from..j].iter().filter(|c| **c != ' ').collect();
        if j + 1 < bytes.len() && bytes[j] == 'e' {
            let mut k = j + 1;
            if bytes[k] == '-' || bytes[k] == '+' {
                k += 1;
            }
            while k < bytes.len() && bytes[k].is_ascii_digit() {
                k += 1;
            }
            let e: String = bytes[j + 1..k].iter().collect();
            exp = e.parse().unwrap_or(0);
            j = k;
        }
        let mantissa = mantissa.trim_end_matches('.');
        if let Ok(m) = mantissa.parse::<f64>() {
            let decimals = mantissa.split('.').nth(1).map_or(0, str::len) as i32;
            let half = 0.5 * 10f64.powi(exp - decimals);
            let token: String = bytes[from..j].iter().filter(|c| **c != ' ').collect();
            found.push((token, m * 10f64.powi(exp), half));
        }
        i = j.max(i + 1);
    }
    found
}

/// `text` without the ordinals that name a stage or a step (`stage 1`, `Step 2`).
fn without_ordinals(text: &str) -> String {
    let mut out = String::new();
    let mut words = text.split(' ').peekable();
    while let Some(w) = words.next() {
        out.push_str(w);
        out.push(' ');
        if matches!(w, "stage" | "Stage" | "step" | "Step") {
            words.next();
        }
    }
    out
}

/// Whether the shown number `x` (± `half`) is one of `json`'s, as shown.
fn traced(x: f64, half: f64, json: &[f64]) -> bool {
    [1.0, 1e3, 1e6, 100.0].iter().any(|s| {
        json.iter()
            .any(|v| (v * s - x).abs() <= half * (1.0 + 1e-9) + 1e-12 * x.abs())
    })
}

/// The verdict paragraph and the first table of a report.
fn verdict_and_summary(report: &str) -> (String, String) {
    let mut paragraphs = report.split("\n\n").map(str::trim);
    let verdict = paragraphs
        .find(|p| !p.is_empty() && !p.starts_with('#'))
        .unwrap_or_default()
        .to_string();
    let table: Vec<&str> = report
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .collect();
    (verdict, table.join("\n"))
}

fn check(command: &str, experiment: &str, json_name: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let exp = common::root().join("experiments").join(experiment);
    common::run_ok(command, &exp, &out);
    let json = common::read_json(&out.join(json_name));
    let mut all = Vec::new();
    numbers(&json, &mut all);
    relative_errors(&json, &mut all);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    let (verdict, mut table) = verdict_and_summary(&report);
    // The force as an equation, under "Results" (fit.json's and discovery.json's `equation`).
    let equations: Vec<&str> = report.lines().filter(|l| l.contains("F_STF = ")).collect();
    if command != "fit" || experiment != "paper_identification.toml" {
        assert!(!equations.is_empty(), "{experiment}: no equation");
    }
    for line in equations {
        table.push('\n');
        table.push_str(line);
    }
    assert!(!verdict.is_empty(), "{experiment}: no verdict");
    assert!(!table.is_empty(), "{experiment}: no summary table");
    let mut missing = Vec::new();
    let mut count = 0;
    for (token, x, half) in shown(&verdict).into_iter().chain(shown(&table)) {
        count += 1;
        if !traced(x, half, &all) {
            missing.push(token);
        }
    }
    assert!(count >= 5, "{experiment}: only {count} numbers read");
    assert!(
        missing.is_empty(),
        "{experiment}: shown but not in {json_name}: {missing:?}\nverdict: {verdict}\ntable:\n{table}"
    );
}

#[test]
fn fit_numbers_trace_to_fit_json() {
    check("fit", "power_law_fit.toml", "fit.json");
}

#[test]
fn identification_numbers_trace_to_its_fit_json() {
    check("fit", "paper_identification.toml", "fit.json");
}

#[test]
fn compare_numbers_trace_to_compare_json() {
    check("compare", "jamming_compare.toml", "compare.json");
}

#[test]
fn discovery_numbers_trace_to_discovery_json() {
    check("discover", "discovery.toml", "discovery.json");
}

#[test]
fn trajectory_discovery_numbers_trace_to_discovery_json() {
    check("discover", "trajectory_discovery.toml", "discovery.json");
}

/// The compare report's other rankings: the table of errors per regime with their mean over
/// the regimes (the one overall score, compare.json's `ranking.overall`) and the line of each
/// loop metric (each z shown is the one compare.json holds; a test with too few cycles is
/// "not tested", never a z of NaN).
#[test]
fn compare_s_rankings_trace_to_compare_json() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let exp = common::root().join("experiments/jamming_compare.toml");
    common::run_ok("compare", &exp, &out);
    let json = common::read_json(&out.join("compare.json"));
    let mut all = Vec::new();
    numbers(&json, &mut all);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(!report.contains("NaN"), "NaN in the report");
    let header = "| model | pre-resonance | resonance | post-resonance | mean over regimes |";
    let rows: Vec<&str> = report
        .lines()
        .skip_while(|l| *l != header)
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .collect();
    assert_eq!(rows.len(), 4, "the errors table:\n{report}");
    let lines: Vec<&str> = report.lines().filter(|l| l.starts_with("by ")).collect();
    assert!(lines.len() >= 5, "the ranking lines");
    let mut missing = Vec::new();
    let mut count = 0;
    for line in rows.iter().chain(&lines) {
        for (token, x, half) in shown(line) {
            count += 1;
            if !traced(x, half, &all) {
                missing.push(format!("{token} in `{line}`"));
            }
        }
    }
    assert!(count >= 30, "only {count} numbers read");
    assert!(
        missing.is_empty(),
        "shown but not in compare.json: {missing:#?}"
    );
    // One overall score: the verdict's best over the regimes is the table's lowest mean.
    let best = json["ranking"]["overall"][0]["score"].as_f64().unwrap();
    assert!(report.contains(&format!("{best:.3}")), "{best}");
}

#[test]
fn the_number_reader_sees_signs_exponents_and_skips_labels() {
    let got: Vec<f64> =
        shown("`power_law#2` ΔAIC +7151.3, k3 = 2.0012e4 ± 2.3e1; stage 1 S 0.0025")
            .into_iter()
            .map(|t| t.1)
            .collect();
    assert_eq!(got, [7151.3, 2.0012e4, 23.0, 0.0025]);
    let grouped: Vec<f64> = shown("k3 = 19 987 ± 11 over 475 cycles, 10 004.5 ± 0.5")
        .into_iter()
        .map(|t| t.1)
        .collect();
    assert_eq!(grouped, [19987.0, 11.0, 475.0, 10004.5, 0.5]);
    assert!(traced(0.0200, 0.00005, &[0.0199862]));
    assert!(!traced(0.0200, 0.00005, &[0.0201]));
    assert!(traced(41.69, 0.005, &[0.041689]));
}
