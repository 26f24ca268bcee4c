//! Toy force models and kinematics the tests of models evaluated along a record share
//! (`physics::track`, `fit::part_cache`, `fit::row_halves`): a memoryless power law with an
//! added mass and an exact gradient ([`Law`]), a relaxing force with one internal state
//! ([`Relax`]), and a sine's t, x and v ([`sine_kinematics`]).

use super::force_model::{ForceModel, ModelError, ModelState};
use super::param_spec::ParamSpec;

/// t, x and v of a sine of 0.01 m at `omega` rad/s, `n` samples 1 ms apart.
pub(crate) fn sine_kinematics(n: usize, omega: f64) -> [Vec<f64>; 3] {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
    let x = t.iter().map(|t| 0.01 * (omega * t).sin()).collect();
    let v = t.iter().map(|t| 0.01 * omega * (omega * t).cos()).collect();
    [t, x, v]
}

/// `c·|v|^n·sgn v` with `m_a` as added mass: memoryless, with an exact gradient. Given a
/// fourth parameter, a speed limit past which it errs.
pub(crate) struct Law(pub Vec<ParamSpec>);

impl ForceModel for Law {
    fn name(&self) -> &str {
        "law"
    }
    fn params(&self) -> &[ParamSpec] {
        &self.0
    }
    fn added_mass(&self, p: &[f64], _s: &ModelState) -> Result<f64, ModelError> {
        Ok(p[2])
    }
    fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
        if p.get(3).is_some_and(|limit| s.v.abs() > *limit) {
            return Err(ModelError::new("law", format!("too fast at t = {}", s.t)));
        }
        Ok(p[0] * s.v.abs().powf(p[1]) * s.v.signum())
    }
    fn gradient(
        &self,
        p: &[f64],
        s: &ModelState,
        a: f64,
        grad: &mut [f64],
    ) -> Result<bool, ModelError> {
        let u = s.v.abs().powf(p[1]) * s.v.signum();
        grad[..3].copy_from_slice(&[u, p[0] * u * s.v.abs().ln(), a]);
        grad[3..].fill(0.0);
        Ok(true)
    }
}

/// A force relaxing towards `c·v` with time constant `tau` (which must be positive): one
/// internal state, named `.0`.
pub(crate) struct Relax(pub &'static str, pub Vec<ParamSpec>);

impl ForceModel for Relax {
    fn name(&self) -> &str {
        self.0
    }
    fn params(&self) -> &[ParamSpec] {
        &self.1
    }
    fn n_internal(&self) -> usize {
        1
    }
    fn force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, ModelError> {
        if p[1] <= 0.0 {
            return Err(ModelError::new(self.0, "tau must be positive"));
        }
        dz[0] = (p[0] * s.v - s.z[0]) / p[1];
        Ok(s.z[0])
    }
}
