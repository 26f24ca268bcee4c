//! A model as it stands in the search, at either level: its parts (the base, then the
//! effects added) and the values of every parameter of its fit.
//!
//! The values are laid out as the level's fit lists its parameters: at trajectory level the
//! refitted oscillator parameters first, then the model's (part by part), then the offset if
//! fitted; at force level the same without the oscillator's. How a stage is fitted and
//! scored is the level's own (force fits in [`super::force_level`], simulations in
//! [`super::trajectory_level`]).

use std::sync::Arc;

use super::candidate::Candidate;
use super::error::DiscoveryError;
use crate::fit::{FitError, FitResult};
use crate::physics::force_model::ForceModel;
use crate::physics::model_sum::ModelSum;

/// A model as it stands: its parts and the values of every parameter of its fit.
#[derive(Clone)]
pub(super) struct SearchModel {
    /// The base, then the effects added, in order.
    pub parts: Vec<Arc<dyn ForceModel>>,
    /// Start (or fitted) values of every parameter of the fit: the level's own first (the
    /// oscillator's at trajectory level), then the sum's, then the offset if fitted.
    pub values: Vec<f64>,
}

impl SearchModel {
    /// `base` alone at its defaults, after the level's own start values `own`, with the
    /// offset (0) if `offset` is fitted.
    pub fn at_defaults(base: &Arc<dyn ForceModel>, own: &[f64], offset: bool) -> SearchModel {
        let values = own.iter().copied();
        let values = values.chain(base.params().iter().map(|s| s.default));
        SearchModel {
            values: values.chain(offset.then_some(0.0)).collect(),
            parts: vec![base.clone()],
        }
    }

    /// The model: the one part, or the sum of the parts.
    pub fn model(&self) -> Result<Arc<dyn ForceModel>, DiscoveryError> {
        Ok(match self.parts.as_slice() {
            [one] => one.clone(),
            _ => Arc::new(ModelSum::new(self.parts.clone())?),
        })
    }

    /// A fit's error `source` as this stage's.
    pub fn fit_error(&self, source: FitError) -> DiscoveryError {
        DiscoveryError::Fit {
            model: self.name(),
            source,
        }
    }

    /// This stage at the values of its fit `fitted`, and the fit (or its error, as this
    /// stage's).
    pub fn fitted(
        &self,
        fitted: Result<FitResult, FitError>,
    ) -> Result<(SearchModel, FitResult), DiscoveryError> {
        let result = fitted.map_err(|e| self.fit_error(e))?;
        let stage = SearchModel {
            parts: self.parts.clone(),
            values: result.params.iter().map(|p| p.value).collect(),
        };
        Ok((stage, result))
    }

    /// The parts' names joined by ` + ` (`power_law + viscous`; the zero force `none` drops out
    /// once another part joins it).
    pub fn name(&self) -> String {
        let names: Vec<&str> = self.parts.iter().map(|p| p.name()).collect();
        let real: Vec<&str> = names.iter().copied().filter(|n| *n != "none").collect();
        if real.is_empty() { names } else { real }.join(" + ")
    }

    /// The candidates a step tries: those this stage does not already hold ([`SearchModel::holds`]).
    pub fn to_try<'a>(
        &self,
        candidates: &'a [Candidate],
        in_base: &[String],
        effects: &[String],
    ) -> Vec<&'a Candidate> {
        candidates
            .iter()
            .filter(|c| !self.holds(c, in_base, effects))
            .collect()
    }

    /// Whether candidate `c` is already in the model: its model is a part of the base (whose
    /// parts are named `in_base`) or of this stage, or its name is one of `effects`.
    pub fn holds(&self, c: &Candidate, in_base: &[String], effects: &[String]) -> bool {
        in_base.iter().any(|b| b == c.model.name())
            || self.parts.iter().any(|p| p.name() == c.model.name())
            || effects.contains(&c.name)
    }

    /// This stage with `extra` added last, its parameters at `start`, after the sum's
    /// parameters (which follow the level's `n_before` own) and before the offset.
    pub fn with(&self, extra: &Arc<dyn ForceModel>, start: &[f64], n_before: usize) -> SearchModel {
        self.inserting(self.parts.len(), n_before, extra, start)
    }

    /// Where the parameters of part `index` start among the values: after the level's
    /// `n_before` own and those of the parts before it.
    pub fn start_of(&self, index: usize, n_before: usize) -> usize {
        let before = &self.parts[..index.min(self.parts.len())];
        n_before + before.iter().map(|p| p.params().len()).sum::<usize>()
    }

    /// This stage without its part `index` (its parameters, which follow the level's
    /// `n_before` own, dropped).
    pub fn without(&self, index: usize, n_before: usize) -> SearchModel {
        let from = self.start_of(index, n_before);
        let to = from + self.parts.get(index).map_or(0, |p| p.params().len());
        let mut values = self.values.clone();
        if to <= values.len() {
            values.drain(from..to);
        }
        let mut parts = self.parts.clone();
        if index < parts.len() {
            parts.remove(index);
        }
        SearchModel { parts, values }
    }

    /// This stage with `extra` (its parameters at `start`) inserted as part `index`, its
    /// parameters after the level's `n_before` own and those of the parts before it.
    pub fn inserting(
        &self,
        index: usize,
        n_before: usize,
        extra: &Arc<dyn ForceModel>,
        start: &[f64],
    ) -> SearchModel {
        let index = index.min(self.parts.len());
        let at = self.start_of(index, n_before).min(self.values.len());
        let mut values = self.values.clone();
        values.splice(at..at, start.iter().copied());
        let mut parts = self.parts.clone();
        parts.insert(index, extra.clone());
        SearchModel { parts, values }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::force_model::{ModelError, ModelState};
    use crate::physics::param_spec::ParamSpec;

    /// A force with `n` parameters named `name`.
    struct Params(&'static str, Vec<ParamSpec>);
    impl ForceModel for Params {
        fn name(&self) -> &str {
            self.0
        }
        fn params(&self) -> &[ParamSpec] {
            &self.1
        }
        fn force(&self, _: &[f64], _: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
            Ok(0.0)
        }
    }

    fn model(name: &'static str, n: usize) -> Arc<dyn ForceModel> {
        let spec = (0..n)
            .map(|_| ParamSpec::new("p", "", 1.0, 0.0, 10.0, ""))
            .collect();
        Arc::new(Params(name, spec))
    }

    #[test]
    fn a_part_taken_out_and_put_back_keeps_the_level_s_own_values_and_the_offset() {
        // Two oscillator values, parts of 1, 2 and 1 parameters, an offset.
        let stage = SearchModel {
            parts: vec![model("a", 1), model("b", 2), model("c", 1)],
            values: vec![10.0, 11.0, 1.0, 2.0, 3.0, 4.0, 9.0],
        };
        let rest = stage.without(1, 2);
        assert_eq!(rest.name(), "a + c");
        assert_eq!(rest.values, [10.0, 11.0, 1.0, 4.0, 9.0]);
        let back = rest.inserting(1, 2, &model("b", 2), &[2.0, 3.0]);
        assert_eq!(back.name(), "a + b + c");
        assert_eq!(back.values, stage.values);
        // At force level (no values of its own) the first part goes.
        let force = SearchModel {
            parts: vec![model("a", 1), model("b", 2)],
            values: vec![1.0, 2.0, 3.0],
        };
        assert_eq!(force.without(0, 0).values, [2.0, 3.0]);
        // Inserting last is adding: `with`.
        let with = force.with(&model("c", 1), &[4.0], 0);
        assert_eq!(
            force.inserting(2, 0, &model("c", 1), &[4.0]).values,
            with.values
        );
    }
}
