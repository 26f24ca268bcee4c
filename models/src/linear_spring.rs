//! `linear_spring`: an elastic element in parallel with the blade, `F = k_s·x`.
//!
//! A gas accumulator, a clamp or the elastic part of a jammed network adds a stiffness to the
//! rig's own springs. It is conservative and odd in x. On a rig whose oscillator stiffness `k`
//! is refitted (trajectory level) it is the same term of the equation as `k`, so a fit frees
//! one of the two, never both, and discovery does not try it while `k` is refitted: there
//! only the sum k + k_s is identifiable. At force level `k` is known and k_s is what the
//! measured force adds to it.
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `k_s` | N/m | 10 | [0, 1e6] | stiffness the element adds (widened to the record's F/X) |

use stf_core::physics::force_model::{ModelError, ModelState};
use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::builtin;
use crate::values::take;

builtin! {
    /// Linear spring; see the [module doc](self).
    LinearSpring: "linear_spring",
    "elastic element F = k_s·x (an accumulator, a clamp)",
    params [
        ParamSpec::new("k_s", "N/m", 10.0, 0.0, 1e6, "stiffness the element adds")
            .same_as("k"),
    ];
    impl {
        /// The law with its values, `k_s·x`.
        fn equation(&self, values: &[String]) -> Option<String> {
            let [k_s] = values else { return None };
            Some(format!("{k_s}·x"))
        }
        #[inline]
        fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
            let [k_s] = take(self.name(), p)?;
            Ok(k_s * s.x)
        }
        fn gradient(
            &self,
            p: &[f64],
            s: &ModelState,
            _a: f64,
            grad: &mut [f64],
        ) -> Result<bool, ModelError> {
            take::<1>(self.name(), p)?;
            grad[0] = s.x;
            Ok(true)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use stf_core::physics::force_model::ForceModel;

    #[test]
    fn force_is_k_s_x_whatever_the_velocity() {
        let m = LinearSpring::new();
        let s = ModelState {
            t: 0.0,
            x: -0.02,
            v: 3.0,
            z: &[],
        };
        assert_eq!(m.force(&[50.0], &s, &mut []).unwrap(), -1.0);
    }
}
