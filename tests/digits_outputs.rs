//! The digits of every bundled example's outputs, as the README promises them: every bundled
//! experiment (`experiments/*.toml`, run by the command it is written for, and the bundled
//! campaign) is run and every file it writes is scanned. In tables and JSON (`*.csv`,
//! `*.json`) a number carries at most 15 significant digits and is never `-0`, `-0.0` or
//! written with an exponent `e0` (a figure's data hold the samples drawn exactly: only the
//! last two rules); what a person reads (`report.md`,
//! `compare.md`, the terminal, the printed experiment entries) has no negative zero, no `NaN`,
//! no exponent where a plain number reads (`1.0004e4 ± 8.1e0` is `10 004 ± 8`) and no number of
//! more than 15 digits (`K = 6.9063702810500684`). A printed entry pasted into an experiment
//! file loads and its fit lands where the discovery ended; the equation of the final force
//! is written with the values the JSON holds, rounded to their errors.

mod common;

use std::path::{Path, PathBuf};

use common::{root, run_ok, stf_lab, succeeded};

/// Why `cell` is not a number as the outputs promise to write it, if it is not.
fn bad_number(cell: &str) -> Option<&'static str> {
    let is_number = !cell.is_empty()
        && cell
            .chars()
            .all(|c| c.is_ascii_digit() || "-+.e".contains(c))
        && cell.parse::<f64>().is_ok();
    if !is_number {
        return None;
    }
    let mantissa = cell.split('e').next().unwrap_or_default();
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    let significant = digits.trim_start_matches('0').len();
    if significant > 15 {
        Some("more than 15 significant digits")
    } else if cell.parse::<f64>().unwrap() == 0.0 && cell.starts_with('-') {
        Some("a negative zero")
    } else if cell.ends_with("e0") || cell.contains("e-0") || cell.contains("e+") {
        Some("a padded exponent")
    } else {
        None
    }
}

/// Why `token`, a number in text a person reads, is not written as the reports promise:
/// [`bad_number`], or an exponent where the number reads plainly (10⁻³ to 10⁶).
fn bad_shown(token: &str) -> Option<&'static str> {
    if let Some(why) = bad_number(token) {
        return Some(why);
    }
    let exponent = token
        .split_once('e')
        .and_then(|(_, e)| e.parse::<i32>().ok());
    match exponent {
        Some(e) if (-3..=5).contains(&e) => Some("an exponent where a plain number reads"),
        _ => None,
    }
}

/// The numbers of `text`: runs of digits, `.`, a sign before them and an exponent after,
/// standing alone (not part of a name such as `stage_1`, `x3` or a hash).
fn tokens(text: &str) -> Vec<String> {
    let chars: Vec<char> = text.chars().collect();
    let mut found = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let prev = if i > 0 { chars[i - 1] } else { ' ' };
        if !chars[i].is_ascii_digit() || prev.is_alphanumeric() || "_.#/".contains(prev) {
            i += 1;
            continue;
        }
        let from = if prev == '-' { i - 1 } else { i };
        let mut j = i;
        while j < chars.len() && (chars[j].is_ascii_digit() || chars[j] == '.') {
            j += 1;
        }
        if j + 1 < chars.len() && chars[j] == 'e' {
            let mut k = j + 1;
            if chars[k] == '-' || chars[k] == '+' {
                k += 1;
            }
            let start = k;
            while k < chars.len() && chars[k].is_ascii_digit() {
                k += 1;
            }
            if k > start {
                j = k;
            }
        }
        let next = chars.get(j).copied().unwrap_or(' ');
        if !(next.is_alphanumeric() || next == '_') {
            let t: String = chars[from..j].iter().collect();
            found.push(t.trim_end_matches('.').to_string());
        }
        i = j.max(i + 1);
    }
    found
}

/// Every problem in the text `text` of `name` a person reads.
fn shown_problems(name: &str, text: &str) -> Vec<String> {
    let mut problems = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line
            .split(|c: char| !c.is_alphanumeric())
            .any(|w| w == "NaN")
        {
            problems.push(format!("{name}:{}: NaN in `{line}`", i + 1));
        }
        for t in tokens(line) {
            if let Some(why) = bad_shown(&t) {
                problems.push(format!("{name}:{}: `{t}` has {why}", i + 1));
            }
        }
    }
    problems
}

/// Every problem in a table or JSON file `name` (numbers as written there).
fn table_problems(name: &str, text: &str) -> Vec<String> {
    let mut problems = Vec::new();
    for (i, line) in text.lines().enumerate() {
        for t in tokens(line) {
            if let Some(why) = bad_number(&t) {
                problems.push(format!("{name}:{}: `{t}` has {why}", i + 1));
            }
        }
    }
    problems
}

/// Every file under `dir`, recursively.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(files(&path));
        } else {
            out.push(path);
        }
    }
    out
}

/// Scan every output under `out` and the terminal text `terminal`; panic listing the problems.
/// Returns how many files were read.
fn scan(out: &Path, terminal: &str) -> usize {
    let mut problems = shown_problems("terminal", terminal);
    let mut read = 0;
    for path in files(out) {
        let name = path.strip_prefix(out).unwrap().display().to_string();
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        let text = match ext {
            "csv" | "json" | "md" | "log" | "toml" => std::fs::read_to_string(&path).unwrap(),
            _ => continue,
        };
        read += 1;
        problems.extend(match ext {
            "md" | "log" => shown_problems(&name, &text),
            // A figure's data are the samples drawn, exactly: only their signs and exponents.
            "csv" if name.starts_with("figures") || name.contains("/figures/") => {
                let mut found = table_problems(&name, &text);
                found.retain(|p| !p.ends_with("more than 15 significant digits"));
                found
            }
            _ => table_problems(&name, &text),
        });
    }
    assert!(
        problems.is_empty(),
        "{} problem(s), the first:\n{}",
        problems.len(),
        problems[..problems.len().min(30)].join("\n")
    );
    read
}

/// Run `command` on the bundled `experiment` into a fresh folder; scan what it wrote and
/// printed. Returns the folder (kept alive by the returned guard).
fn run_and_scan(command: &str, experiment: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let output = stf_lab()
        .args([command, "--out"])
        .arg(&out)
        .arg(root().join("experiments").join(experiment))
        .output()
        .unwrap();
    let output = succeeded(output);
    let terminal = format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    let read = scan(&out, &terminal);
    assert!(read >= 5, "{experiment}: only {read} files read");
    (dir, out)
}

/// The numbers of an equation (digit groups `19 987` joined) with the half-width of the
/// rounding each was written with.
fn equation_numbers(equation: &str) -> Vec<(f64, f64)> {
    let joined = equation.replace('\u{a0}', " ");
    let mut out = Vec::new();
    let words: Vec<&str> = joined.split(' ').collect();
    let mut i = 0;
    while i < words.len() {
        let mut word = words[i].to_string();
        while i + 1 < words.len()
            && word.chars().last().is_some_and(|c| c.is_ascii_digit())
            && words[i + 1].len() >= 3
            && words[i + 1][..3].chars().all(|c| c.is_ascii_digit())
        {
            word.push_str(words[i + 1]);
            i += 1;
        }
        for t in tokens(&word.replace('^', " ")) {
            let (mantissa, exp) = match t.split_once('e') {
                Some((m, e)) => (m.to_string(), e.parse::<i32>().unwrap()),
                None => (t.clone(), 0),
            };
            let decimals = mantissa.split('.').nth(1).map_or(0, str::len) as i32;
            let value: f64 = t.parse().unwrap();
            out.push((value, 0.5 * 10f64.powi(exp - decimals)));
        }
        i += 1;
    }
    out
}

/// Each number of `equation` is one of `values`, as rounded (in the model's order).
fn equation_traces(equation: &str, values: &[f64]) {
    let numbers = equation_numbers(equation);
    assert_eq!(numbers.len(), values.len(), "{equation}: {numbers:?}");
    for ((shown, half), value) in numbers.iter().zip(values) {
        assert!(
            (shown - value).abs() <= half * (1.0 + 1e-9),
            "{equation}: {shown} is not {value} rounded"
        );
    }
}

#[test]
fn the_scanner_finds_what_it_looks_for() {
    assert_eq!(
        bad_number("0.00015500000000000003"),
        Some("more than 15 significant digits")
    );
    assert_eq!(bad_number("-0.0"), Some("a negative zero"));
    assert_eq!(bad_number("1.5e0"), Some("a padded exponent"));
    for fine in [
        "0.000155",
        "6.204",
        "-41.69",
        "1e300",
        "2.5e-7",
        "power_law",
        "",
    ] {
        assert_eq!(bad_number(fine), None, "{fine}");
    }
    let text =
        "k3 = 1.0004e4 ± 8.1e0, ΔAIC -0.0, K = 6.9063702810500684, z NaN, `stage_1` x0 2.6e-8";
    let problems = shown_problems("t", text);
    assert_eq!(problems.len(), 5, "{problems:#?}");
    assert_eq!(
        tokens("a 10 004 ± 8, x3 = 2, f_off -0 at 1e-4."),
        ["10", "004", "8", "2", "-0", "1e-4"]
    );
    assert_eq!(
        equation_numbers("F_STF = 4.01·|v|^1.501·sgn v + 19 987·x³"),
        [(4.01, 0.005), (1.501, 0.0005), (19987.0, 0.5)]
    );
}

#[test]
fn the_fit_example_s_outputs_carry_the_promised_digits_and_its_equations() {
    let (_dir, out) = run_and_scan("fit", "power_law_fit.toml");
    let doc = common::read_json(&out.join("fit.json"));
    let power_law = &doc["models"][1];
    assert_eq!(power_law["name"], "power_law");
    let eq = power_law["equation"].as_str().unwrap();
    assert!(eq.starts_with("F_STF = ") && eq.contains("·|v|^"), "{eq}");
    let p = &power_law["params"];
    equation_traces(eq, &[p["K"].as_f64().unwrap(), p["n"].as_f64().unwrap()]);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains(eq), "the report does not write {eq}");
}

#[test]
fn the_identification_example_s_outputs_carry_the_promised_digits() {
    run_and_scan("fit", "paper_identification.toml");
}

#[test]
fn the_compare_example_s_outputs_carry_the_promised_digits() {
    let (_dir, out) = run_and_scan("compare", "jamming_compare.toml");
    // Each built-in model writes its own law (with its bounds widened to the record or not),
    // never a named term.
    let doc = common::read_json(&out.join("compare.json"));
    for m in doc["models"].as_array().unwrap() {
        let (name, eq) = (m["name"].as_str().unwrap(), &m["fit"]["equation"]);
        let eq = eq.as_str().unwrap_or_default();
        assert!(
            eq.starts_with("F_STF = ") && !eq.contains(&format!("F_{name}(")),
            "{name}: {eq}"
        );
    }
    for table in ["compare.csv", "cycles.csv"] {
        let text = std::fs::read_to_string(out.join(table)).unwrap();
        assert!(text.split(',').count() > 20, "{table}");
    }
}

#[test]
fn the_trajectory_discovery_example_s_outputs_carry_the_promised_digits() {
    run_and_scan("discover", "trajectory_discovery.toml");
}

#[test]
fn the_simulation_example_s_summary_carries_the_promised_digits() {
    let dir = tempfile::tempdir().unwrap();
    let record = dir.path().join("sweep.csv");
    let output = common::simulate(&root().join("experiments/paper_sweep.toml"), &record, &[]);
    let output = succeeded(output);
    // The record itself keeps every double exactly, its sign of zero too (read back, it is
    // the simulation bit for bit); its JSON and what is printed follow the rules.
    let mut problems = shown_problems("terminal", &String::from_utf8_lossy(&output.stdout));
    let json = std::fs::read_to_string(record.with_extension("json")).unwrap();
    problems.extend(table_problems("sweep.json", &json));
    assert!(problems.is_empty(), "{problems:#?}");
}

#[test]
fn the_campaign_example_s_outputs_carry_the_promised_digits() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("campaign");
    let output = stf_lab()
        .args(["campaign", "--quiet", "--out"])
        .arg(&out)
        .arg(root().join("experiments/campaign/campaign.toml"))
        .output()
        .unwrap();
    let output = succeeded(output);
    let read = scan(&out, &String::from_utf8_lossy(&output.stdout));
    assert!(read >= 20, "only {read} files read");
}

/// The discovery example: its outputs' digits, its final force as an equation of the values
/// `discovery.json` holds, and its printed entry (15 digits) pasted into an experiment file
/// loads and refits to where the discovery ended.
#[test]
fn the_discovery_example_s_entry_and_equation_reproduce_its_fit() {
    let (dir, out) = run_and_scan("discover", "discovery.toml");
    let doc = common::read_json(&out.join("discovery.json"));
    let fm = &doc["final_model"];
    let value = |name: &str| fm["params"][name].as_f64().unwrap();
    let eq = fm["equation"].as_str().unwrap();
    equation_traces(eq, &[value("K"), value("n"), value("k3")]);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains(eq), "the report does not write {eq}");

    let entry = fm["experiment_entry"].as_str().unwrap();
    let parsed: toml::Table = toml::from_str(entry).unwrap();
    let params = parsed["models"][0]["params"].as_table().unwrap();
    for (name, v) in params {
        let text = v.to_string();
        assert_eq!(bad_number(&text), None, "{name} = {text}");
        assert!(
            (v.as_float().unwrap() / value(name) - 1.0).abs() < 1e-14,
            "{name}"
        );
    }
    let record = root().join("experiments/records/discovery_sweep.csv");
    let exp = dir.path().join("refit.toml");
    let text = format!(
        "[data]\nfile = {:?}\n\n{entry}",
        record.display().to_string()
    );
    std::fs::write(&exp, text).unwrap();
    let refit = dir.path().join("refit");
    run_ok("fit", &exp, &refit);
    let fit = common::read_json(&refit.join("fit.json"));
    let m = &fit["models"][0];
    for name in ["K", "n", "k3"] {
        let (x, se) = (
            m["params"][name].as_f64().unwrap(),
            m["std_errors"][name].as_f64().unwrap(),
        );
        assert!(
            (x - value(name)).abs() <= 0.5 * se,
            "{name}: refit {x} ± {se} against the discovery's {}",
            value(name)
        );
    }
}
