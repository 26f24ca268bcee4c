//! Are the fits' standard errors honest? Over many noise seeds of one truth, the fraction of
//! fits whose ±2σ interval holds the truth (95 % if σ is right), run in release:
//!
//! ```text
//! cargo run --release -p stf-core --example coverage [-- SEEDS]
//! ```
//!
//! The truth: the forced reference oscillator with a power-law STF (K = 5, n = 1.6) driven by
//! a rotor sweep ω = 4 → 8 rad/s at 0.1 rad/s² (40 s through resonance at 5.9 rad/s), sampled
//! at 200 Hz. For each seed (default 100):
//!
//! 1. Force level: the record through the rig's sensors ([`SensorNoise::RIG`]); v and a from
//!    the derivative filter; K and n fitted to F_STF from K = 1, n = 1.2.
//! 2. Force level on the force recovered from x through the equation of motion (the drive
//!    − m·a − c·v − k·x) instead of the force sensor's, whose errors are the derivative
//!    filter's, correlated over its window; the oscillator without dry friction (whose jumps
//!    the filter cannot follow).
//! 3. Trajectory level: the same sensors, the drive reconstructed from the encoder's angle
//!    and the simulations started from the record's initial state, as `stf-lab fit` does
//!    ([`Kinematics::excitation`], [`Kinematics::initial_state`]); K, n and the bearing's c
//!    fitted to x from 10 % off.
//!
//! Per parameter: coverage of ±2σ by the robust (block) standard errors and by the naive
//! per-sample ones, the mean |error|/σ (≈ 0.80 if σ is right) and mean σ of each; the
//! spread (sd) and bias of the estimates over the seeds; then the blocks and the wall time.

use std::sync::Arc;
use std::time::Instant;

use stf_core::data::force_data::ForceData;
use stf_core::data::kinematics::{Kinematics, KinematicsSettings};
use stf_core::fit::{FitParam, FitResult, ForceFit, TrajectoryData, TrajectoryFit};
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::synthetic::{sample_record, SensorNoise};
use stf_core::simulate::{Simulation, Trajectory};

#[path = "../tests/support/mod.rs"]
mod support;
use support::power_law;

const TRUTH: [f64; 2] = [5.0, 1.6];

/// The truth, simulated once (every seed samples the same run).
fn truth_run(system: OscillatorParams) -> Trajectory {
    let osc = Oscillator::new(system, Excitation::Rotor(RotorAngle::sweep(4.0, 0.1, 0.0)))
        .with_model(power_law(), TRUTH.to_vec())
        .unwrap_or_else(|e| panic!("{e}"));
    Simulation::new(&osc)
        .rate(200.0)
        .run(0.0, 40.0)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The oscillator without dry friction, whose force the filter can recover.
const SMOOTH: OscillatorParams = OscillatorParams {
    t_friction: 0.0,
    delta_t: 0.0,
    ..OscillatorParams::FORCED
};

/// Which force a force-level fit takes.
#[derive(Clone, Copy)]
enum Force {
    /// The force sensor's.
    Measured,
    /// The force recovered from x through the equation of motion (of [`SMOOTH`]).
    Recovered,
}

fn force_fit(run: &Trajectory, seed: u64, force: Force) -> FitResult {
    let rec = sample_record(run, &SensorNoise::RIG, seed, true);
    let k = Kinematics::from_record(&rec, &KinematicsSettings::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let f = match force {
        Force::Measured => rec.f_stf.clone().unwrap_or_default(),
        Force::Recovered => k.recovered_force(&SMOOTH),
    };
    let data = ForceData::new(&k.t, &k.x, &k.v, &k.a, &f);
    ForceFit::new(power_law())
        .fit(&data, None)
        .unwrap_or_else(|e| panic!("{e}"))
}

fn trajectory_fit(run: &Trajectory, seed: u64) -> FitResult {
    let rec = sample_record(run, &SensorNoise::RIG, seed, true);
    let k = Kinematics::from_record(&rec, &KinematicsSettings::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let truth = OscillatorParams::FORCED;
    let start = |name: &str, v: f64, lo: f64, hi: f64| FitParam::new(name, v).bounds(lo, hi);
    let (x0, v0) = k.initial_state();
    TrajectoryFit::new(truth, Arc::new(k.excitation()))
        .model(power_law(), TRUTH.to_vec())
        .initial(x0, v0)
        .free(start("K", 1.1 * TRUTH[0], 0.0, 100.0))
        .free(start("n", 0.95 * TRUTH[1], 1.0, 4.0))
        .free(start("c", 0.9 * truth.c, 0.0, 5.0 * truth.c))
        .free(
            FitParam::new("x0", x0)
                .bounds(x0 - 2e-3, x0 + 2e-3)
                .scale(1e-4),
        )
        .free(
            FitParam::new("v0", v0)
                .bounds(v0 - 0.05, v0 + 0.05)
                .scale(1e-3),
        )
        .fit(
            &TrajectoryData {
                t: &rec.t,
                x: &rec.x,
            },
            None,
        )
        .unwrap_or_else(|e| panic!("{e}"))
}

/// Coverage of ±2σ, mean |error|/σ and mean σ of `name` over `fits`, with σ robust or naive.
fn stats(fits: &[FitResult], name: &str, truth: f64, robust: bool) -> (f64, f64, f64) {
    let (mut inside, mut z, mut sigma) = (0.0, 0.0, 0.0);
    for r in fits {
        let p = r.param(name).unwrap_or_else(|| panic!("no {name}"));
        let s = if robust {
            p.std_error
        } else {
            p.naive_std_error
        };
        let e = (p.value - truth).abs() / s;
        inside += f64::from(u8::from(e <= 2.0));
        z += e;
        sigma += s;
    }
    let n = fits.len() as f64;
    (100.0 * inside / n, z / n, sigma / n)
}

fn report(label: &str, fits: &[FitResult], truth: &[(&str, f64)], seconds: f64) {
    println!("{label}");
    println!(
        "  {:<4} {:>10}  {:>9} {:>9} {:>10}  {:>9} {:>9} {:>10}  {:>10} {:>10}",
        "", "truth", "cover", "|e|/σ", "mean σ", "naive", "|e|/σ", "mean σ", "sd", "bias"
    );
    for &(name, value) in truth {
        let (c, z, s) = stats(fits, name, value, true);
        let (cn, zn, sn) = stats(fits, name, value, false);
        let nf = fits.len() as f64;
        let values: Vec<f64> = fits
            .iter()
            .map(|r| r.value(name).unwrap_or(f64::NAN))
            .collect();
        let mean = values.iter().sum::<f64>() / nf;
        let sd = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (nf - 1.0)).sqrt();
        println!(
            "  {name:<4} {value:>10.4}  {c:>8.0}% {z:>9.2} {s:>10.3e}  {cn:>8.0}% {zn:>9.2} {sn:>10.3e}  {sd:>10.3e} {:>+10.3e}",
            mean - value
        );
    }
    let mut lengths: Vec<usize> = fits
        .iter()
        .filter_map(|r| r.error_blocks)
        .map(|b| b.length)
        .collect();
    lengths.sort_unstable();
    let few = fits
        .iter()
        .filter_map(|r| r.error_blocks)
        .filter(|b| b.count < 10)
        .count();
    let unsettled = fits
        .iter()
        .filter_map(|r| r.error_blocks)
        .filter(|b| !b.settled)
        .count();
    let converged = fits.iter().filter(|r| r.convergence.converged()).count();
    println!(
        "  block length, samples: min {}, median {}, max {}; < 10 blocks in {few} fits, not \
         settled in {unsettled}; converged {converged}/{}; {} samples; wall {seconds:.1} s \
         ({:.2} s a fit)",
        lengths.first().copied().unwrap_or(0),
        lengths.get(lengths.len() / 2).copied().unwrap_or(0),
        lengths.last().copied().unwrap_or(0),
        fits.len(),
        fits.first().map_or(0, |r| r.n_points),
        seconds / fits.len() as f64
    );
}

fn main() {
    let seeds: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(100);
    let run = truth_run(OscillatorParams::FORCED);
    println!(
        "power law K = {}, n = {} on the forced oscillator, rotor sweep 4 → 8 rad/s over 40 s at \
         200 Hz; {seeds} noise seeds; ±2σ should hold the truth in 95 % of fits",
        TRUTH[0], TRUTH[1]
    );
    let clock = Instant::now();
    let fits: Vec<FitResult> = (1..=seeds)
        .map(|s| force_fit(&run, s, Force::Measured))
        .collect();
    report(
        "force level (rig sensors: x σ 0.05 mm, 0.01 mm quantum, F σ 0.02 N, 2048-count \
         encoder; v, a filtered), K and n:",
        &fits,
        &[("K", TRUTH[0]), ("n", TRUTH[1])],
        clock.elapsed().as_secs_f64(),
    );
    let smooth = truth_run(SMOOTH);
    let clock = Instant::now();
    let fits: Vec<FitResult> = (1..=seeds)
        .map(|s| force_fit(&smooth, s, Force::Recovered))
        .collect();
    report(
        "force level on the force recovered from x (the drive − m·a − c·v − k·x, v and a \
         filtered from x; rig sensors; oscillator without dry friction), K and n:",
        &fits,
        &[("K", TRUTH[0]), ("n", TRUTH[1])],
        clock.elapsed().as_secs_f64(),
    );
    let traj = [
        ("K", TRUTH[0]),
        ("n", TRUTH[1]),
        ("c", OscillatorParams::FORCED.c),
    ];
    let clock = Instant::now();
    let fits: Vec<FitResult> = (1..=seeds).map(|s| trajectory_fit(&run, s)).collect();
    report(
        "trajectory level (rig sensors, the drive reconstructed from the 2048-count encoder, \
         the initial state fitted as `stf-lab fit` does), K, n and c:",
        &fits,
        &traj,
        clock.elapsed().as_secs_f64(),
    );
}
