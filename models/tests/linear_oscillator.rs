//! A linear oscillator (no dry friction) with a viscous STF against the analytic steady state.

use std::sync::Arc;

use stf_core::numerics::integrate::Settings;
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::Simulation;

#[test]
fn steady_state_amplitude_matches_the_analytic_one() {
    let p = OscillatorParams {
        t_friction: 0.0,
        delta_t: 0.0,
        ..OscillatorParams::FORCED
    };
    let c_s = 20.0;
    for omega in [3.0, 5.9, 9.0] {
        let osc = Oscillator::new(p, Excitation::Rotor(RotorAngle::constant(omega)))
            .with_model(Arc::new(stf_models::viscous::Viscous::new()), vec![c_s])
            .unwrap();
        // The transient decays as exp(−(c + c_s)/(2m)·t): e^-36 after 30 s.
        let run = Simulation::new(&osc)
            .settings(Settings::default().rtol(1e-11).atol(1e-13))
            .rate(2000.0)
            .run(0.0, 36.0)
            .unwrap();
        let tail = run.t.iter().position(|&t| t >= 30.0).unwrap();
        let amplitude = run.x[tail..].iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let force = p.f0 * omega * omega;
        let exact =
            force / ((p.k - p.m * omega * omega).powi(2) + ((p.c + c_s) * omega).powi(2)).sqrt();
        let rel = (amplitude - exact).abs() / exact;
        eprintln!("ω {omega}: {amplitude:.9e} vs {exact:.9e}, rel {rel:.2e}");
        assert!(rel < 1e-4, "ω = {omega}: relative error {rel}");
    }
}
