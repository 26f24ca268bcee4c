//! What the script tests and the script benchmark share: the native twin of
//! `models/scripts/power_law.rhai`.

use stf_core::physics::force_model::{ForceModel, ModelError, ModelState};
use stf_core::physics::param_spec::ParamSpec;

/// The native power law, with the formula of the built-in, under the script's specs.
pub struct NativePowerLaw(pub Vec<ParamSpec>);

impl ForceModel for NativePowerLaw {
    fn name(&self) -> &str {
        "native_power_law"
    }
    fn params(&self) -> &[ParamSpec] {
        &self.0
    }
    fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
        Ok(p[0] * s.v.abs().powf(p[1]) * s.v.signum())
    }
}
