//! Simulate the paper's sweep with the default method (for profilers), `repeats` times
//! (default 3), and print the best wall time.
//!
//! `cargo run --release -p stf-core --example profile_sweep [repeats]`
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::Simulation;

fn main() {
    let repeats: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let osc = Oscillator::new(
        OscillatorParams::FORCED,
        Excitation::Rotor(RotorAngle::sweep(2.35, 0.047, 50.0)),
    );
    let mut best = f64::INFINITY;
    let mut calls = 0;
    for _ in 0..repeats.max(1) {
        let t = std::time::Instant::now();
        let run = Simulation::new(&osc).rate(1000.0).run(50.0, 200.0);
        best = best.min(t.elapsed().as_secs_f64());
        // Dropped after the clock stops: freeing the columns is the caller's cost.
        match run {
            Ok(run) => calls = run.stats.rhs_calls,
            Err(e) => eprintln!("{e}"),
        }
    }
    println!(
        "{calls} RHS calls, Simulation::run best of {repeats}: {:.2} ms",
        best * 1e3
    );
}
