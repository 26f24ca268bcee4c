//! `viscous`: a Newtonian fluid, `F = c_s·v`.
//!
//! The baseline every thickening model is compared with.
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `c_s` | N·s/m | 2 | [0, 1e4] | damping coefficient of the fluid |

use stf_core::physics::force_model::{ForceModel, ModelError, ModelState};
use stf_core::physics::param_spec::ParamSpec;

use crate::values::take;

/// One line for listings.
pub const SUMMARY: &str = "Newtonian drag F = c_s·v";

/// Newtonian drag of the blade, `F = c_s·v`.
///
/// The baseline every thickening model is compared with: force proportional to the blade's
/// velocity, as for a Newtonian liquid in laminar flow around the blade.
pub struct Viscous {
    specs: Vec<ParamSpec>,
}

impl Viscous {
    /// The model with its parameter `c_s`.
    pub fn new() -> Self {
        Viscous {
            specs: vec![ParamSpec::new(
                "c_s",
                "N·s/m",
                2.0,
                0.0,
                1e4,
                "damping coefficient of the fluid",
            )
            .same_as("c")],
        }
    }
}

impl Default for Viscous {
    fn default() -> Self {
        Self::new()
    }
}

impl ForceModel for Viscous {
    fn name(&self) -> &str {
        "viscous"
    }
    fn summary(&self) -> &str {
        SUMMARY
    }
    fn params(&self) -> &[ParamSpec] {
        &self.specs
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

#[cfg(test)]
mod tests {
    use super::*;

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
