//! `viscous`: a Newtonian fluid, `F = c_s·v`.
//!
//! The baseline every thickening model is compared with.
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `c_s` | N·s/m | 2 | [0, 1e4] | damping coefficient of the fluid |

use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::linear_builtin;

linear_builtin! {
    /// Newtonian drag of the blade, `F = c_s·v`.
    ///
    /// The baseline every thickening model is compared with: force proportional to the blade's
    /// velocity, as for a Newtonian liquid in laminar flow around the blade.
    Viscous: "viscous", "Newtonian drag F = c_s·v",
    param ParamSpec::new("c_s", "N·s/m", 2.0, 0.0, 1e4, "damping coefficient of the fluid")
        .same_as("c");
    law "v", |c_s, s| c_s * s.v;
}

#[cfg(test)]
mod tests {
    use super::*;
    use stf_core::physics::force_model::{ForceModel, ModelState};

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
