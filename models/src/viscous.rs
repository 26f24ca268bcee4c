//! `viscous`: a Newtonian fluid, `F = c_s·v`.
//!
//! The baseline every thickening model is compared with.
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `c_s` | N·s/m | 2 | [0, 1e4] | damping coefficient of the fluid |

use stf_core::physics::force_model::{ModelError, ModelState};
use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::builtin;
use crate::values::take;

builtin! {
    /// Newtonian drag of the blade, `F = c_s·v`.
    ///
    /// The baseline every thickening model is compared with: force proportional to the blade's
    /// velocity, as for a Newtonian liquid in laminar flow around the blade.
    Viscous: "viscous", "Newtonian drag F = c_s·v",
    params [
        ParamSpec::new("c_s", "N·s/m", 2.0, 0.0, 1e4, "damping coefficient of the fluid")
            .same_as("c"),
    ];
    impl {
        /// The law with its values, `c_s·v`.
        fn equation(&self, values: &[String]) -> Option<String> {
            let [c_s] = values else { return None };
            Some(format!("{c_s}·v"))
        }
        #[inline]
        fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
            let [c_s] = take(self.name(), p)?;
            Ok(c_s * s.v)
        }
        fn gradient(
            &self,
            p: &[f64],
            s: &ModelState,
            _a: f64,
            grad: &mut [f64],
        ) -> Result<bool, ModelError> {
            take::<1>(self.name(), p)?;
            grad[0] = s.v;
            Ok(true)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use stf_core::physics::force_model::ForceModel;

    #[test]
    fn force_is_proportional_to_velocity() {
        let m = Viscous::new();
        let s = ModelState {
            t: 0.0,
            x: 0.1,
            v: -0.3,
            z: &[],
        };
        assert_eq!(m.force(&[4.0], &s, &mut []).unwrap(), -1.2);
    }
}
