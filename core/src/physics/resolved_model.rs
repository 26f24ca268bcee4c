//! A force model resolved once for an integration: a sum's parts (and the parts of any sum
//! among them) as one flat list, each with the range of its parameters and internal states.
//!
//! An integrator calls the model at every right-hand-side evaluation, tens of thousands of
//! times a simulation. Called as a [`ModelSum`](crate::physics::model_sum::ModelSum) through
//! `dyn ForceModel`, a sum of two models costs three indirect calls and the sum's own
//! bookkeeping (each part's state and parameter slices) at every call; resolved, it costs one
//! indirect call a part. The arithmetic is the sum's own: added masses and forces added from
//! zero in the parts' order (a nested sum's parts in place, which adds the same numbers in
//! the same order), so a simulation is the same to the bit.

use std::ops::Range;
use std::sync::Arc;

use crate::physics::force_model::{ForceModel, ModelError, ModelState};

/// One model of a resolved sum: its parameters and internal states in the whole model's.
#[derive(Clone)]
struct Part {
    model: Arc<dyn ForceModel>,
    params: Range<usize>,
    states: Range<usize>,
}

/// A force model as an integration calls it (see the [module doc](self)).
#[derive(Clone)]
pub struct ResolvedModel {
    /// The leaves: a model that is not a sum is its own only part.
    parts: Vec<Part>,
    /// Whether the model is a sum (its parts' added masses and forces are added from zero).
    sum: bool,
}

impl ResolvedModel {
    /// `model` resolved: a sum ([`ForceModel::summands`]) into its leaves.
    pub fn new(model: &Arc<dyn ForceModel>) -> Self {
        let mut parts = Vec::new();
        let sum = model.summands().is_some();
        flatten(model, 0, 0, &mut parts);
        ResolvedModel { parts, sum }
    }

    /// [`ForceModel::mass_and_force`] of the model: `p` its parameters, `s` the state with
    /// all of its internal states, `dz` their rates.
    #[inline(always)]
    pub fn mass_and_force(
        &self,
        p: &[f64],
        s: &ModelState,
        dz: &mut [f64],
    ) -> Result<(f64, f64), ModelError> {
        if !self.sum {
            return self.parts[0].model.mass_and_force(p, s, dz);
        }
        let (mut mass, mut force) = (0.0, 0.0);
        for part in &self.parts {
            let local = ModelState {
                z: &s.z[part.states.clone()],
                ..*s
            };
            let (m, f) = part.model.mass_and_force(
                &p[part.params.clone()],
                &local,
                &mut dz[part.states.clone()],
            )?;
            mass += m;
            force += f;
        }
        Ok((mass, force))
    }
}

/// Push `model`'s leaves onto `out`, its parameters from `param` and states from `state` on.
fn flatten(model: &Arc<dyn ForceModel>, param: usize, state: usize, out: &mut Vec<Part>) {
    let Some(summands) = model.summands() else {
        out.push(Part {
            model: model.clone(),
            params: param..param + model.params().len(),
            states: state..state + model.n_internal(),
        });
        return;
    };
    let (mut param, mut state) = (param, state);
    for part in summands {
        flatten(part, param, state, out);
        param += part.params().len();
        state += part.n_internal();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::model_sum::ModelSum;
    use crate::physics::param_spec::ParamSpec;

    /// `m_a = p[1]`, `f = p[0]·v + z[0]` (one state, `ż = p[0]·x − z` when `stateful`).
    struct Part2(&'static str, Vec<ParamSpec>, bool);
    impl ForceModel for Part2 {
        fn name(&self) -> &str {
            self.0
        }
        fn params(&self) -> &[ParamSpec] {
            &self.1
        }
        fn n_internal(&self) -> usize {
            usize::from(self.2)
        }
        fn added_mass(&self, p: &[f64], _s: &ModelState) -> Result<f64, ModelError> {
            Ok(p[1])
        }
        fn force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, ModelError> {
            if p[0] < 0.0 {
                return Err(ModelError::new(self.0, "negative"));
            }
            let z = s.z.first().copied().unwrap_or(0.0);
            if let Some(d) = dz.first_mut() {
                *d = p[0] * s.x - z;
            }
            Ok(p[0] * s.v.powf(1.3) + z)
        }
    }

    fn part(name: &'static str, stateful: bool) -> Arc<dyn ForceModel> {
        let spec = |n: &str| ParamSpec::new(n, "", 1.0, -10.0, 10.0, "");
        Arc::new(Part2(name, vec![spec("c"), spec("m")], stateful))
    }

    #[test]
    fn a_nested_sum_resolves_to_its_leaves_and_gives_the_sum_s_numbers_to_the_bit() {
        let inner: Arc<dyn ForceModel> =
            Arc::new(ModelSum::new(vec![part("a", true), part("b", false)]).unwrap());
        let outer: Arc<dyn ForceModel> =
            Arc::new(ModelSum::new(vec![inner, part("c", true), part("d", false)]).unwrap());
        let resolved = ResolvedModel::new(&outer);
        assert_eq!(resolved.parts.len(), 4);
        let p = [0.3, 0.1, 1.7, -0.2, 0.9, 0.05, 2.1, 0.4];
        let z = [0.013, -0.27];
        for (k, v) in [0.0, 1e-3, 0.37, 2.9].into_iter().enumerate() {
            let s = ModelState {
                t: 0.1 * k as f64,
                x: 0.01 - 0.004 * k as f64,
                v,
                z: &z,
            };
            let (mut dz_sum, mut dz_flat) = ([0.0; 2], [0.0; 2]);
            let want = outer.mass_and_force(&p, &s, &mut dz_sum).unwrap();
            let got = resolved.mass_and_force(&p, &s, &mut dz_flat).unwrap();
            assert_eq!(want.0.to_bits(), got.0.to_bits());
            assert_eq!(want.1.to_bits(), got.1.to_bits());
            assert_eq!(dz_sum.map(f64::to_bits), dz_flat.map(f64::to_bits));
        }
        let mut bad = p;
        bad[4] = -1.0;
        let s = ModelState {
            t: 0.0,
            x: 0.0,
            v: 1.0,
            z: &z,
        };
        let err = resolved
            .mass_and_force(&bad, &s, &mut [0.0; 2])
            .unwrap_err();
        assert_eq!(err.model, "c");
    }

    /// A sum widened to a record's scale (other bounds, same force) resolves to the sum's
    /// parts, and an oscillator simulated with it is the sum's to the bit.
    #[test]
    fn a_widened_sum_resolves_to_the_sum_s_parts_and_simulates_to_the_bit() {
        use crate::data::record_bounds::{widened, DataScales};
        use crate::physics::excitation::{Excitation, RotorAngle};
        use crate::physics::oscillator::Oscillator;
        use crate::physics::oscillator_params::OscillatorParams;
        use crate::simulate::Simulation;

        /// `m_a = p[1]`, `f = p[0]·v + z` with `ż = p[0]·x − z`: smooth for either sign of v.
        struct Lin(&'static str, Vec<ParamSpec>);
        impl ForceModel for Lin {
            fn name(&self) -> &str {
                self.0
            }
            fn params(&self) -> &[ParamSpec] {
                &self.1
            }
            fn n_internal(&self) -> usize {
                1
            }
            fn added_mass(&self, p: &[f64], _s: &ModelState) -> Result<f64, ModelError> {
                Ok(p[1])
            }
            fn force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, ModelError> {
                dz[0] = p[0] * s.x - s.z[0];
                Ok(p[0] * s.v + s.z[0])
            }
        }
        let spec = |n: &str, unit: &str| ParamSpec::new(n, unit, 0.5, 0.0, 10.0, "");
        let lin = |name: &'static str| -> Arc<dyn ForceModel> {
            Arc::new(Lin(name, vec![spec("c", "N·s/m"), spec("m", "kg")]))
        };
        let sum: Arc<dyn ForceModel> = Arc::new(ModelSum::new(vec![lin("a"), lin("b")]).unwrap());
        // A 95 kg axis pushed by 60 N: the added mass's bound is raised, so the sum is wrapped.
        let axis = DataScales {
            force: 60.0,
            x: 0.25,
            v: 0.5,
            a: 1.0,
        };
        let wide = widened(sum.clone(), &axis);
        assert_ne!(wide.params(), sum.params(), "the bounds changed");
        assert!(wide.summands().is_some(), "a widened sum is still a sum");
        let (of_sum, of_wide) = (ResolvedModel::new(&sum), ResolvedModel::new(&wide));
        let names = |r: &ResolvedModel| -> Vec<(String, Range<usize>, Range<usize>)> {
            r.parts
                .iter()
                .map(|p| {
                    (
                        p.model.name().to_string(),
                        p.params.clone(),
                        p.states.clone(),
                    )
                })
                .collect()
        };
        assert_eq!(names(&of_wide), names(&of_sum));
        assert_eq!(of_wide.parts.len(), 2);
        assert!(of_wide.sum);
        let p = vec![0.4, 0.02, 0.7, 0.01];
        let run = |model: &Arc<dyn ForceModel>| {
            let osc = Oscillator::new(
                OscillatorParams::FORCED,
                Excitation::Rotor(RotorAngle::constant(6.0)),
            )
            .with_model(model.clone(), p.clone())
            .unwrap();
            Simulation::new(&osc).rate(200.0).run(0.0, 3.0).unwrap()
        };
        let (want, got) = (run(&sum), run(&wide));
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
        assert_eq!(bits(&got.x), bits(&want.x));
        assert_eq!(bits(&got.f_stf), bits(&want.f_stf));
        assert!(want.x.iter().any(|x| x.abs() > 1e-4), "the rig moved");
    }

    #[test]
    fn a_lone_model_is_called_as_it_is() {
        let lone = part("a", true);
        let resolved = ResolvedModel::new(&lone);
        let s = ModelState {
            t: 0.0,
            x: 0.2,
            v: -0.0,
            z: &[-0.0],
        };
        let (mut a, mut b) = ([0.0], [0.0]);
        let want = lone.mass_and_force(&[0.0, -0.0], &s, &mut a).unwrap();
        let got = resolved.mass_and_force(&[0.0, -0.0], &s, &mut b).unwrap();
        assert_eq!(
            (want.0.to_bits(), want.1.to_bits()),
            (got.0.to_bits(), got.1.to_bits())
        );
    }
}
