//! The seam through which any STF force model plugs into the oscillator.
//!
//! A model has named parameters ([`ParamSpec`]), may carry internal state variables that the
//! integrator advances together with x and v, and may contribute an acceleration-proportional
//! part (added mass) that the oscillator moves to the left-hand side:
//!
//! ```text
//! F_STF = m_a(state)·ẍ + f(t, x, v, z),     ż = g(t, x, v, z)
//! ```
//!
//! Only [`ForceModel::name`], [`ForceModel::params`] and [`ForceModel::force`] are required;
//! a model without internal state or added mass needs nothing else.
//!
//! ```
//! use stf_core::physics::force_model::{ForceModel, ModelError, ModelState};
//! use stf_core::physics::param_spec::ParamSpec;
//!
//! struct Linear { specs: Vec<ParamSpec> }
//! impl ForceModel for Linear {
//!     fn name(&self) -> &str { "linear" }
//!     fn params(&self) -> &[ParamSpec] { &self.specs }
//!     fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
//!         Ok(p[0] * s.v)
//!     }
//! }
//! let m = Linear { specs: vec![ParamSpec::new("c", "N·s/m", 1.0, 0.0, 100.0, "damping")] };
//! let f = m.force(&[2.0], &ModelState { t: 0.0, x: 0.0, v: 0.5, z: &[] }, &mut []).unwrap();
//! assert_eq!(f, 1.0);
//! ```

use std::sync::Arc;

use crate::physics::param_spec::ParamSpec;
use crate::physics::track::{self, Track};

/// The state a force model sees: time, displacement, velocity and its own internal variables.
#[derive(Clone, Copy, Debug)]
pub struct ModelState<'a> {
    /// Time, s.
    pub t: f64,
    /// Displacement of the blade, m.
    pub x: f64,
    /// Velocity of the blade, m/s.
    pub v: f64,
    /// The model's internal state variables (empty for a memoryless model).
    pub z: &'a [f64],
}

pub use crate::model_error::ModelError;

/// An STF force model: `F_STF = m_a·ẍ + f(t, x, v, z)`.
pub trait ForceModel: Send + Sync {
    /// Short name (`power_law`), or a script's file stem.
    fn name(&self) -> &str;

    /// One line saying what the model is.
    fn summary(&self) -> &str {
        ""
    }

    /// The names of the models this one adds up, in order: the model's own name for a single
    /// model, the parts' terms for a sum ([`crate::physics::model_sum::ModelSum`]; none for
    /// the zero force). The text `a + b` is only their display.
    fn terms(&self) -> Vec<&str> {
        vec![self.name()]
    }

    /// The models this one adds up, when it is a sum
    /// ([`crate::physics::model_sum::ModelSum`]), in order: an integration calls them one by
    /// one ([`crate::physics::resolved_model`]) rather than through the sum. `None` (the
    /// default) for any other model; a wrapper that changes only bounds (a sum widened to a
    /// record's scale) forwards its inner model's, one that changes the force does not.
    fn summands(&self) -> Option<&[Arc<dyn ForceModel>]> {
        None
    }

    /// The parameters, in the order in which their values are passed as `p`.
    fn params(&self) -> &[ParamSpec];

    /// Number of internal state variables advanced by the integrator.
    fn n_internal(&self) -> usize {
        0
    }

    /// Initial values of the internal state (zeros unless the model says otherwise).
    fn initial_internal(&self, _p: &[f64], z0: &mut [f64]) {
        z0.fill(0.0);
    }

    /// Added mass `m_a` (kg): the part of the force proportional to the acceleration.
    fn added_mass(&self, _p: &[f64], _s: &ModelState) -> Result<f64, ModelError> {
        Ok(0.0)
    }

    /// The rest of the force, N, positive when it opposes positive x (it enters the equation
    /// with a plus sign on the left-hand side). Writes the rates of the internal state to `dz`.
    fn force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, ModelError>;

    /// The added mass and the rest of the force at once (what a fitter needs at every
    /// sample): `(added_mass, force)`. The default calls both; a sum visits its parts once.
    fn mass_and_force(
        &self,
        p: &[f64],
        s: &ModelState,
        dz: &mut [f64],
    ) -> Result<(f64, f64), ModelError> {
        Ok((self.added_mass(p, s)?, self.force(p, s, dz)?))
    }

    /// Only the rates of the internal state, written to `dz` (the intermediate stages of an
    /// integration step need no force). The default calls [`ForceModel::force`]; a sum
    /// evaluates only its parts with state.
    fn rates(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<(), ModelError> {
        self.force(p, s, dz).map(|_| ())
    }

    /// The gradient of the whole force `m_a·a + f` with respect to the parameters at state
    /// `s` and acceleration `a`, written to `grad` (one entry per parameter); `Ok(false)` when
    /// the model does not provide it (the default), and the fitter differences instead. Only
    /// models without internal state provide it (a state would need its sensitivities); a sum
    /// gives its memoryless parts' entries and leaves NaN in those of its parts with state,
    /// which the fitter differences.
    fn gradient(
        &self,
        _p: &[f64],
        _s: &ModelState,
        _a: f64,
        _grad: &mut [f64],
    ) -> Result<bool, ModelError> {
        Ok(false)
    }

    /// Along a whole record: adds the added mass and the rest of the force at the `k`-th of
    /// `rows` (strictly increasing; `None`: every sample) to `mass[k]` and `force[k]`,
    /// integrating the internal state along every sample (one RK4 step a sample interval).
    /// The provided version ([`track::mass_and_force_along`]) calls this model's own methods
    /// directly; a sum hands each part the record ([`crate::physics::track`]). A model that
    /// wraps another without changing its parameters should forward it.
    fn mass_and_force_along(
        &self,
        p: &[f64],
        track: &Track,
        rows: Option<&[usize]>,
        mass: &mut [f64],
        force: &mut [f64],
    ) -> Result<(), ModelError> {
        track::mass_and_force_along(self, p, track, rows, mass, force)
    }

    /// Along a whole record for several parameter vectors `ps` at once: each one's added mass
    /// and force at `rows`, as [`ForceModel::mass_and_force_along`] gives them into zeroed
    /// buffers, to the bit; `None` when the model does not integrate them side by side, or errs
    /// for any of them (each is then evaluated on its own). Provided by
    /// [`track::mass_and_force_lanes`] (a model with one internal variable, up to
    /// [`track::MAX_LANES`] vectors); a model that wraps another without changing its
    /// parameters should forward it.
    fn mass_and_force_lanes(
        &self,
        ps: &[&[f64]],
        track: &Track,
        rows: Option<&[usize]>,
    ) -> Option<Vec<(Vec<f64>, Vec<f64>)>> {
        track::mass_and_force_lanes(self, ps, track, rows)
    }

    /// Along a whole record: [`ForceModel::gradient`] at the `k`-th of `rows` (`None`: every
    /// sample), acceleration `a[i]` at sample `i`, parameter `j`'s entry written to
    /// `grad[j·n + k]` (`n` results); `Ok(false)` when the model gives none. Provided by
    /// [`track::gradient_along`]; a sum leaves NaN in the columns of its parts with state.
    fn gradient_along(
        &self,
        p: &[f64],
        track: &Track,
        a: &[f64],
        rows: Option<&[usize]>,
        grad: &mut [f64],
    ) -> Result<bool, ModelError> {
        track::gradient_along(self, p, track, a, rows, grad)
    }

    /// The force as the term of an equation, with `values` the parameters' values as a person
    /// reads them (one per parameter, in order, each already rounded to its standard error):
    /// `4.01·|v|^1.501·sgn v` for `power_law`. The default names the model with its values,
    /// `F_maxwell(c_m = 5.2, tau = 0.050)`: what a script or a model with internal state,
    /// whose law is not one line, writes. `None` when `values` do not match the parameters.
    fn equation(&self, values: &[String]) -> Option<String> {
        named_term(self.name(), self.params(), values)
    }

    /// The simpler built-in these fitted values `p` make this model over a record that
    /// reaches `reach`, with that model's values: a wall with no gap and exponent 3 is a cubic
    /// spring, a gate that is open at every speed the record reaches is its ungated law.
    /// `None` (the default) when the model is what its name says. Discovery names the
    /// simpler effect.
    fn reduces_to(&self, _p: &[f64], _reach: Reach) -> Option<(String, Vec<f64>)> {
        None
    }
}

/// A model written as a named term with its values, `F_name(a = 1.2, b = 3)`; `None` when
/// `values` do not match `specs`.
pub fn named_term(name: &str, specs: &[ParamSpec], values: &[String]) -> Option<String> {
    if values.len() != specs.len() {
        return None;
    }
    let args: Vec<String> = specs
        .iter()
        .zip(values)
        .map(|(s, v)| format!("{} = {v}", s.name))
        .collect();
    Some(format!("F_{name}({})", args.join(", ")))
}

/// How far a record goes: the largest |x| (m) and |ẋ| (m/s) it reaches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reach {
    /// Largest |x|, m.
    pub x: f64,
    /// Largest |ẋ|, m/s.
    pub v: f64,
}

impl Reach {
    /// The reach of displacement and velocity samples.
    pub fn of(x: &[f64], v: &[f64]) -> Self {
        let max = |s: &[f64]| s.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        Reach {
            x: max(x),
            v: max(v),
        }
    }
}

/// What share of a record's reach counts as nothing: a gap, a threshold speed or a damping
/// term below 5 % of it does not change the force where the record goes.
pub const NEGLIGIBLE_SHARE: f64 = 0.05;
