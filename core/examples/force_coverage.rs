//! Are force-level standard errors honest at the rig's sampling rates? Over many noise seeds
//! of one truth, the RMS of z = (estimate − truth)/σ for each parameter (1 if σ is right),
//! at two sweep rates and at 200 Hz and 1 kHz, run in release:
//!
//! ```text
//! cargo run --release -p stf-core --example force_coverage [-- SEEDS]
//! ```
//!
//! The truth: the forced reference oscillator (dry friction included) with a power-law STF
//! (K = 20, n = 1.5) driven by a rotor sweep from ω = 2.35 rad/s through resonance to
//! 9.4 rad/s at 0.047 rad/s² (the source study's) or 0.2 rad/s²; each seed (default 100: over
//! 40 an RMS z moves by about ±0.11 with the seeds alone, as wide as the band it is held to)
//! samples it through the rig's sensors ([`SensorNoise::RIG`]), derives v and a with the
//! default derivative filter and fits K and n to F_STF from the model's defaults, as `fit`
//! does: corrected for the filter's noise ([`FilterNoise`], simulation–extrapolation), and
//! as fitted, without the correction. Per case and parameter: the RMS, mean (the bias in σ)
//! and largest |z| and the share of fits whose ±2σ holds the truth, corrected; the RMS and
//! mean z uncorrected; the RMS error of the estimates against the truth, corrected and
//! uncorrected; the median block length of the robust errors and the wall time of the
//! corrected fits.
//!
//! The last column is a control for the seeds themselves: the RMS z that the force sensor's
//! white noise alone gives the parameter over the same seeds, against its exact σ (the
//! least-squares shift it makes along the true v, `(JᵀJ)⁻¹Jᵀε`, over `σ_F·√((JᵀJ)⁻¹)`). It
//! is 1 on average; how far it lies from 1 is how far these seeds alone move an RMS z (about
//! ±1/√(2·seeds): ±0.11 over 40), whatever the errors.

use std::time::Instant;

use stf_core::data::force_data::ForceData;
use stf_core::data::kinematics::{Kinematics, KinematicsSettings};
use stf_core::fit::{FilterNoise, FitResult, ForceFit};
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::synthetic::{sample_record, SensorNoise};
use stf_core::simulate::{Simulation, Trajectory};

#[path = "../tests/support/mod.rs"]
mod support;
use support::power_law;

const TRUTH: [(&str, f64); 2] = [("K", 20.0), ("n", 1.5)];

/// The truth swept from 2.35 to 9.4 rad/s at `alpha` rad/s², sampled at `rate` Hz.
fn truth_run(alpha: f64, rate: f64) -> Trajectory {
    let osc = Oscillator::new(
        OscillatorParams::FORCED,
        Excitation::Rotor(RotorAngle::sweep(2.35, alpha, 0.0)),
    )
    .with_model(power_law(), TRUTH.iter().map(|t| t.1).collect())
    .unwrap_or_else(|e| panic!("{e}"));
    Simulation::new(&osc)
        .rate(rate)
        .run(0.0, (9.4 - 2.35) / alpha)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The fit of seed `seed`, corrected for the filter's noise or not, and its wall time, s.
fn force_fit(run: &Trajectory, seed: u64, corrected: bool) -> (FitResult, f64) {
    let rec = sample_record(run, &SensorNoise::RIG, seed, true);
    let k = Kinematics::from_record(&rec, &KinematicsSettings::default())
        .unwrap_or_else(|e| panic!("{e}"));
    let f = rec.f_stf.clone().unwrap_or_default();
    let data = ForceData::new(&k.t, &k.x, &k.v, &k.a, &f);
    let noise = corrected.then(|| FilterNoise::new(k.motion_filter, k.sigma_x));
    let clock = Instant::now();
    let r = ForceFit::new(power_law())
        .filter_noise(noise)
        .fit(&data, None)
        .unwrap_or_else(|e| panic!("{e}"));
    (r, clock.elapsed().as_secs_f64())
}

/// z of K and n for the force sensor's white noise alone on seed `seed`: the least-squares
/// shift `(JᵀJ)⁻¹Jᵀε` that the noise ε of the sampled F_STF makes along the true v, over its
/// exact σ, `σ_F·√diag((JᵀJ)⁻¹)`.
fn white_noise_z(run: &Trajectory, seed: u64) -> [f64; 2] {
    let rec = sample_record(run, &SensorNoise::RIG, seed, true);
    let f = rec.f_stf.unwrap_or_default();
    let (k, n) = (TRUTH[0].1, TRUTH[1].1);
    let (mut a, mut g) = ([[0.0; 2]; 2], [0.0; 2]);
    for ((v, f), f0) in run.v.iter().zip(&f).zip(&run.f_stf) {
        let s = v.abs().powf(n) * v.signum();
        let j = [s, k * s * v.abs().max(f64::MIN_POSITIVE).ln()];
        for p in 0..2 {
            g[p] += j[p] * (f - f0);
            for q in 0..2 {
                a[p][q] += j[p] * j[q];
            }
        }
    }
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let shift = [
        (a[1][1] * g[0] - a[0][1] * g[1]) / det,
        (a[0][0] * g[1] - a[1][0] * g[0]) / det,
    ];
    let sigma = [a[1][1] / det, a[0][0] / det].map(|v| SensorNoise::RIG.f_sigma * v.sqrt());
    [shift[0] / sigma[0], shift[1] / sigma[1]]
}

/// RMS of `estimate − truth` of `name` over `fits`.
fn rms_error(fits: &[FitResult], name: &str, truth: f64) -> f64 {
    let sq: f64 = fits
        .iter()
        .filter_map(|r| r.value(name))
        .map(|v| (v - truth).powi(2))
        .sum();
    (sq / fits.len() as f64).sqrt()
}

/// RMS z, largest |z|, ±2σ coverage (%) and mean z (the bias in σ) of `name` over `fits`.
fn z_stats(fits: &[FitResult], name: &str, truth: f64) -> (f64, f64, f64, f64) {
    let z: Vec<f64> = fits
        .iter()
        .map(|r| {
            let p = r.param(name).unwrap_or_else(|| panic!("no {name}"));
            (p.value - truth) / p.std_error
        })
        .collect();
    let n = z.len() as f64;
    let rms = (z.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
    let max = z.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let cover = 100.0 * z.iter().filter(|v| v.abs() <= 2.0).count() as f64 / n;
    (rms, max, cover, z.iter().sum::<f64>() / n)
}

fn main() {
    let seeds: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(100);
    println!(
        "force level, power law K 20, n 1.5, ω 2.35 → 9.4 rad/s, rig sensors, {seeds} seeds; \
         RMS z 1 (0.8–1.2) and ±2σ coverage 95 % if σ is right"
    );
    println!(
        "| sweep | rate | param | RMS z | mean z | max |z| | ±2σ | RMS z, mean z uncorrected | \
         RMS error corrected / uncorrected | block (median) | wall | control: white-noise RMS z |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for alpha in [0.047, 0.2] {
        for rate in [200.0, 1000.0] {
            let run = truth_run(alpha, rate);
            let (fits, walls): (Vec<FitResult>, Vec<f64>) =
                (1..=seeds).map(|s| force_fit(&run, s, true)).unzip();
            let plain: Vec<FitResult> = (1..=seeds).map(|s| force_fit(&run, s, false).0).collect();
            let wall = walls.iter().sum::<f64>() / walls.len() as f64;
            let mut blocks: Vec<usize> = fits
                .iter()
                .filter_map(|r| r.error_blocks)
                .map(|b| b.length)
                .collect();
            blocks.sort_unstable();
            let block = blocks.get(blocks.len() / 2).copied().unwrap_or(0);
            let white: Vec<[f64; 2]> = (1..=seeds).map(|s| white_noise_z(&run, s)).collect();
            for (j, (name, truth)) in TRUTH.into_iter().enumerate() {
                let control =
                    (white.iter().map(|z| z[j] * z[j]).sum::<f64>() / seeds as f64).sqrt();
                let (rms, max, cover, mean) = z_stats(&fits, name, truth);
                let (rms0, _, _, mean0) = z_stats(&plain, name, truth);
                let (e, e0) = (
                    rms_error(&fits, name, truth),
                    rms_error(&plain, name, truth),
                );
                println!(
                    "| {alpha} rad/s² | {rate:.0} Hz | {name} | {rms:.2} | {mean:+.2} | {max:.1} | \
                     {cover:.0} % | {rms0:.2}, {mean0:+.2} | {e:.4} / {e0:.4} | {block} | \
                     {wall:.1} s | {control:.2} |"
                );
            }
        }
    }
}
