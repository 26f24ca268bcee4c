//! The reports of the bundled examples as a reader gets them: every command that fits writes
//! a report that opens with its verdict; every figure's PNG is free of marks outside its
//! shapes (the bitmap backend's spikes at line joins); motion is in mm and mm/s with a unit on
//! every axis and no `-0` tick; `params.csv` sits beside `fit.json`; and no number in a JSON
//! result carries arithmetic residue (more than 15 significant digits).

mod common;

use std::path::Path;

use common::{read_json, root, run_ok};
use stf_lab::report::{print_problems, stray_coloured_pixels, MIN_TEXT_PT};

/// Every figure under `dir/figures`: its PNG clean, its tick labels never `-0`, every text at
/// least 8 pt at the print width the SVG states and inside the canvas.
fn check_figures(dir: &Path) -> usize {
    let mut count = 0;
    for entry in std::fs::read_dir(dir.join("figures")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "svg") {
            let svg = std::fs::read_to_string(&path).unwrap();
            let png = std::fs::read(path.with_extension("png")).unwrap();
            let stray = stray_coloured_pixels(&svg, &png, 3.0).unwrap();
            assert_eq!(stray, 0, "{}: {stray} stray pixels", path.display());
            let problems = print_problems(&svg, MIN_TEXT_PT).unwrap();
            assert!(
                problems.is_empty(),
                "{}: {}",
                path.display(),
                problems.join("; ")
            );
            let texts: Vec<&str> = svg.lines().map(str::trim).collect();
            for bad in ["-0", "-0.0", "-0.00", "-0.000"] {
                assert!(!texts.contains(&bad), "{}: a {bad} tick", path.display());
            }
            count += 1;
        }
    }
    count
}

/// The numbers of a JSON text with more than 15 significant digits.
fn noisy_numbers(json: &str) -> Vec<String> {
    fn walk(v: &serde_json::Value, out: &mut Vec<String>) {
        match v {
            serde_json::Value::Number(n) if n.is_f64() => {
                let t = n.to_string();
                let mantissa = t.split(['e', 'E']).next().unwrap_or("");
                let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
                if digits.trim_start_matches('0').len() > 15 {
                    out.push(t);
                }
            }
            serde_json::Value::Array(a) => a.iter().for_each(|v| walk(v, out)),
            serde_json::Value::Object(o) => o.values().for_each(|v| walk(v, out)),
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(&serde_json::from_str(json).unwrap(), &mut out);
    out
}

fn header(csv: &Path) -> String {
    std::fs::read_to_string(csv)
        .unwrap()
        .lines()
        .next()
        .unwrap()
        .to_string()
}

#[test]
fn fit_writes_a_verdict_clean_figures_in_mm_and_a_parameter_table() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("pl");
    run_ok("fit", &root().join("experiments/power_law_fit.toml"), &out);
    assert!(check_figures(&out) >= 5);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let verdict = md.lines().nth(2).unwrap();
    assert!(verdict.starts_with("Best fit: `power_law`"), "{verdict}");
    let figures = out.join("figures");
    assert!(header(&figures.join("hysteresis_x.csv")).contains("displacement x, mm"));
    assert!(header(&figures.join("hysteresis_v.csv")).contains("velocity v, mm/s"));
    let th = header(&figures.join("time_history.csv"));
    assert!(th.contains("x, mm") && th.contains("v, mm/s"), "{th}");

    let text = std::fs::read_to_string(out.join("fit.json")).unwrap();
    assert_eq!(noisy_numbers(&text), Vec::<String>::new());
    // params.csv: one row per parameter, with the value and error of fit.json and a unit.
    let fit = read_json(&out.join("fit.json"));
    let csv = std::fs::read_to_string(out.join("params.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("model,parameter,value,std_error,unit,fixed,at_bound")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let pl = &fit["models"][1];
    assert_eq!(pl["name"], "power_law");
    let k_row = rows
        .iter()
        .find(|r| r[0] == "power_law" && r[1] == "K")
        .unwrap();
    assert_eq!(
        k_row[2].parse::<f64>().unwrap(),
        pl["params"]["K"].as_f64().unwrap()
    );
    assert_eq!(
        k_row[3].parse::<f64>().unwrap(),
        pl["std_errors"]["K"].as_f64().unwrap()
    );
    assert!(k_row[4].starts_with('N'), "{k_row:?}");
    let n_row = rows
        .iter()
        .find(|r| r[0] == "power_law" && r[1] == "n")
        .unwrap();
    assert_eq!(&n_row[4..], ["", "false", "false"]);
}

#[test]
fn the_identification_writes_a_report_and_prints_a_readable_system() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("id");
    let run = run_ok(
        "fit",
        &root().join("experiments/paper_identification.toml"),
        &out,
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("identified system:"))
        .unwrap();
    assert!(!line.contains('{') && line.contains(" N/m"), "{line}");
    // Each stage's line gives every value with its unit.
    let stage = |n: usize| {
        let head = format!("stage {n} (");
        stdout
            .lines()
            .find(|l| l.starts_with(&head))
            .unwrap_or_else(|| panic!("no {head} in\n{stdout}"))
            .to_string()
    };
    for unit in [" N/m", " N·s/m", " N"] {
        assert!(stage(1).contains(unit), "{unit} not in {}", stage(1));
    }
    assert!(stage(2).contains(" kg·m"), "{}", stage(2));
    // Each stage over time, and the swept stage's frequency response.
    assert_eq!(check_figures(&out), 3);
    assert!(out.join("figures/frequency_response_stage_2.svg").is_file());
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("Identified oscillator: m 7.65 kg, k 269.9"),
        "{md}"
    );
    // Each stage's table has a unit column.
    assert!(
        md.contains("| parameter | value ± standard error | unit |") && md.contains("| kg·m |"),
        "{md}"
    );
    let csv = std::fs::read_to_string(out.join("params.csv")).unwrap();
    assert!(
        csv.contains("stage 2,F0,") && csv.contains(",kg·m,"),
        "{csv}"
    );
    let text = std::fs::read_to_string(out.join("fit.json")).unwrap();
    assert_eq!(noisy_numbers(&text), Vec::<String>::new());
}

#[test]
fn compare_and_discover_reports_open_with_their_verdicts() {
    let tmp = tempfile::tempdir().unwrap();
    let cmp = tmp.path().join("cmp");
    run_ok(
        "compare",
        &root().join("experiments/jamming_compare.toml"),
        &cmp,
    );
    assert!(check_figures(&cmp) >= 7);
    let md = std::fs::read_to_string(cmp.join("report.md")).unwrap();
    assert!(
        md.lines()
            .nth(2)
            .unwrap()
            .starts_with("Models ranked in each regime"),
        "{md}"
    );
    assert!(md.contains("The duty of a cycle is"), "duty unexplained");
    assert!(header(&cmp.join("figures/frequency_response.csv")).contains("local maximum of x, mm"));
    // The resonance window sits at the amplitude peak compare.json states, and says so; the
    // zero-force level and the boundaries' spread over it are stated in both.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(cmp.join("compare.json")).unwrap()).unwrap();
    let measured = &json["measured"];
    let peak = measured["resonance"]["peak_omega_rad_s"].as_f64().unwrap();
    let line = md
        .lines()
        .find(|l| l.starts_with("resonance (ω "))
        .unwrap_or_else(|| panic!("no resonance window:\n{md}"));
    let span = line["resonance (ω ".len()..]
        .split(" rad/s")
        .next()
        .unwrap();
    let (lo, hi) = span.split_once('–').unwrap();
    let (lo, hi): (f64, f64) = (lo.parse().unwrap(), hi.parse().unwrap());
    assert!(
        lo - 0.01 <= peak && peak <= hi + 0.01,
        "peak {peak} outside {line}"
    );
    assert!(line.contains("around the amplitude peak"), "{line}");
    let zero = &measured["zero_level"];
    assert_eq!(zero["zero_level"], measured["on_threshold"]);
    assert_eq!(zero["at_levels"].as_array().unwrap().len(), 2);
    assert!(md.contains("zero force level"), "{md}");

    for (example, first) in [
        ("experiments/discovery.toml", "Named: `cubic_stiffness`."),
        (
            "experiments/trajectory_discovery.toml",
            "Named: `cubic_stiffness`.",
        ),
    ] {
        let out = tmp.path().join(example.replace('/', "_"));
        run_ok("discover", &root().join(example), &out);
        check_figures(&out);
        let md = std::fs::read_to_string(out.join("report.md")).unwrap();
        assert!(md.lines().nth(2).unwrap().starts_with(first), "{md}");
        // No paragraph is said twice.
        let paragraphs: Vec<&str> = md.split("\n\n").filter(|p| p.len() > 40).collect();
        for (i, p) in paragraphs.iter().enumerate() {
            assert!(!paragraphs[..i].contains(p), "said twice: {p}");
        }
        let text = std::fs::read_to_string(out.join("discovery.json")).unwrap();
        assert_eq!(noisy_numbers(&text), Vec::<String>::new(), "{example}");
    }
    // The shaker's chirp runs 0.5 → 1.5 Hz (3.14 → 9.42 rad/s): the residual is located at
    // speeds the drive reached (the x cycles' own 2π/duration had said 10.05 rad/s).
    let md = std::fs::read_to_string(
        tmp.path()
            .join("experiments_trajectory_discovery.toml")
            .join("report.md"),
    )
    .unwrap();
    let located = md.split("largest at ω ").nth(1).unwrap();
    let (lo, rest) = located.split_once('–').unwrap();
    let hi = rest.split_once(' ').unwrap().0;
    let (lo, hi): (f64, f64) = (lo.parse().unwrap(), hi.parse().unwrap());
    assert!(3.1 <= lo && hi <= 9.43, "ω {lo}–{hi} rad/s");
}
