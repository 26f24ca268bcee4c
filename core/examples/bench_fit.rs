//! Benchmarks of the fitter (run in release):
//!
//! ```text
//! cargo run --release -p stf-core --example bench_fit
//! ```
//!
//! 1. Force level: a native power law `K·|v|ⁿ·sign v` on 150 000 samples of a sine sweep,
//!    σ = 0.02 N noise, from K = 1, n = 1.2.
//! 2. Trajectory level, the source study's forced identification: k, c, T, ΔT, F0 of the
//!    no-STF oscillator on a synthetic 0.047 rad/s² sweep (t 50 → 200 s, 1 kHz, σ = 0.1 mm),
//!    started 10 % off.

use std::sync::Arc;
use std::time::Instant;

use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use stf_core::data::force_data::ForceData;
use stf_core::fit::{FitParam, ForceFit, TrajectoryData, TrajectoryFit};
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::Simulation;

#[path = "../tests/support/mod.rs"]
mod support;
use support::power_law;

fn main() {
    let mut rng = StdRng::seed_from_u64(1);

    // 1. Force level.
    let n = 150_000;
    let (mut t, mut x, mut v, mut a, mut f) = (vec![], vec![], vec![], vec![], vec![]);
    let noise = Normal::new(0.0, 0.02).unwrap_or_else(|e| panic!("{e}"));
    for i in 0..n {
        let ti = i as f64 * 1e-3;
        let w = 2.0 * std::f64::consts::PI * (0.3 + 0.01 * ti);
        let phi = 2.0 * std::f64::consts::PI * (0.3 * ti + 0.005 * ti * ti);
        t.push(ti);
        x.push(0.03 * phi.sin());
        v.push(0.03 * w * phi.cos());
        a.push(-0.03 * w * w * phi.sin());
        let vi = *v.last().unwrap_or(&0.0);
        f.push(4.0 * vi.abs().powf(1.5) * vi.signum() + noise.sample(&mut rng));
    }
    let model = power_law();
    let data = ForceData::new(&t, &x, &v, &a, &f);
    let r = ForceFit::new(model)
        .fit(&data, None)
        .unwrap_or_else(|e| panic!("{e}"));
    println!(
        "force level, power_law, {n} samples: K = {:.4} ± {:.4} (truth 4), n = {:.4} ± {:.4} (truth 1.5), rms {:.4} N, {} evaluations, {:.3} s, {:?}",
        r.params[0].value, r.params[0].std_error, r.params[1].value, r.params[1].std_error,
        r.rms, r.evaluations, r.wall_seconds, r.convergence
    );

    // 2. Trajectory level.
    let truth = OscillatorParams::FORCED;
    let excitation = Arc::new(Excitation::Rotor(RotorAngle::sweep(2.35, 0.047, 50.0)));
    let osc = Oscillator::with_shared_excitation(truth, excitation.clone());
    let clock = Instant::now();
    let run = Simulation::new(&osc)
        .rate(1000.0)
        .run(50.0, 200.0)
        .unwrap_or_else(|e| panic!("{e}"));
    let one_sim = clock.elapsed().as_secs_f64();
    let noise = Normal::new(0.0, 1e-4).unwrap_or_else(|e| panic!("{e}"));
    let xr: Vec<f64> = run.x.iter().map(|x| x + noise.sample(&mut rng)).collect();
    let data = TrajectoryData { t: &run.t, x: &xr };
    let at_truth = TrajectoryFit::new(truth, excitation.clone())
        .fit(&data, None)
        .unwrap_or_else(|e| panic!("{e}"));
    let mut fit = TrajectoryFit::new(truth, excitation);
    for (name, factor) in [
        ("k", 1.1),
        ("c", 0.9),
        ("T", 1.1),
        ("delta_T", 0.9),
        ("F0", 1.1),
    ] {
        let v = truth.get(name).unwrap_or(0.0) * factor;
        fit = fit.free(FitParam::new(name, v).bounds(0.0, 3.0 * v));
    }
    let r = fit.fit(&data, None).unwrap_or_else(|e| panic!("{e}"));
    let err = |name: &str| {
        100.0 * (r.value(name).unwrap_or(f64::NAN) / truth.get(name).unwrap_or(f64::NAN) - 1.0)
    };
    println!(
        "trajectory level, 5 parameters, {} samples: one simulation {:.3} s; S(μ) = {:.5} mm² vs {:.5} at the truth; k error {:+.3} %, F0 error {:+.3} %, c {:+.2} %, T {:+.2} %, ΔT {:+.2} %; {} simulations ({} failed), {:.1} s, {:?}",
        data.t.len(), one_sim, r.s_mm2.unwrap_or(f64::NAN), at_truth.s_mm2.unwrap_or(f64::NAN),
        err("k"), err("F0"), err("c"), err("T"), err("delta_T"),
        r.evaluations, r.failures, r.wall_seconds, r.convergence
    );
    for line in &r.log {
        println!("  {line}");
    }
}
