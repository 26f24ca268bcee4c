//! `maxwell`: a force with memory, a dashpot `c_m` in series with a spring (a Maxwell element).
//!
//! A viscoelastic fluid does not respond at once: its stress relaxes towards the viscous value
//! with a relaxation time τ. For a Maxwell element (dashpot c_m in series with a spring
//! c_m/τ) driven at the blade's velocity the force F obeys
//!
//! ```text
//! dF/dt = (c_m·v − F)/τ
//! ```
//!
//! F is the model's one internal state (`z[0]`, starting at 0) and the force it returns. Slow
//! motion (ωτ ≪ 1) sees a dashpot c_m; fast motion (ωτ ≫ 1) sees a spring of stiffness c_m/τ.
//! In steady sinusoidal motion v = V·sin ωt the force is
//! `c_m·V/√(1 + (ωτ)²)·sin(ωt − atan ωτ)`. It dissipates on average over a cycle but not at
//! every instant (the spring gives energy back). Dense suspensions relax on the order of
//! 10–100 ms near the thickening transition.
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `c_m` | N·s/m | 5 | [0, 1e4] | viscosity of the dashpot (the long-time damping) |
//! | `tau` | s | 0.05 | [1e-4, 10] | relaxation time; spring stiffness is c_m/τ |

use stf_core::physics::force_model::{ModelError, ModelState};
use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::builtin;
use crate::values::take;

builtin! {
    /// Maxwell viscoelastic element; see the [module doc](self).
    Maxwell: "maxwell",
    "viscoelastic force with memory dF/dt = (c_m·v − F)/τ",
    params [
        ParamSpec::new("c_m", "N·s/m", 5.0, 0.0, 1e4,
            "dashpot viscosity: the damping of slow motion"),
        ParamSpec::new("tau", "s", 0.05, 1e-4, 10.0, "relaxation time; the spring is c_m/tau"),
    ];
    impl {
        fn n_internal(&self) -> usize {
            1
        }
        crate::builtin::state_forwards!();
        // Inlined into the integration along a record, whose every step calls it four times:
        // the errors are built out of line.
        #[inline(always)]
        fn force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, ModelError> {
            let [c_m, tau] = take(self.name(), p)?;
            if tau.is_nan() || tau <= 0.0 {
                return Err(bad_tau(tau));
            }
            let (Some(&f), Some(rate)) = (s.z.first(), dz.first_mut()) else {
                return Err(no_state());
            };
            *rate = (c_m * s.v - f) / tau;
            Ok(f)
        }
    }
}

/// The error of a relaxation time that is not positive.
#[cold]
#[inline(never)]
fn bad_tau(tau: f64) -> ModelError {
    ModelError::new(
        "maxwell",
        format!("relaxation time tau must be positive, got {tau}"),
    )
}

/// The error of a call without the internal state or its rate.
#[cold]
#[inline(never)]
fn no_state() -> ModelError {
    ModelError::new(
        "maxwell",
        "needs one internal state (the force) and its rate",
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;
    use stf_core::physics::force_model::ForceModel;

    /// Integrates the model's state along v(t) = V·sin ωt with classical RK4 and returns
    /// (amplitude, phase) of the force over the last `fit` periods, from its projections on
    /// sin ωt and cos ωt.
    fn steady_response(c_m: f64, tau: f64, v_amp: f64, omega: f64) -> (f64, f64) {
        let m = Maxwell::new();
        let p = [c_m, tau];
        let rate = |t: f64, f: f64| {
            let s = ModelState {
                t,
                x: 0.0,
                v: v_amp * (omega * t).sin(),
                z: &[f],
            };
            let mut dz = [0.0];
            m.force(&p, &s, &mut dz).unwrap();
            dz[0]
        };
        let period = 2.0 * PI / omega;
        let steps_per_period = 2000;
        let h = period / steps_per_period as f64;
        let (settle, fit) = (40, 4);
        let (mut t, mut f) = (0.0, 0.0);
        let (mut s_sum, mut c_sum) = (0.0, 0.0);
        for i in 0..(settle + fit) * steps_per_period {
            if i >= settle * steps_per_period {
                // Rectangle rule over whole periods is exact for trigonometric polynomials.
                s_sum += f * (omega * t).sin();
                c_sum += f * (omega * t).cos();
            }
            let k1 = rate(t, f);
            let k2 = rate(t + h / 2.0, f + h / 2.0 * k1);
            let k3 = rate(t + h / 2.0, f + h / 2.0 * k2);
            let k4 = rate(t + h, f + h * k3);
            f += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            t += h;
        }
        let n = (fit * steps_per_period) as f64;
        let (a_sin, a_cos) = (2.0 * s_sum / n, 2.0 * c_sum / n);
        (a_sin.hypot(a_cos), a_cos.atan2(a_sin))
    }

    #[test]
    fn steady_sinusoidal_response_matches_the_maxwell_element() {
        for &(c_m, tau, v_amp, omega) in &[(5.0, 0.05, 0.1, 6.0), (20.0, 0.5, 0.02, 10.0)] {
            let (amp, phase) = steady_response(c_m, tau, v_amp, omega);
            let wt: f64 = omega * tau;
            let amp_exact = c_m * v_amp / (1.0 + wt * wt).sqrt();
            assert!(
                (amp - amp_exact).abs() < 1e-6 * amp_exact,
                "amplitude {amp} vs {amp_exact}"
            );
            assert!(
                (phase + wt.atan()).abs() < 1e-6,
                "phase {phase} vs {}",
                -wt.atan()
            );
        }
    }

    #[test]
    fn force_is_the_state_and_bad_tau_is_an_error() {
        let m = Maxwell::new();
        let s = ModelState {
            t: 0.0,
            x: 0.0,
            v: 0.2,
            z: &[0.5],
        };
        let mut dz = [0.0];
        assert_eq!(m.force(&[5.0, 0.1], &s, &mut dz).unwrap(), 0.5);
        // (5·0.2 − 0.5)/0.1 = 5 N/s.
        assert!((dz[0] - 5.0).abs() < 1e-12);
        assert!(m.force(&[5.0, 0.0], &s, &mut dz).is_err());
        assert!(m
            .force(&[5.0, 0.1], &ModelState { z: &[], ..s }, &mut [])
            .is_err());
    }
}
