//! `yield`: a velocity-independent resistance, `F = F_y·v/√(v² + v_s²)` ≈ `F_y·sign v`.
//!
//! A jammed plug in front of the blade behaves like a solid with a yield stress: once it
//! flows, the resistance hardly depends on the speed (Coulomb-like, as a Bingham fluid's
//! yield term or the frictional contacts of a jammed granular network). The sign function is
//! smoothed over a small speed `v_s` so the right-hand side of the ODE stays continuous; for
//! |v| ≫ v_s the force is F_y·sign v, at v = 0 it is zero. The force opposes the motion
//! (F·v ≥ 0) and is odd in v. A small `v_s` makes the equation stiff while the blade nearly
//! stops (step ≈ m·v_s/F_y for an explicit integrator), so do not make it smaller than needed.
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `F_y` | N | 0.2 | [0, 50] | yield force of the jammed plug |
//! | `v_s` | m/s | 1e-3 | [1e-6, 0.1] | speed over which the sign is smoothed |
//!
//! The file is `yield_stress.rs` because `yield` is a reserved word in Rust; the model's
//! name is `yield`.

use stf_core::physics::force_model::{ModelError, ModelState};
use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::builtin;
use crate::values::take;

builtin! {
    /// Velocity-independent yield resistance; see the [module doc](self).
    Yield: "yield",
    "yield (Coulomb-like) resistance F ≈ F_y·sign v",
    params [
        ParamSpec::new("F_y", "N", 0.2, 0.0, 50.0, "yield force of the jammed plug"),
        ParamSpec::new("v_s", "m/s", 1e-3, 1e-6, 0.1, "speed over which sign v is smoothed"),
    ];
    impl {
        /// The law with its values, `f_y·v/√(v² + (v_s)²)`.
        fn equation(&self, values: &[String]) -> Option<String> {
            let [f_y, v_s] = values else { return None };
            Some(format!("{f_y}·v/√(v² + ({v_s})²)"))
        }
        #[inline]
        fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
            let [f_y, v_s] = take(self.name(), p)?;
            let norm = s.v.hypot(v_s);
            Ok(if norm > 0.0 { f_y * s.v / norm } else { 0.0 })
        }
        fn gradient(
            &self,
            p: &[f64],
            s: &ModelState,
            _a: f64,
            grad: &mut [f64],
        ) -> Result<bool, ModelError> {
            let [f_y, v_s] = take(self.name(), p)?;
            let norm = s.v.hypot(v_s);
            let (df, dv) = if norm > 0.0 {
                (s.v / norm, -f_y * s.v * v_s / (norm * norm * norm))
            } else {
                (0.0, 0.0)
            };
            grad[..2].copy_from_slice(&[df, dv]);
            Ok(true)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use stf_core::physics::force_model::ForceModel;

    fn at(v: f64, p: &[f64]) -> f64 {
        let s = ModelState {
            t: 0.0,
            x: 0.0,
            v,
            z: &[],
        };
        Yield::new().force(p, &s, &mut []).unwrap()
    }

    #[test]
    fn force_is_f_y_sign_v_smoothed() {
        // v = v_s·√3 gives exactly F_y·√3/2 (v/√(v² + v_s²) = √3/√4).
        let v_s = 1e-3;
        assert_relative_eq!(
            at(v_s * 3f64.sqrt(), &[0.4, v_s]),
            0.4 * 3f64.sqrt() / 2.0,
            max_relative = 1e-12
        );
        // Far above v_s: within 1e-6 of −F_y.
        assert!((at(-1.0, &[0.4, v_s]) + 0.4).abs() < 1e-6);
        assert_eq!(at(0.0, &[0.4, v_s]), 0.0);
        // A zero smoothing speed is a sharp sign, still finite at rest.
        assert_eq!(at(0.0, &[0.4, 0.0]), 0.0);
        assert_relative_eq!(at(-0.2, &[0.4, 0.0]), -0.4, max_relative = 1e-15);
    }
}
