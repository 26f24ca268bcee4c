//! The regime boundaries of `compare` against the truth, on records made by `stf-lab simulate`
//! with the rig's sensors (noise on x and F_STF, x quantised, φ from a 2048-count encoder).
//!
//! For each truth (`power_law`, `jamming_on_off`, `wall_impact`, at their defaults) and each of the source study's
//! sweep rates (0.0333 and 0.047 rad/s², ω 3 → 14 rad/s at 100 Hz) the same experiment is
//! simulated twice: with the sensors (the record `compare` classifies, through the program's own
//! loading, filters and cycles) and without them (the truth). From the noise-free truth the test
//! finds, cycle by cycle of its exact φ, where its force crosses the study's definitions: its
//! peak passes 0.2 N (pre → resonance); after being on for at least half a cycle, it is zero
//! (|F| ≤ 3 σ of the force sensor, 0.06 N) for more than half of the cycle, or falls back to
//! ≤ 0.2 N (resonance → post). A crossing counts where the truth holds the new behaviour for
//! three cycles running; its ω is the mean of the two cycles around it. The classifier's
//! boundaries must lie within 0.1 rad/s of these, with the same rule, or both be absent.
//!
//! `cargo test --release --test regime_boundaries -- --nocapture` prints the table of errors.

mod common;

use std::path::Path;

use common::{csv_column, simulate_ok};
use stf_core::regimes::{cycles_from_phase, duty, Boundary, BoundaryRule, RegimeThresholds};
use stf_lab::experiment::Experiment;
use stf_lab::fitting::load_data;
use stf_study::compare::measured_regimes;

/// The force sensor's σ of the rig (`SensorNoise::RIG`), N.
const SENSOR_SIGMA: f64 = 0.02;
const TOLERANCE: f64 = 0.1;

struct Case {
    model: &'static str,
    /// The `[[simulate.truth]]` tables.
    truth: &'static str,
    alpha: f64,
    seed: u64,
}

fn experiment(dir: &Path, case: &Case, noise: bool) -> std::path::PathBuf {
    let name = format!("{}_{}_{}", case.model.replace(' ', ""), case.alpha, noise);
    let path = dir.join(format!("{name}.toml"));
    let text = format!(
        "[data]\nfile = \"{name}.csv\"\n\n[simulate]\nsweep = {{ w0 = 3.0, alpha = {a}, t0 = 0.0, t1 = {t1} }}\nrate = 100.0\nnoise = {noise}\nseed = {seed}\n\n{truth}\n\n[[models]]\nname = \"viscous\"\n",
        a = case.alpha,
        t1 = 11.0 / case.alpha,
        seed = case.seed,
        truth = case.truth,
    );
    std::fs::write(&path, text).unwrap();
    simulate_ok(&path, &dir.join(format!("{name}.csv")));
    path
}

/// Where the noise-free truth crosses the definitions: (ω, rule) of each boundary.
type Crossings = (Option<f64>, Option<(f64, BoundaryRule)>);

fn truth_crossings(record: &Path) -> Crossings {
    let (t, phi, f) = (
        csv_column(record, "t"),
        csv_column(record, "phi"),
        csv_column(record, "f_stf"),
    );
    let th = RegimeThresholds::default();
    let (level, on) = (
        th.negligible_level(SENSOR_SIGMA),
        th.on_threshold(SENSOR_SIGMA),
    );
    let cycles = cycles_from_phase(&t, &phi).unwrap();
    let omega: Vec<f64> = cycles.iter().map(|c| c.omega).collect();
    // 0: negligible, 1: on, 2: on–off.
    let kind: Vec<u8> = cycles
        .iter()
        .map(|c| {
            let s = &f[c.start..c.end];
            if s.iter().fold(0.0f64, |m, v| m.max(v.abs())) <= level {
                0
            } else if duty(s, on, th.min_off_fraction) >= th.resonance_duty {
                1
            } else {
                2
            }
        })
        .collect();
    let n = kind.len();
    let holds = |from: usize, p: &dyn Fn(u8) -> bool| {
        (from..n.saturating_sub(2)).find(|&j| (j..j + 3).all(|i| p(kind[i])))
    };
    let mid = |j: usize| 0.5 * (omega[j - 1] + omega[j]);
    let Some(j1) = holds(1, &|k| k != 0) else {
        return (None, None);
    };
    let post = match holds(j1, &|k| k == 1) {
        None => Some((mid(j1), BoundaryRule::OnOffFromOnset)),
        Some(on_from) => holds(on_from, &|k| k != 1).map(|j2| {
            let rule = if kind[j2] == 0 {
                BoundaryRule::ForceGone
            } else {
                BoundaryRule::OnOff
            };
            (mid(j2), rule)
        }),
    };
    (Some(mid(j1)), post)
}

/// One row of the table and whether it passes.
fn check(
    what: &str,
    case: &Case,
    truth: Option<(f64, BoundaryRule)>,
    found: Option<Boundary>,
) -> bool {
    let show = |x: Option<(f64, BoundaryRule)>| {
        x.map_or("none".to_string(), |(w, r)| format!("{w:.3} ({r:?})"))
    };
    let found_pair = found.map(|b| (b.omega, b.rule));
    let (ok, err) = match (truth, found_pair) {
        (None, None) => (true, "—".to_string()),
        (Some((w, r)), Some((v, q))) => (
            (v - w).abs() <= TOLERANCE && r == q,
            format!("{:+.3}", v - w),
        ),
        _ => (false, "missing".to_string()),
    };
    println!(
        "| {} | {} | {} | {} | {} | {} | {} |",
        case.model,
        case.alpha,
        case.seed,
        what,
        show(truth),
        show(found_pair),
        err
    );
    ok
}

fn run_case(case: &Case) -> bool {
    let dir = tempfile::tempdir().unwrap();
    let noisy = experiment(dir.path(), case, true);
    let clean = experiment(dir.path(), case, false);
    let record = clean.with_extension("csv");
    let (pre, post) = truth_crossings(&record);
    let mut exp = Experiment::load(&noisy).unwrap();
    let data = load_data(&mut exp).unwrap();
    let c = measured_regimes(&exp, &data).unwrap();
    let b = c.boundaries;
    let a = check(
        "pre → resonance",
        case,
        pre.map(|w| (w, BoundaryRule::ForceOnset)),
        b.pre_resonance,
    );
    let z = check("resonance → post", case, post, b.resonance_post);
    a && z
}

const CASES: [(&str, &str); 3] = [
    (
        "power_law",
        "[[simulate.truth]]\nname = \"power_law\"\nparams = { K = 5.0, n = 1.6 }",
    ),
    (
        "jamming_on_off",
        "[[simulate.truth]]\nname = \"jamming_on_off\"\nparams = { K_j = 100.0, v_c = 0.05 }",
    ),
    (
        "wall_impact",
        "[[simulate.truth]]\nname = \"wall_impact\"\nparams = { k_w = 3e5, gap = 0.01 }",
    ),
];

/// Power law + wall contact: between the impacts the power law's force is 0.07–0.10 N, right at
/// the on-threshold, and the impacts raise the record's noise estimate (third differences of
/// the spikes) from the sensor's 0.02 N to ≈ 0.029 N, so the on-threshold (0.087 N) cuts through
/// that background and the measured on-fraction flickers around ½ where the truth's (threshold
/// 0.06 N) stays near 1. Known not to meet 0.1 rad/s on every seed; kept, unloosened:
/// `cargo test --release --test regime_boundaries -- --ignored --nocapture`.
#[test]
#[ignore]
fn a_force_at_the_on_threshold_between_impacts_is_not_placed_within_a_tenth() {
    let combo = (
        "power_law + wall_impact",
        "[[simulate.truth]]\nname = \"power_law\"\n\n[[simulate.truth]]\nname = \"wall_impact\"",
    );
    let failed = run_all(&[combo], &[1, 2, 3, 4]);
    assert_eq!(failed, 0, "{failed} cases outside {TOLERANCE} rad/s");
}

fn run_all(cases: &[(&'static str, &'static str)], seeds: &[u64]) -> usize {
    println!(
        "| truth | α rad/s² | seed | boundary | truth ω (rule) | found ω (rule) | error rad/s |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut failed = 0;
    for &(model, truth) in cases {
        for alpha in [0.0333, 0.047] {
            for &seed in seeds {
                let case = Case {
                    model,
                    truth,
                    alpha,
                    seed,
                };
                failed += usize::from(!run_case(&case));
            }
        }
    }
    failed
}

#[test]
fn boundaries_land_within_a_tenth_of_a_rad_s_of_the_truths_crossings() {
    let failed = run_all(&CASES, &[1, 2]);
    assert_eq!(failed, 0, "{failed} cases outside {TOLERANCE} rad/s");
}

/// Jamming with a higher critical speed, whose force is on for about half of each cycle
/// through the resonance and after it: its zero-force share crosses ½ at a shallow angle
/// (≈ 0.05 per rad/s), so the crossing is ill-conditioned in the truth itself. Known not to
/// meet 0.1 rad/s (see docs/compare.md); kept, unloosened, as the measurement:
/// `cargo test --release --test regime_boundaries -- --ignored --nocapture`.
#[test]
#[ignore]
fn a_shallow_on_off_crossing_is_not_placed_within_a_tenth() {
    let failed = run_all(
        &[
            (
                "jamming_on_off v_c 0.065",
                "[[simulate.truth]]\nname = \"jamming_on_off\"\nparams = { v_c = 0.065 }",
            ),
            (
                "jamming_on_off v_c 0.07",
                "[[simulate.truth]]\nname = \"jamming_on_off\"\nparams = { v_c = 0.07 }",
            ),
        ],
        &[1, 2],
    );
    assert_eq!(failed, 0, "{failed} cases outside {TOLERANCE} rad/s");
}

/// The zero-force level moves the resonance → post-resonance boundary (the force is "zero"
/// between its pulses below it): on an on–off jamming record with the rig's sensors, at both sweep
/// rates and two seeds, the range the comparison states (the boundary at half, once and twice
/// the level, each with its ±) holds the boundary found at levels in between (0.7× and 1.4×),
/// and the onset, which follows the negligible level, moves by less than one cycle.
#[test]
fn the_stated_zero_level_range_holds_the_boundary_at_other_levels() {
    use stf_core::regimes::{classify, zero_level_spread};
    // The default jamming law stays on to the end of the sweep; with a higher critical speed
    // it becomes on–off after the resonance (the shallow crossing above).
    let truth = "[[simulate.truth]]\nname = \"jamming_on_off\"\nparams = { v_c = 0.065 }";
    println!(
        "| α rad/s² | seed | zero level N | boundary ± | stated range | 0.7× | 1.4× | onset ω |"
    );
    for alpha in [0.0333, 0.047] {
        for seed in [1, 2] {
            let case = Case {
                model: "jamming_on_off",
                truth,
                alpha,
                seed,
            };
            let dir = tempfile::tempdir().unwrap();
            let mut exp = Experiment::load(&experiment(dir.path(), &case, true)).unwrap();
            let data = load_data(&mut exp).unwrap();
            let base = measured_regimes(&exp, &data).unwrap();
            let f = data.record.f_stf.clone().unwrap();
            let sig = data.force_data().with_force(&f);
            let z = zero_level_spread(&sig, &base.cycles, &exp.regimes, &base).unwrap();
            assert!((z.zero_level - base.on_threshold).abs() < 1e-15);
            assert!(z.zero_level_rule.contains("3σ"), "{}", z.zero_level_rule);
            let [lo, hi] = z.resonance_post_range.expect("a resonance → post boundary");
            let onset = base.boundaries.pre_resonance.expect("an onset");
            let cycle = base.cycles.get(onset.cycle).map_or(f64::NAN, |c| {
                (c.omega - base.cycles[onset.cycle - 1].omega).abs()
            });
            let mut found = Vec::new();
            for factor in [0.7, 1.4] {
                let th = RegimeThresholds {
                    noise_sigma: Some(base.noise_sigma),
                    on_k: exp.regimes.on_k * factor,
                    on_min: exp.regimes.on_min * factor,
                    ..exp.regimes.clone()
                };
                let c = classify(&sig, base.cycles.clone(), &th).unwrap();
                let post = c
                    .boundaries
                    .resonance_post
                    .expect("a boundary at this level");
                assert!(
                    (lo..=hi).contains(&post.omega),
                    "α {alpha}, seed {seed}: at {factor}× the boundary is at {:.3}, outside the \
                     stated {lo:.3}–{hi:.3}",
                    post.omega
                );
                let o = c.boundaries.pre_resonance.expect("an onset").omega;
                assert!(
                    (o - onset.omega).abs() <= cycle,
                    "α {alpha}, seed {seed}: the onset moved from {:.3} to {o:.3} (a cycle is \
                     {cycle:.3} rad/s)",
                    onset.omega
                );
                found.push(post.omega);
            }
            let post = base.boundaries.resonance_post.expect("a boundary");
            println!(
                "| {alpha} | {seed} | {:.4} | {:.3} ± {:.3} | {lo:.3}–{hi:.3} | {:.3} | {:.3} | \
                 {:.3} |",
                z.zero_level, post.omega, post.uncertainty, found[0], found[1], onset.omega
            );
        }
    }
}
