//! Simulate the paper's sweep once with the default method (for profilers).
use stf_core::excitation::{Excitation, RotorAngle};
use stf_core::oscillator::Oscillator;
use stf_core::simulate::Simulation;
use stf_core::system::OscillatorParams;

fn main() {
    let osc = Oscillator::new(
        OscillatorParams::FORCED,
        Excitation::Rotor(RotorAngle::sweep(2.35, 0.047, 50.0)),
    );
    for _ in 0..3 {
        let t = std::time::Instant::now();
        match Simulation::new(&osc).rate(1000.0).run(50.0, 200.0) {
            Ok(run) => println!(
                "{} RHS calls, {:.2} ms",
                run.stats.rhs_calls,
                t.elapsed().as_secs_f64() * 1e3
            ),
            Err(e) => eprintln!("{e}"),
        }
    }
}
