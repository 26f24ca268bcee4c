//! Sums of force models: `power_law + added_mass` is a model.
//!
//! The parameters of a sum are those of its parts, in order. A bare parameter name that more
//! than one part uses is prefixed with its model's name (`power_law.K`); every parameter can
//! also be addressed by its prefixed name, clash or not. Internal states are stacked the same
//! way. Forces and added masses add. A sum knows its terms as a list ([`ForceModel::terms`]);
//! its name `a + b` is only their display (reports, JSON keys), never split again.

use std::sync::Arc;

use crate::physics::force_model::{ForceModel, ModelError, ModelState};
use crate::physics::param_spec::ParamSpec;
use crate::physics::track::Track;

/// The factor of its default that an added term's amplitude (its first parameter, by the
/// models' convention) starts at when the term starts neutral: a millionth of its default's
/// contribution, nothing against the rest of the sum, yet inside its bounds, where a fit's
/// bound map is not flat. A sum started so, from the optimum of the sum without that term,
/// starts at that optimum's residual and, since a fit never ends worse than its start, ends
/// no worse.
pub const NEUTRAL_AMPLITUDE: f64 = 1e-6;

/// The neutral start of `model`'s amplitude ([`NEUTRAL_AMPLITUDE`] × its first parameter's
/// default), if it has one: a positive default and a lower bound at or below the neutral
/// value.
pub fn neutral_amplitude(model: &dyn ForceModel) -> Option<f64> {
    let spec = model.params().first()?;
    let v = NEUTRAL_AMPLITUDE * spec.default;
    (spec.default > 0.0 && spec.min <= v && v <= spec.max).then_some(v)
}

/// A sum of force models, itself a [`ForceModel`].
pub struct ModelSum {
    name: String,
    parts: Vec<Arc<dyn ForceModel>>,
    specs: Vec<ParamSpec>,
    /// Start of each part's parameters in `specs`, then their end (one entry more than the
    /// parts: no part is asked its sizes per sample).
    param_offsets: Vec<usize>,
    /// Start of each part's internal states, then their end.
    state_offsets: Vec<usize>,
}

impl ModelSum {
    /// The sum of `parts`. Two parts of the same name are an error (their parameters could
    /// not be told apart); an empty sum is the zero force, named `none`, and drops out of any
    /// sum it is a part of (`none + cubic_stiffness` is `cubic_stiffness`).
    pub fn new(parts: Vec<Arc<dyn ForceModel>>) -> Result<Self, ModelError> {
        let parts: Vec<Arc<dyn ForceModel>> = parts
            .into_iter()
            .filter(|p| !(p.name() == "none" && p.params().is_empty() && p.n_internal() == 0))
            .collect();
        for (i, a) in parts.iter().enumerate() {
            if parts[..i].iter().any(|b| b.name() == a.name()) {
                return Err(ModelError::new(
                    a.name(),
                    "appears twice in a sum of models; each part must have its own name",
                ));
            }
        }
        let mut specs = Vec::new();
        let mut param_offsets = Vec::new();
        let mut state_offsets = Vec::new();
        let mut n_internal = 0;
        for part in &parts {
            param_offsets.push(specs.len());
            state_offsets.push(n_internal);
            n_internal += part.n_internal();
            for spec in part.params() {
                let clashes = parts
                    .iter()
                    .filter(|other| other.params().iter().any(|s| s.name == spec.name))
                    .count()
                    > 1;
                let mut spec = spec.clone();
                if clashes && parts.len() > 1 {
                    spec.name = format!("{}.{}", part.name(), spec.name);
                }
                specs.push(spec);
            }
        }
        param_offsets.push(specs.len());
        state_offsets.push(n_internal);
        let terms: Vec<&str> = parts.iter().flat_map(|p| p.terms()).collect();
        let name = if terms.is_empty() {
            "none".to_string()
        } else {
            terms.join(" + ")
        };
        Ok(ModelSum {
            name,
            parts,
            specs,
            param_offsets,
            state_offsets,
        })
    }

    /// The parts of the sum.
    pub fn parts(&self) -> &[Arc<dyn ForceModel>] {
        &self.parts
    }

    /// Index of a parameter given by its name in the sum (`K`, or `power_law.K`) or by
    /// `model.param` even where the bare name is unique.
    pub fn param_index(&self, name: &str) -> Option<usize> {
        if let Some(i) = self.specs.iter().position(|s| s.name == name) {
            return Some(i);
        }
        let (model, param) = name.split_once('.')?;
        let part = self.parts.iter().position(|p| p.name() == model)?;
        let local = self.parts[part]
            .params()
            .iter()
            .position(|s| s.name == param)?;
        Some(self.param_offsets[part] + local)
    }

    fn part_slices<'a>(&self, i: usize, p: &'a [f64]) -> &'a [f64] {
        &p[self.param_offsets[i]..self.param_offsets[i + 1]]
    }

    /// The internal states of part `i` (their range in the sum's).
    fn states(&self, i: usize) -> std::ops::Range<usize> {
        self.state_offsets[i]..self.state_offsets[i + 1]
    }

    /// The state part `i` sees: the sum's `s` with its own internal states only.
    fn local<'s>(&self, i: usize, s: &ModelState<'s>) -> ModelState<'s> {
        ModelState {
            z: &s.z[self.states(i)],
            ..*s
        }
    }
}

impl ForceModel for ModelSum {
    fn name(&self) -> &str {
        &self.name
    }

    fn summary(&self) -> &str {
        "a sum of force models"
    }

    fn terms(&self) -> Vec<&str> {
        self.parts.iter().flat_map(|p| p.terms()).collect()
    }

    /// The parts' terms joined by `+` (or `−` before a term with a negative coefficient);
    /// `0` for the zero force.
    fn equation(&self, values: &[String]) -> Option<String> {
        if values.len() != self.specs.len() {
            return None;
        }
        let mut text = String::new();
        for (i, part) in self.parts.iter().enumerate() {
            let term = part.equation(&values[self.param_offsets[i]..self.param_offsets[i + 1]])?;
            match (text.is_empty(), term.strip_prefix('-')) {
                (true, _) => text = term,
                (false, Some(rest)) => text.push_str(&format!(" − {rest}")),
                (false, None) => text.push_str(&format!(" + {term}")),
            }
        }
        Some(if text.is_empty() { "0".into() } else { text })
    }

    fn summands(&self) -> Option<&[Arc<dyn ForceModel>]> {
        Some(&self.parts)
    }

    fn params(&self) -> &[ParamSpec] {
        &self.specs
    }

    fn n_internal(&self) -> usize {
        self.state_offsets[self.parts.len()]
    }

    fn initial_internal(&self, p: &[f64], z0: &mut [f64]) {
        for (i, part) in self.parts.iter().enumerate() {
            part.initial_internal(self.part_slices(i, p), &mut z0[self.states(i)]);
        }
    }

    fn added_mass(&self, p: &[f64], s: &ModelState) -> Result<f64, ModelError> {
        let mut total = 0.0;
        for (i, part) in self.parts.iter().enumerate() {
            let local = self.local(i, s);
            total += part.added_mass(self.part_slices(i, p), &local)?;
        }
        Ok(total)
    }

    fn force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, ModelError> {
        let mut total = 0.0;
        for (i, part) in self.parts.iter().enumerate() {
            let states = self.states(i);
            let local = self.local(i, s);
            total += part.force(self.part_slices(i, p), &local, &mut dz[states])?;
        }
        Ok(total)
    }

    fn mass_and_force(
        &self,
        p: &[f64],
        s: &ModelState,
        dz: &mut [f64],
    ) -> Result<(f64, f64), ModelError> {
        let (mut mass, mut force) = (0.0, 0.0);
        for (i, part) in self.parts.iter().enumerate() {
            let states = self.states(i);
            let local = self.local(i, s);
            let (m, f) = part.mass_and_force(self.part_slices(i, p), &local, &mut dz[states])?;
            mass += m;
            force += f;
        }
        Ok((mass, force))
    }

    fn rates(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<(), ModelError> {
        for (i, part) in self.parts.iter().enumerate() {
            let states = self.states(i);
            if states.is_empty() {
                continue;
            }
            let local = self.local(i, s);
            part.rates(self.part_slices(i, p), &local, &mut dz[states])?;
        }
        Ok(())
    }

    /// Each part along the whole record in turn, its added mass and force added in the
    /// parts' order (as [`ForceModel::mass_and_force`] adds them sample by sample).
    fn mass_and_force_along(
        &self,
        p: &[f64],
        track: &Track,
        rows: Option<&[usize]>,
        mass: &mut [f64],
        force: &mut [f64],
    ) -> Result<(), ModelError> {
        for (i, part) in self.parts.iter().enumerate() {
            part.mass_and_force_along(self.part_slices(i, p), track, rows, mass, force)?;
        }
        Ok(())
    }

    /// A sum of one part is that part; a sum of several adds its parts sample by sample and
    /// is not integrated side by side.
    fn mass_and_force_lanes(
        &self,
        ps: &[&[f64]],
        track: &Track,
        rows: Option<&[usize]>,
    ) -> Option<Vec<(Vec<f64>, Vec<f64>)>> {
        match self.parts.as_slice() {
            [one] => one.mass_and_force_lanes(ps, track, rows),
            _ => None,
        }
    }

    /// Each memoryless part's columns from its own gradient along the record; NaN in the
    /// columns of a part with state or without a gradient (differenced by the fitter).
    fn gradient_along(
        &self,
        p: &[f64],
        track: &Track,
        a: &[f64],
        rows: Option<&[usize]>,
        grad: &mut [f64],
    ) -> Result<bool, ModelError> {
        let n = track.len_at(rows);
        let mut any = false;
        for (i, part) in self.parts.iter().enumerate() {
            let (start, end) = (self.param_offsets[i], self.param_offsets[i + 1]);
            let own = &mut grad[start * n..end * n];
            let given = self.states(i).is_empty()
                && part.gradient_along(&p[start..end], track, a, rows, own)?;
            if !given {
                own.fill(f64::NAN);
            }
            any |= given;
        }
        Ok(any)
    }

    fn gradient(
        &self,
        p: &[f64],
        s: &ModelState,
        a: f64,
        grad: &mut [f64],
    ) -> Result<bool, ModelError> {
        // A part with state gets NaN entries (differenced by the fitter); a memoryless part
        // sees no state. Without any part's gradient there is none.
        let mut any = false;
        for (i, part) in self.parts.iter().enumerate() {
            let (start, end) = (self.param_offsets[i], self.param_offsets[i + 1]);
            let own = &mut grad[start..end];
            let given = self.states(i).is_empty() && {
                let local = ModelState { z: &[], ..*s };
                part.gradient(&p[start..end], &local, a, own)?
            };
            if !given {
                own.fill(f64::NAN);
            }
            any |= given;
        }
        Ok(any)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Lin(&'static str, Vec<ParamSpec>);
    impl ForceModel for Lin {
        fn name(&self) -> &str {
            self.0
        }
        fn params(&self) -> &[ParamSpec] {
            &self.1
        }
        fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
            Ok(p[0] * s.v)
        }
    }

    fn lin(name: &'static str, param: &str) -> Arc<dyn ForceModel> {
        Arc::new(Lin(
            name,
            vec![ParamSpec::new(param, "", 1.0, 0.0, 10.0, "")],
        ))
    }

    #[test]
    fn clashing_names_are_prefixed_and_forces_add() {
        let sum = ModelSum::new(vec![lin("a", "c"), lin("b", "c"), lin("d", "e")]).unwrap();
        let names: Vec<_> = sum.params().iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["a.c", "b.c", "e"]);
        assert_eq!(sum.param_index("d.e"), Some(2));
        assert_eq!(sum.param_index("b.c"), Some(1));
        assert_eq!(sum.param_index("c"), None);
        let s = ModelState {
            t: 0.0,
            x: 0.0,
            v: 2.0,
            z: &[],
        };
        assert_eq!(sum.force(&[1.0, 2.0, 3.0], &s, &mut []).unwrap(), 12.0);
        assert_eq!(sum.name(), "a + b + d");
    }

    #[test]
    fn a_sum_lists_its_terms_flat_and_the_zero_sum_has_none() {
        let inner: Arc<dyn ForceModel> =
            Arc::new(ModelSum::new(vec![lin("a", "c"), lin("b", "e")]).unwrap());
        assert_eq!(inner.terms(), ["a", "b"]);
        let outer = ModelSum::new(vec![inner, lin("d", "f")]).unwrap();
        assert_eq!(outer.terms(), ["a", "b", "d"]);
        assert_eq!(outer.name(), "a + b + d");
        assert_eq!(lin("a", "c").terms(), ["a"]);
        let zero: Arc<dyn ForceModel> = Arc::new(ModelSum::new(Vec::new()).unwrap());
        assert!(zero.terms().is_empty());
        assert_eq!(zero.name(), "none");
        let with_zero = ModelSum::new(vec![zero, lin("d", "f")]).unwrap();
        assert_eq!((with_zero.terms(), with_zero.name()), (vec!["d"], "d"));
    }

    #[test]
    fn a_part_twice_is_an_error() {
        assert!(ModelSum::new(vec![lin("a", "c"), lin("a", "c")]).is_err());
    }
}
