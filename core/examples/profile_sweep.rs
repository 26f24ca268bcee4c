//! Simulate the paper's sweep with the default method (for profilers), `repeats` times
//! (default 3), and print the median and the best wall time: the whole `Simulation::run`, or with
//! `integrate` as the second argument the integration alone (what `bench_sweep` times).
//!
//! `cargo run --release -p stf-core --example profile_sweep [repeats] [integrate]`
use stf_core::numerics::integrate::{integrate, Settings};
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::Simulation;

fn main() {
    let repeats: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let integrate_only = std::env::args().nth(2).as_deref() == Some("integrate");
    let osc = Oscillator::new(
        OscillatorParams::FORCED,
        Excitation::Rotor(RotorAngle::sweep(2.35, 0.047, 50.0)),
    );
    let times: Vec<f64> = (0..=150_000).map(|i| 50.0 + i as f64 * 1e-3).collect();
    let y0 = osc.initial_state(0.0, 0.0);
    let settings = Settings::default();
    let mut walls = Vec::with_capacity(repeats.max(1));
    let mut calls = 0;
    for _ in 0..repeats.max(1) {
        let t = std::time::Instant::now();
        // Dropped after the clock stops: freeing the output is the caller's cost.
        let (stats, _solution, _run) = if integrate_only {
            match integrate(&osc, times[0], &y0, &times, &settings) {
                Ok(sol) => (sol.stats, Some(sol), None),
                Err(e) => return eprintln!("{e}"),
            }
        } else {
            match Simulation::new(&osc).rate(1000.0).run(50.0, 200.0) {
                Ok(run) => (run.stats, None, Some(run)),
                Err(e) => return eprintln!("{e}"),
            }
        };
        walls.push(t.elapsed().as_secs_f64());
        calls = stats.rhs_calls;
    }
    let what = if integrate_only {
        "integrate"
    } else {
        "Simulation::run"
    };
    walls.sort_by(f64::total_cmp);
    println!(
        "{calls} RHS calls, {what} of {} runs: median {:.3} ms, best {:.3} ms",
        walls.len(),
        walls[walls.len() / 2] * 1e3,
        walls[0] * 1e3
    );
}
