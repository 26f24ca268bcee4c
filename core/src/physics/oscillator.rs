//! The oscillator with a pluggable STF force model, as an ODE system.
//!
//! ```text
//! (m + m_a)·ẍ = excitation(t) − f_off − k·x − F_R(ẋ) − f(t, x, ẋ, z),    ż = g(t, x, ẋ, z)
//! ```
//!
//! The state is `[x, v, z…]`. The model's added mass `m_a` is moved to the left-hand side; a
//! non-positive effective mass is an error, not a NaN. The model is resolved once when it is
//! plugged in ([`ResolvedModel`]): a sum's parts are called one by one at every evaluation.

use std::sync::Arc;

use crate::numerics::integrate::fd_jacobian;
use crate::numerics::integrate::{OdeSystem, SimError};
use crate::physics::excitation::Excitation;
use crate::physics::force_model::{ForceModel, ModelError, ModelState};
use crate::physics::oscillator_params::OscillatorParams;
use crate::physics::resistance::{bearing_resistance_parts, bearing_resistance_slope};
use crate::physics::resolved_model::ResolvedModel;

/// The forces acting at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Forces {
    /// Acceleration ẍ, m/s².
    pub a: f64,
    /// STF force `m_a·ẍ + f`, N.
    pub f_stf: f64,
    /// Bearing resistance F_R(v), N.
    pub f_r: f64,
    /// Driving force, N.
    pub drive: f64,
}

/// The trolley on springs, its drive and an optional STF force model.
#[derive(Clone)]
pub struct Oscillator {
    /// Mass, stiffness, friction and unbalance.
    pub params: OscillatorParams,
    /// What drives it.
    pub excitation: Arc<Excitation>,
    model: Option<Arc<dyn ForceModel>>,
    /// The model as the right-hand side calls it.
    resolved: Option<ResolvedModel>,
    model_params: Vec<f64>,
}

impl Oscillator {
    /// An oscillator without STF.
    pub fn new(params: OscillatorParams, excitation: Excitation) -> Self {
        Oscillator::with_shared_excitation(params, Arc::new(excitation))
    }

    /// The same oscillator with a shared excitation (cheap to clone for fits).
    pub fn with_shared_excitation(params: OscillatorParams, excitation: Arc<Excitation>) -> Self {
        Oscillator {
            params,
            excitation,
            model: None,
            resolved: None,
            model_params: Vec::new(),
        }
    }

    /// Plug in an STF model with its parameter values (in the order of its specs).
    pub fn with_model(
        mut self,
        model: Arc<dyn ForceModel>,
        values: Vec<f64>,
    ) -> Result<Self, ModelError> {
        if values.len() != model.params().len() {
            return Err(ModelError::new(
                model.name(),
                format!(
                    "expects {} parameter values, got {}",
                    model.params().len(),
                    values.len()
                ),
            ));
        }
        self.resolved = Some(ResolvedModel::new(&model));
        self.model = Some(model);
        self.model_params = values;
        Ok(self)
    }

    /// The STF model, if any.
    pub fn model(&self) -> Option<&Arc<dyn ForceModel>> {
        self.model.as_ref()
    }

    /// The STF model's parameter values.
    pub fn model_params(&self) -> &[f64] {
        &self.model_params
    }

    /// Number of internal states of the model.
    pub fn n_internal(&self) -> usize {
        self.model.as_ref().map_or(0, |m| m.n_internal())
    }

    /// The initial state `[x0, v0, z0…]`, with the model's own initial internal state.
    pub fn initial_state(&self, x0: f64, v0: f64) -> Vec<f64> {
        let mut y = vec![0.0; 2 + self.n_internal()];
        y[0] = x0;
        y[1] = v0;
        if let Some(m) = &self.model {
            m.initial_internal(&self.model_params, &mut y[2..]);
        }
        y
    }

    /// The forces at `(t, y)`; writes the rates of the internal states to `dz`.
    #[inline]
    pub fn forces(&self, t: f64, y: &[f64], dz: &mut [f64]) -> Result<Forces, SimError> {
        let drive = self.excitation.force(t, &self.params);
        self.forces_with_drive(t, y, drive, dz)
    }

    /// [`Oscillator::forces`] with the driving force at `t` already known (e.g. from
    /// [`Excitation::force_and_angle`]), so that it is not evaluated twice.
    #[inline(always)]
    pub fn forces_with_drive(
        &self,
        t: f64,
        y: &[f64],
        drive: f64,
        dz: &mut [f64],
    ) -> Result<Forces, SimError> {
        let (x, v) = (y[0], y[1]);
        let p = &self.params;
        let (viscous, dry, smooth_speed) = bearing_resistance_parts(p, v);
        let (m_a, f) = match &self.resolved {
            None => (0.0, 0.0),
            Some(model) => self.model_mass_and_force(model, t, y, dz)?,
        };
        let mass = p.m + m_a;
        if !(mass > 0.0) {
            return Err(SimError::NonPositiveMass { time: t, mass });
        }
        // 1/mass and everything but the friction's last division are ready before the square
        // root of the velocity is: the acceleration waits for that root, one division, one
        // product and one subtraction.
        let inv_mass = 1.0 / mass;
        let a =
            (drive - p.f_off - p.k * x - viscous - f) * inv_mass - (dry * inv_mass) / smooth_speed;
        if !a.is_finite() {
            return Err(SimError::NonFinite {
                time: t,
                what: format!("the acceleration (STF force {f} N, added mass {m_a} kg)"),
            });
        }
        Ok(Forces {
            a,
            f_stf: m_a * a + f,
            f_r: viscous + dry / smooth_speed,
            drive,
        })
    }
}

impl Oscillator {
    /// The model's added mass and force at `(t, y)`, the rates of its states in `dz`. Kept out
    /// of line: without a model the right-hand side is then a small leaf function (no stack
    /// frame for the model's call), which the integrators call ≈ 65 000 times a sweep.
    #[inline(never)]
    fn model_mass_and_force(
        &self,
        model: &ResolvedModel,
        t: f64,
        y: &[f64],
        dz: &mut [f64],
    ) -> Result<(f64, f64), SimError> {
        let s = ModelState {
            t,
            x: y[0],
            v: y[1],
            z: &y[2..],
        };
        model
            .mass_and_force(&self.model_params, &s, dz)
            .map_err(|source| SimError::Model { time: t, source })
    }
}

impl OdeSystem for Oscillator {
    fn dim(&self) -> usize {
        2 + self.n_internal()
    }

    #[inline]
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        let (head, dz) = dy.split_at_mut(2);
        let f = self.forces(t, y, dz)?;
        head[0] = y[1];
        head[1] = f.a;
        Ok(())
    }

    /// Analytic without an STF model (`∂ẍ/∂x = −k/m`, `∂ẍ/∂v = −F_R'(v)/m`, no right-hand-side
    /// call); with one, forward differences (the model's derivatives are not known).
    fn jacobian(&self, t: f64, y: &[f64], fy: &[f64], jac: &mut [f64]) -> Result<u64, SimError> {
        if self.model.is_some() || y.len() != 2 || jac.len() != 4 {
            let mut work = vec![0.0; y.len()];
            return fd_jacobian(|t, y, dy| self.rhs(t, y, dy), t, y, fy, jac, &mut work);
        }
        let p = &self.params;
        jac.copy_from_slice(&[
            0.0,
            1.0,
            -p.k / p.m,
            -bearing_resistance_slope(p, y[1]) / p.m,
        ]);
        Ok(0)
    }

    /// The velocity: dry friction flips with its sign.
    fn switching_component(&self) -> Option<usize> {
        Some(1)
    }

    /// The knots of a measured or piecewise-defined drive.
    fn next_breakpoint(&self, t: f64) -> Option<f64> {
        self.excitation.next_breakpoint(t)
    }
}
