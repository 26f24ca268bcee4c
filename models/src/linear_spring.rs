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

use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::linear_builtin;

linear_builtin! {
    /// Linear spring; see the [module doc](self).
    LinearSpring: "linear_spring",
    "elastic element F = k_s·x (an accumulator, a clamp)",
    param ParamSpec::new("k_s", "N/m", 10.0, 0.0, 1e6, "stiffness the element adds")
        .same_as("k");
    law "x", |k_s, s| k_s * s.x;
}

#[cfg(test)]
mod tests {
    use super::*;
    use stf_core::physics::force_model::{ForceModel, ModelState};

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
