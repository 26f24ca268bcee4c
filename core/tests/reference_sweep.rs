//! The no-STF forced model against the reference figures of an independent implementation.

use stf_core::analysis::{breakaway, local_maxima, peak, BREAKAWAY_DISPLACEMENT};
use stf_core::excitation::{Excitation, RotorAngle};
use stf_core::oscillator::Oscillator;
use stf_core::simulate::Simulation;
use stf_core::system::OscillatorParams;

#[test]
fn sweep_0p047_peak_and_breakaway() {
    let osc = Oscillator::new(
        OscillatorParams::FORCED,
        Excitation::Rotor(RotorAngle::sweep(2.35, 0.047, 50.0)),
    );
    let run = Simulation::new(&osc).rate(1000.0).run(50.0, 200.0).unwrap();
    let omega = run.omega.as_ref().unwrap();
    let p = peak(&run.t, &run.x, Some(omega)).unwrap();
    let b = breakaway(&run.x, BREAKAWAY_DISPLACEMENT).unwrap();
    let maxima = local_maxima(&run.t, &run.x, omega);
    eprintln!(
        "peak {:.3} mm at {:.3} rad/s, breakaway {:.3} rad/s, {} maxima, {:?}",
        p.amplitude * 1e3,
        p.omega,
        omega[b],
        maxima.len(),
        run.stats
    );
    assert!((p.amplitude * 1e3 - 41.69).abs() < 0.2);
    assert!((p.omega - 6.22).abs() < 0.03);
    assert!((omega[b] - 3.80).abs() < 0.05);
}
