//! Force models the core tests and examples share: a law given as a function of its
//! parameters and the state ([`law`]), and the power law ([`power_law`]).
#![allow(dead_code)]

use std::sync::Arc;

use stf_core::physics::force_model::{ForceModel, ModelError, ModelState};
use stf_core::physics::param_spec::ParamSpec;

/// A force as a function of the parameters and the state.
type ForceOf = Box<dyn Fn(&[f64], &ModelState) -> f64 + Send + Sync>;

/// A memoryless force `force(p, state)` named `name` with the parameters `specs`.
pub struct Law {
    name: &'static str,
    specs: Vec<ParamSpec>,
    force: ForceOf,
}

impl ForceModel for Law {
    fn name(&self) -> &str {
        self.name
    }
    fn params(&self) -> &[ParamSpec] {
        &self.specs
    }
    fn force(&self, p: &[f64], s: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
        Ok((self.force)(p, s))
    }
}

/// The law `force` named `name` with the parameters `specs`.
pub fn law(
    name: &'static str,
    specs: Vec<ParamSpec>,
    force: impl Fn(&[f64], &ModelState) -> f64 + Send + Sync + 'static,
) -> Arc<dyn ForceModel> {
    let force = Box::new(force);
    Arc::new(Law { name, specs, force })
}

/// `p·g(state)` named `name`, its one parameter `spec`.
pub fn term(name: &'static str, spec: ParamSpec, g: fn(&ModelState) -> f64) -> Arc<dyn ForceModel> {
    law(name, vec![spec], move |p, s| p[0] * g(s))
}

/// The power law `K·|v|ⁿ·sign v`, K in [0, 100] from 1, n in [1, 4] from 1.2.
pub fn power_law() -> Arc<dyn ForceModel> {
    law(
        "power_law",
        vec![
            ParamSpec::new("K", "N (s/m)^n", 1.0, 0.0, 100.0, ""),
            ParamSpec::new("n", "", 1.2, 1.0, 4.0, ""),
        ],
        |p, s| p[0] * s.v.abs().powf(p[1]) * s.v.signum(),
    )
}
