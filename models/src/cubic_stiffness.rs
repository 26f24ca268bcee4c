//! `cubic_stiffness`: an elastic jammed network, `F = k3·x³`.
//!
//! A jammed suspension is a solid-like contact network that stores elastic energy; compressed
//! between the blade and the walls it stiffens with strain, the lowest odd term of which is a
//! Duffing-type cubic spring. It adds to the trolley's linear springs (k·x), bending the
//! resonance curve towards higher frequencies (hardening) for k3 > 0. It is conservative (no
//! dissipation) and odd in x: F(−x) = −F(x).
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `k3` | N/m³ | 1e5 | [0, 1e9] | cubic stiffness (0.1 N at 1 cm, 7.4 N at 42 mm) |

use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::linear_builtin;

linear_builtin! {
    /// Cubic (Duffing) stiffness; see the [module doc](self).
    CubicStiffness: "cubic_stiffness",
    "elastic jammed network F = k3·x³",
    param ParamSpec::new("k3", "N/m³", 1e5, 0.0, 1e9, "cubic stiffness of the jammed network");
    law "x³", |k3, s| k3 * s.x * s.x * s.x;
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use stf_core::physics::force_model::{ForceModel, ModelState};

    #[test]
    fn force_is_k3_x_cubed_whatever_the_velocity() {
        let m = CubicStiffness::new();
        let s = ModelState {
            t: 0.0,
            x: -0.02,
            v: 3.0,
            z: &[],
        };
        // 2e5·(−0.02)³ = 2e5·(−8e-6) = −1.6 N.
        assert_relative_eq!(
            m.force(&[2e5], &s, &mut []).unwrap(),
            -1.6,
            max_relative = 1e-12
        );
    }

    #[test]
    fn force_gradient_and_equation_follow_the_one_law() {
        let m = CubicStiffness::new();
        let x = 0.0123456789;
        let s = ModelState {
            t: 0.0,
            x,
            v: 0.0,
            z: &[],
        };
        let k3 = 3.3e5;
        assert_eq!(m.force(&[k3], &s, &mut []).unwrap(), k3 * x * x * x);
        let mut grad = [f64::NAN];
        assert!(m.gradient(&[k3], &s, 0.0, &mut grad).unwrap());
        assert_eq!(grad[0], x * x * x);
        assert_eq!(m.equation(&["19 987".into()]).as_deref(), Some("19 987·x³"));
        assert!(m.force(&[], &s, &mut []).is_err());
    }
}
