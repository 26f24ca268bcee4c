//! Drives sampled from records are interpolated between their samples, so the right-hand side
//! has a kink at every sample. The default method and Rodas4 end a step at each such
//! breakpoint ([`OdeSystem::next_breakpoint`]) instead of stepping across it.
//!
//! Known answers: `y' = u(t)` with `u` piecewise linear is integrated exactly when no step
//! straddles a knot (to rounding by Dormand–Prince; to 1e-10 by Rodas4, whose ∂f/∂t is a
//! finite difference). And the source study's sweep driven by the bundled record's
//! measured rotor angle stays within 1e-3 mm of a tight reference, which it did not when steps
//! crossed the record's 15 000 knots (4.7e-3 mm, with 34 000 rejected steps).

use std::path::Path;

use stf_core::data::kinematics::{Kinematics, KinematicsSettings};
use stf_core::data::record::Record;
use stf_core::numerics::integrate::{integrate, Method, OdeSystem, Settings, SimError, Solution};
use stf_core::numerics::interpolate::Linear;
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;

/// `y' = u(t)`, `u` linear between uneven knots.
struct Integral {
    u: Linear,
}

impl OdeSystem for Integral {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, t: f64, _y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        dy[0] = self.u.at(t);
        Ok(())
    }
    fn next_breakpoint(&self, t: f64) -> Option<f64> {
        self.u.next_knot(t)
    }
}

/// The same system with its breakpoints hidden: what an integrator sees that steps across them.
struct Hidden<'a, S: OdeSystem>(&'a S);

impl<S: OdeSystem> OdeSystem for Hidden<'_, S> {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        self.0.rhs(t, y, dy)
    }
    fn jacobian(&self, t: f64, y: &[f64], fy: &[f64], jac: &mut [f64]) -> Result<u64, SimError> {
        self.0.jacobian(t, y, fy, jac)
    }
    fn switching_component(&self) -> Option<usize> {
        self.0.switching_component()
    }
}

fn max_error(sol: &Solution, exact: &[f64]) -> f64 {
    exact
        .iter()
        .enumerate()
        .map(|(i, e)| (sol.y(i)[0] - e).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_piecewise_linear_drive_is_integrated_exactly_knot_to_knot() {
    // Uneven knots over 10 s with a zig-zag u: slopes jump by up to ±40 at every knot.
    let mut knots = vec![0.0];
    while *knots.last().unwrap() < 10.0 {
        let k = knots.len() as f64;
        knots.push(knots.last().unwrap() + 0.05 + 0.04 * (1.7 * k).sin().abs());
    }
    let values: Vec<f64> = (0..knots.len())
        .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 } * (1.0 + 0.1 * i as f64))
        .collect();
    // The exact integral at the knots: trapezoids.
    let mut exact = vec![0.0];
    for i in 1..knots.len() {
        let area = 0.5 * (values[i - 1] + values[i]) * (knots[i] - knots[i - 1]);
        exact.push(exact[i - 1] + area);
    }
    let sys = Integral {
        u: Linear::new(knots.clone(), values),
    };
    for method in [Method::Auto, Method::Rodas4] {
        let s = Settings::default().method(method);
        let sol = integrate(&sys, 0.0, &[0.0], &knots, &s).unwrap();
        let err = max_error(&sol, &exact);
        let hidden = integrate(&Hidden(&sys), 0.0, &[0.0], &knots, &s).unwrap();
        let err_hidden = max_error(&hidden, &exact);
        eprintln!(
            "{method:?}: knot to knot {err:.1e} ({:?}); across knots {err_hidden:.1e} ({:?})",
            sol.stats, hidden.stats
        );
        assert!(err < 1e-9, "{method:?}: error {err:e}");
        // The few rejected steps are the first ones, while the step size is found.
        assert!(
            sol.stats.rejected * 100 < hidden.stats.rejected,
            "{method:?}: {:?} against {:?}",
            sol.stats,
            hidden.stats
        );
        assert!(err_hidden > 100.0 * err.max(1e-15));
    }
}

#[test]
fn a_sweep_driven_by_the_measured_rotor_angle_stays_within_a_micrometre() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../experiments/records/forced_sweep.csv");
    let record = Record::read(&path).unwrap();
    let kinematics = Kinematics::from_record(&record, &KinematicsSettings::paper()).unwrap();
    let osc = Oscillator::new(OscillatorParams::FORCED, kinematics.excitation());
    let t = &kinematics.t;
    let y0 = osc.initial_state(0.0, 0.0);
    let tight = Settings::default()
        .method(Method::Dopri5)
        .rtol(1e-10)
        .atol(1e-12);
    let reference = integrate(&osc, t[0], &y0, t, &tight).unwrap();
    let dx = |sol: &Solution| {
        (0..t.len())
            .map(|i| (sol.y(i)[0] - reference.y(i)[0]).abs())
            .fold(0.0, f64::max)
    };
    let default = integrate(&osc, t[0], &y0, t, &Settings::default()).unwrap();
    let across = integrate(&Hidden(&osc), t[0], &y0, t, &Settings::default()).unwrap();
    eprintln!(
        "knot to knot: max |Δx| {:.2e} mm, {:?}; across knots: {:.2e} mm, {:?}",
        dx(&default) * 1e3,
        default.stats,
        dx(&across) * 1e3,
        across.stats
    );
    assert!(dx(&default) < 1e-6, "max |Δx| {:e} m", dx(&default));
    assert!(default.stats.rhs_calls < across.stats.rhs_calls);
}
