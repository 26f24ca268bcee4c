//! Trajectory-level discovery on a rotor rig without a force sensor: records with t, φ and x
//! only, made by `stf-lab simulate` with the rig's default sensors (x noise 0.05 mm quantised
//! to 0.01 mm, a 2048-count encoder), a sweep ω 3 → 9.4 rad/s at 0.1 rad/s² sampled at 200 Hz
//! (15 held-out cycles), truth power law K 20, n 1.5 plus one hidden effect. From the power law
//! alone, discovery names exactly the hidden effect — or nothing — and the x residual after
//! is within 1.2× the noise.
//!
//! `yield` (≈ F_y·sign v) has nearly the form of the bearing's Coulomb friction T, which is
//! refitted: a yield force of 0.3 N is named, one of 0.2 N is mostly absorbed by T (0.54 →
//! 0.70 N) and the step says its "nothing is missing" is not to be trusted, naming `yield` as
//! the candidate that came closest.

mod common;

use common::{read_json, run_ok, simulate_ok};

/// The x noise RMS of the records, mm (0.05 mm Gaussian, quantised to 0.01 mm).
const X_NOISE_MM: f64 = 0.0501;

/// The CI records: ω 3 → 9.4 rad/s at 0.1 rad/s², 200 Hz.
const SHORT: &str = "sweep = { w0 = 3.0, alpha = 0.1, t0 = 0.0, t1 = 64.0 }\nrate = 200.0";

/// The source study's sweep: ω = 0.047·t for t 50 → 200 s at 1 kHz (150 001 samples).
const PAPER: &str = "sweep = { w0 = 2.35, alpha = 0.047, t0 = 50.0, t1 = 200.0 }\nrate = 1000.0";

/// Simulate the truth `power_law` + `hidden` (seed `seed`) on the CI sweep, drop every column
/// but t, φ and x, and discover from `power_law`; discovery.json.
fn discover(hidden: Option<(&str, &str)>, seed: u64, refit: Option<&str>) -> serde_json::Value {
    discover_on(SHORT, hidden, seed, refit)
}

/// [`discover`] on the record `sweep` (the `[simulate]` lines of its sweep and rate).
fn discover_on(
    sweep: &str,
    hidden: Option<(&str, &str)>,
    seed: u64,
    refit: Option<&str>,
) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let (plus, extra) = hidden.map_or((String::new(), ""), |(name, params)| {
        (format!("plus = [\"{name}\"]\n"), params)
    });
    let fit = refit.map_or(String::new(), |r| format!("[fit]\nsystem = {r}\n\n"));
    let exp = dir.path().join("e.toml");
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = \"r.csv\"\n\n{fit}[simulate]\n{sweep}\n\
             noise = true\nseed = {seed}\n\n[[simulate.truth]]\nname = \"power_law\"\n{plus}\
             params = {{ K = 20.0, n = 1.5{extra} }}\n\n[discover]\nbase = \"power_law\"\n\
             level = \"trajectory\"\n"
        ),
    )
    .unwrap();
    let record = dir.path().join("r.csv");
    simulate_ok(&exp, &record);
    keep_columns(&record, &["t", "phi", "x"]);
    let out = dir.path().join("disc");
    run_ok("discover", &exp, &out);
    let d = read_json(&out.join("discovery.json"));
    assert_eq!(d["level"], "trajectory");
    d
}

/// Rewrite the CSV `path` with only the columns `keep` (a record without a force sensor).
fn keep_columns(path: &std::path::Path, keep: &[&str]) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let idx: Vec<usize> = keep
        .iter()
        .map(|k| header.iter().position(|h| h == k).unwrap())
        .collect();
    let mut out = keep.join(",") + "\n";
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        out += &idx.iter().map(|&i| cells[i]).collect::<Vec<_>>().join(",");
        out.push('\n');
    }
    std::fs::write(path, out).unwrap();
    assert!(!std::fs::read_to_string(path).unwrap().contains("f_stf"));
}

fn effects(d: &serde_json::Value) -> Vec<String> {
    d["effects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_str().unwrap().to_string())
        .collect()
}

fn assert_at_the_noise(d: &serde_json::Value) {
    let rms_mm = d["s_after_mm2"].as_f64().unwrap().sqrt();
    assert!(
        rms_mm <= 1.2 * X_NOISE_MM,
        "x residual after {rms_mm} mm against {X_NOISE_MM} mm of noise"
    );
}

#[test]
fn nothing_hidden_nothing_named() {
    for seed in [1, 2, 3] {
        let d = discover(None, seed, None);
        assert!(effects(&d).is_empty(), "seed {seed}: {:?}", d["notes"]);
        assert_at_the_noise(&d);
    }
}

/// The first step fitted three candidates at trajectory level and said of each other one that
/// the force-level screen left it out (the recovered force asks for the hidden effect).
fn assert_screened(d: &serde_json::Value) {
    for step in d["steps"].as_array().unwrap().iter().take(1) {
        let candidates = step["candidates"].as_array().unwrap();
        let left_out = candidates
            .iter()
            .filter(|c| {
                c["failure"]
                    .as_str()
                    .is_some_and(|f| f.starts_with("not fitted at trajectory level"))
            })
            .count();
        assert_eq!(left_out, candidates.len().saturating_sub(3), "{step}");
    }
}

#[test]
fn a_hidden_cubic_spring_is_named() {
    let d = discover(Some(("cubic_stiffness", ", k3 = 1e4")), 5, None);
    assert_eq!(effects(&d), ["cubic_stiffness"], "{:?}", d["notes"]);
    assert_at_the_noise(&d);
}

#[test]
fn a_hidden_added_mass_is_named() {
    let d = discover(Some(("added_mass", ", m_a = 0.5")), 5, None);
    assert_eq!(effects(&d), ["added_mass"], "{:?}", d["notes"]);
    assert_at_the_noise(&d);
    assert_screened(&d);
}

#[test]
fn a_hidden_yield_is_named() {
    let d = discover(Some(("yield", ", F_y = 0.3")), 5, None);
    assert_eq!(effects(&d), ["yield"], "{:?}", d["notes"]);
    assert_at_the_noise(&d);
}

#[test]
fn a_yield_the_bearing_friction_absorbs_is_flagged_not_denied() {
    let d = discover(Some(("yield", ", F_y = 0.2")), 5, None);
    let notes: Vec<&str> = d["notes"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|n| n.as_str())
        .collect();
    let flagged = notes
        .iter()
        .any(|n| n.starts_with("not to be trusted") && n.contains("`yield` comes closest"));
    assert!(
        effects(&d) == ["yield"] || flagged,
        "neither named nor flagged: {notes:?}"
    );
}

/// The full set on the source study's sweep (150 001 samples; about a minute or two each):
/// `cargo test --release --test discover_rotor_trajectory -- --ignored`.
#[test]
#[ignore]
fn on_the_papers_sweep_exactly_the_hidden_effect_is_named() {
    for seed in [1, 2, 3] {
        let d = discover_on(PAPER, None, seed, None);
        assert!(effects(&d).is_empty(), "seed {seed}: {:?}", d["notes"]);
        assert_at_the_noise(&d);
    }
    let cases = [
        ("cubic_stiffness", ", k3 = 1e4", None),
        ("added_mass", ", m_a = 0.5", None),
        ("yield", ", F_y = 0.3", None),
        ("yield", ", F_y = 0.3", Some("[\"k\", \"c\"]")),
    ];
    for (name, params, refit) in cases {
        let d = discover_on(PAPER, Some((name, params)), 5, refit);
        assert_eq!(effects(&d), [name], "{:?}", d["notes"]);
        assert_at_the_noise(&d);
    }
}

/// The parameters of each built-in candidate, to read a candidate's training RSS against the
/// current model's from its ΔAIC (N·ln(RSS/N) + 2p).
fn own_params(name: &str) -> f64 {
    let model = stf_models::find(name).unwrap_or_else(|| panic!("unknown candidate {name}"));
    model.params().len() as f64
}

/// A small Maxwell element hidden beside the power law (c_m 1 N·s/m, τ 0.05 s; t, φ, x
/// only, the scouted CI record at two seeds): no candidate that was fitted ends with a
/// training RSS above the model it extends (each starts, among its starts, from that
/// model's optimum with its own term neutral), and `maxwell` is named. (On a record of an
/// independent implementation of the rig, every candidate's scout fit ended above the
/// base's training RMS and nothing was named.)
#[test]
fn a_small_hidden_maxwell_element_is_named_and_no_candidate_ends_worse_than_its_base() {
    for seed in [1, 2] {
        let d = discover(Some(("maxwell", ", c_m = 1.0, tau = 0.05")), seed, None);
        for step in d["steps"].as_array().unwrap() {
            for c in step["candidates"].as_array().unwrap() {
                let Some(delta_aic) = c["delta_aic"].as_f64() else {
                    continue;
                };
                let name = c["name"].as_str().unwrap();
                let rss_term = delta_aic - 2.0 * own_params(name);
                // Within the neutral term's own contribution and the fit's tolerance: a
                // relative RSS excess of 5e-6 over 10 000 training samples; the failure seen
                // was 8.5 % (N·ln 1.085 ≈ 800).
                assert!(
                    rss_term <= 0.05,
                    "seed {seed}: `{name}` ends above the model it extends: N·ln(RSS ratio) \
                     {rss_term}\n{c}"
                );
            }
        }
        assert_eq!(effects(&d), ["maxwell"], "seed {seed}: {}", d["verdict"]);
        assert_at_the_noise(&d);
    }
}
