//! `added_mass`: fluid carried along with the blade, `F = m_a·ẍ`.
//!
//! A blade that accelerates must also accelerate some of the fluid around it. In a Newtonian
//! liquid that is the potential-flow added mass; in a dense suspension struck fast enough,
//! Waitukaitis & Jaeger (Nature 487, 205, 2012) saw a jammed, solid-like front propagate
//! ahead of the impactor and move with it, so the blade drags a plug of fluid whose inertia
//! shows up as a force in phase with the acceleration. The model returns `m_a` from
//! [`ForceModel::added_mass`] and no other force; the oscillator moves `m_a` to the
//! left-hand side (`(m + m_a)·ẍ = …`). It stores energy (kinetic), it does not dissipate.
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `m_a` | kg | 0.5 | [0, 20] | mass of fluid moving with the blade |

use stf_core::physics::force_model::{ModelError, ModelState};
use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::builtin;
use crate::values::take;

builtin! {
    /// Added mass of fluid carried by the blade; see the [module doc](self).
    AddedMass: "added_mass",
    "fluid moving with the blade F = m_a·ẍ",
    params [
        ParamSpec::new("m_a", "kg", 0.5, 0.0, 20.0, "mass of fluid carried along with the blade")
            .same_as("m"),
    ];
    impl {
        /// The law with its values, `m_a·ẍ`.
        fn equation(&self, values: &[String]) -> Option<String> {
            let [m_a] = values else { return None };
            Some(format!("{m_a}·ẍ"))
        }
        #[inline]
        fn added_mass(&self, p: &[f64], _s: &ModelState) -> Result<f64, ModelError> {
            let [m_a] = take(self.name(), p)?;
            Ok(m_a)
        }
        #[inline]
        fn force(&self, p: &[f64], _s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
            take::<1>(self.name(), p)?;
            Ok(0.0)
        }
        fn gradient(
            &self,
            p: &[f64],
            _s: &ModelState,
            a: f64,
            grad: &mut [f64],
        ) -> Result<bool, ModelError> {
            take::<1>(self.name(), p)?;
            grad[0] = a;
            Ok(true)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use stf_core::physics::excitation::{Excitation, RotorAngle};
    use stf_core::physics::force_model::ForceModel;
    use stf_core::physics::oscillator::Oscillator;
    use stf_core::physics::oscillator_params::OscillatorParams;

    #[test]
    fn added_mass_is_the_parameter_and_the_rest_of_the_force_is_zero() {
        let m = AddedMass::new();
        let s = ModelState {
            t: 1.0,
            x: 0.01,
            v: 0.2,
            z: &[],
        };
        assert_eq!(m.added_mass(&[1.5], &s).unwrap(), 1.5);
        assert_eq!(m.force(&[1.5], &s, &mut []).unwrap(), 0.0);
        assert_eq!(m.params()[0].name, "m_a");
    }

    #[test]
    fn the_oscillator_sees_the_heavier_mass() {
        // Free oscillator without friction or drive: ẍ = −k·x/(m + m_a) at x = 0.01, v = 0.
        let params = OscillatorParams {
            c: 0.0,
            t_friction: 0.0,
            delta_t: 0.0,
            f0: 0.0,
            ..OscillatorParams::FORCED
        };
        let osc = Oscillator::new(params, Excitation::Rotor(RotorAngle::constant(0.0)))
            .with_model(Arc::new(AddedMass::new()), vec![2.35])
            .unwrap();
        let f = osc.forces(0.0, &[0.01, 0.0], &mut []).unwrap();
        let a = -params.k * 0.01 / (params.m + 2.35);
        assert!((f.a - a).abs() < 1e-12 * a.abs());
        assert!((f.f_stf - 2.35 * a).abs() < 1e-12);
    }
}
