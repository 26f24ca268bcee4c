//! `bouc_wen`: rate-independent hysteresis with one internal state (the Bouc–Wen model).
//!
//! Dampers and jammed suspensions show loops whose shape does not depend on the speed: the
//! force builds up over a displacement, saturates, and drops back at once when the motion
//! reverses. The Bouc–Wen model carries a hysteretic displacement z,
//!
//! ```text
//! ż = A·ẋ − β·|ẋ|·|z|^(n−1)·z − γ·ẋ·|z|^n,     F = k_bw·z
//! ```
//!
//! Its classic parameters (A, β, γ, n, k_bw) are not identifiable from a record: scaling z by
//! λ and A by λ, β and γ by λ⁻ⁿ and k_bw by 1/λ gives the same force, so A is fixed to 1; and
//! n trades off against β, γ and the loop's corner (a fit that frees it wanders along a valley),
//! so it is fixed to 1, the classic form whose loading branch is an exponential approach to
//! saturation. The three that remain are written as three features of the loop, each with a
//! unit the record's scale sets (so their defaults and bounds follow a record in kN and cm as
//! well as the trolley's N and mm):
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `F_bw` | N | 0.5 | [0, 50] | saturation force k_bw·z_u (widened to the record's force) |
//! | `x_bw` | m | 2e-3 | [1e-5, 0.1] | yield displacement z_u = 1/(β + γ); initial stiffness F_bw/x_bw |
//! | `beta` | — | 0.5 | [0, 5] | β/(β + γ): unloading stiffness at saturation is 2·beta·F_bw/x_bw |
//!
//! In the normalised state w = z/x_bw (|w| ≤ 1) the model is
//!
//! ```text
//! ẇ = (ẋ − beta·|ẋ|·w − (1 − beta)·ẋ·|w|) / x_bw,     F = F_bw·w
//! ```
//!
//! and back: β = beta/x_bw, γ = (1 − beta)/x_bw, k_bw = F_bw/x_bw. `beta` = 0.5 is the common
//! choice β = γ (unloading as stiff as the first loading); `beta` = 0 is elastic without
//! hysteresis. w is the model's one internal state (`z[0]`), starting at 0. The state is
//! clamped to |w| ≤ 1 inside the law (exact for the model, whose w never leaves [−1, 1]), so
//! a step longer than the state's time scale x_bw/|ẋ| gives a rough force, never a runaway.
//!
//! A loop narrower than 5 % of the stroke is in effect `yield` (F_bw·sign ẋ); a yield
//! displacement 20 times the stroke never saturates and is in effect `linear_spring`
//! (k_s = F_bw/x_bw): discovery names the simpler effect.

use stf_core::physics::force_model::{ModelError, ModelState, Reach, NEGLIGIBLE_SHARE};
use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::builtin;
use crate::values::take;

builtin! {
    /// Bouc–Wen hysteresis; see the [module doc](self).
    BoucWen: "bouc_wen",
    "rate-independent hysteresis (Bouc–Wen, n = 1) F = F_bw·w",
    params [
        ParamSpec::new("F_bw", "N", 0.5, 0.0, 50.0, "saturation force of the hysteretic loop"),
        ParamSpec::new("x_bw", "m", 2e-3, 1e-5, 0.1,
            "yield displacement: the force saturates over a few x_bw"),
        ParamSpec::new("beta", "", 0.5, 0.0, 5.0,
            "beta/(beta + gamma): unloading stiffness is 2·beta·F_bw/x_bw"),
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
            let [f_bw, x_bw, beta] = take(self.name(), p)?;
            if x_bw.is_nan() || x_bw <= 0.0 {
                return Err(bad_x_bw(x_bw));
            }
            let (Some(&w), Some(rate)) = (s.z.first(), dz.first_mut()) else {
                return Err(no_state());
            };
            let w = w.clamp(-1.0, 1.0);
            *rate = (s.v - beta * s.v.abs() * w - (1.0 - beta) * s.v * w.abs()) / x_bw;
            Ok(f_bw * w)
        }
        /// A loop narrower than 5 % of the stroke is `yield`; a yield displacement that the
        /// stroke never reaches (20 times it) is a `linear_spring` of the initial stiffness.
        fn reduces_to(&self, p: &[f64], reach: Reach) -> Option<(String, Vec<f64>)> {
            let [f_bw, x_bw, _] = take(self.name(), p).ok()?;
            if x_bw < NEGLIGIBLE_SHARE * reach.x {
                Some(("yield".to_string(), vec![f_bw, NEGLIGIBLE_SHARE * reach.v]))
            } else if reach.x < NEGLIGIBLE_SHARE * x_bw {
                Some(("linear_spring".to_string(), vec![f_bw / x_bw]))
            } else {
                None
            }
        }
    }
}

/// The error of a yield displacement that is not positive.
#[cold]
#[inline(never)]
fn bad_x_bw(x_bw: f64) -> ModelError {
    ModelError::new(
        "bouc_wen",
        format!("yield displacement x_bw must be positive, got {x_bw}"),
    )
}

/// The error of a call without the internal state or its rate.
#[cold]
#[inline(never)]
fn no_state() -> ModelError {
    ModelError::new(
        "bouc_wen",
        "needs one internal state (the hysteretic displacement) and its rate",
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use stf_core::physics::force_model::ForceModel;

    /// w after moving by `dx` from `w0` at speed `v` in `steps` Euler steps (fine enough).
    fn travel(p: &[f64; 3], w0: f64, dx: f64, steps: usize) -> f64 {
        let m = BoucWen::new();
        let v = dx.signum() * 0.1;
        let h = dx.abs() / 0.1 / steps as f64;
        let mut w = w0;
        for _ in 0..steps {
            let mut dz = [0.0];
            let s = ModelState {
                t: 0.0,
                x: 0.0,
                v,
                z: &[w],
            };
            m.force(p, &s, &mut dz).unwrap();
            w += h * dz[0];
        }
        w
    }

    /// Loading from w = 0 is the exponential approach 1 − e^(−x/x_bw) whatever beta;
    /// unloading from saturation starts at 2·beta times the initial stiffness.
    #[test]
    fn loading_saturates_exponentially_and_unloading_is_two_beta_stiffer() {
        for beta in [0.0, 0.5, 1.5] {
            let p = [2.0, 1e-3, beta];
            let w = travel(&p, 0.0, 2e-3, 200_000);
            let exact = 1.0 - (-2.0_f64).exp();
            assert!((w - exact).abs() < 1e-4, "beta {beta}: w {w} vs {exact}");
        }
        let m = BoucWen::new();
        let mut dz = [0.0];
        let s = ModelState {
            t: 0.0,
            x: 0.0,
            v: -0.1,
            z: &[1.0],
        };
        assert_eq!(m.force(&[2.0, 1e-3, 0.8], &s, &mut dz).unwrap(), 2.0);
        // ẇ = (−0.1 − 0.8·0.1 + 0.2·0.1)/1e-3 = −160 /s: 2·0.8 times the loading rate 100 /s.
        assert!((dz[0] + 160.0).abs() < 1e-9, "{}", dz[0]);
    }

    #[test]
    fn the_state_is_clamped_and_bad_values_are_errors() {
        let m = BoucWen::new();
        let s = ModelState {
            t: 0.0,
            x: 0.0,
            v: 0.1,
            z: &[3.0],
        };
        let mut dz = [0.0];
        assert_eq!(m.force(&[2.0, 1e-3, 0.5], &s, &mut dz).unwrap(), 2.0);
        assert_eq!(dz[0], 0.0, "saturated: no further loading");
        assert!(m.force(&[2.0, 0.0, 0.5], &s, &mut dz).is_err());
        assert!(m
            .force(&[2.0, 1e-3, 0.5], &ModelState { z: &[], ..s }, &mut [])
            .is_err());
    }

    #[test]
    fn a_narrow_loop_is_yield_and_an_unreached_one_a_linear_spring() {
        let m = BoucWen::new();
        let reach = Reach { x: 0.03, v: 0.2 };
        let narrow = m.reduces_to(&[1.0, 1e-3, 0.5], reach).unwrap();
        assert_eq!(narrow.0, "yield");
        assert_eq!(narrow.1[0], 1.0);
        let wide = m.reduces_to(&[1.0, 1.0, 0.5], reach).unwrap();
        assert_eq!(wide, ("linear_spring".to_string(), vec![1.0]));
        assert_eq!(m.reduces_to(&[1.0, 5e-3, 0.5], reach), None);
    }
}
