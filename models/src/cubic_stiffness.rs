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

use stf_core::physics::force_model::{ModelError, ModelState};
use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::builtin;
use crate::values::take;

builtin! {
    /// Cubic (Duffing) stiffness; see the [module doc](self).
    CubicStiffness: "cubic_stiffness",
    "elastic jammed network F = k3·x³",
    params [
        ParamSpec::new("k3", "N/m³", 1e5, 0.0, 1e9, "cubic stiffness of the jammed network"),
    ];
    impl {
        /// The law with its values, `k3·x³`.
        fn equation(&self, values: &[String]) -> Option<String> {
            let [k3] = values else { return None };
            Some(format!("{k3}·x³"))
        }
        #[inline]
        fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
            let [k3] = take(self.name(), p)?;
            Ok(k3 * s.x * s.x * s.x)
        }
        fn gradient(
            &self,
            p: &[f64],
            s: &ModelState,
            _a: f64,
            grad: &mut [f64],
        ) -> Result<bool, ModelError> {
            take::<1>(self.name(), p)?;
            grad[0] = s.x * s.x * s.x;
            Ok(true)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use stf_core::physics::force_model::ForceModel;

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
}
