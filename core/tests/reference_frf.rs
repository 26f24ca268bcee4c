//! The frequency response of the no-STF forced model on the 0.047 rad/s² sweep against an
//! independent implementation (local maxima of x), and the reference figures of docs/ARCHITECTURE.md §1.

use stf_core::data::response::{breakaway, local_maxima, peak, BREAKAWAY_DISPLACEMENT};
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::Simulation;

#[test]
fn sweep_0p047_matches_the_reference_response() {
    let osc = Oscillator::new(
        OscillatorParams::FORCED,
        Excitation::Rotor(RotorAngle::sweep(2.35, 0.047, 50.0)),
    );
    let run = Simulation::new(&osc).rate(1000.0).run(50.0, 200.0).unwrap();
    let omega = run.omega.as_ref().unwrap();
    let p = peak(&run.t, &run.x, Some(omega)).unwrap();
    let b = omega[breakaway(&run.x, BREAKAWAY_DISPLACEMENT).unwrap()];
    eprintln!(
        "peak {:.3} mm at {:.3} rad/s, breakaway {b:.3} rad/s, {} RHS calls",
        p.amplitude * 1e3,
        p.omega,
        run.stats.rhs_calls
    );
    assert!((p.amplitude * 1e3 - 41.69).abs() < 0.2);
    assert!((p.omega - 6.22).abs() < 0.03);
    assert!((b - 3.80).abs() < 0.05);

    // Every reference crest has a crest of ours within 5 ms, of the same height to 0.05 mm.
    let ours = local_maxima(&run.t, &run.x, omega);
    let text = include_str!("data/frf_no_stf_sweep_0p047.csv");
    let mut worst: f64 = 0.0;
    let mut count = 0;
    for line in text.lines().skip(1) {
        let v: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        let (t, x) = (v[0], v[2]);
        let near = ours
            .iter()
            .min_by(|a, b| (a.t - t).abs().total_cmp(&(b.t - t).abs()))
            .unwrap();
        assert!((near.t - t).abs() < 0.005, "no crest near t = {t}");
        worst = worst.max((near.x - x).abs());
        count += 1;
    }
    eprintln!(
        "{count} reference crests, max |Δx_peak| = {:.4} mm",
        worst * 1e3
    );
    assert!(count > 100);
    assert!(worst < 0.05e-3);
}
