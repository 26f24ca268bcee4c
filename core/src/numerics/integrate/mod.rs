//! ODE integration behind one small interface, with named settings.
//!
//! An [`OdeSystem`] gives the right-hand side `dy/dt = f(t, y)` (which may fail, e.g. when a
//! script model errs); [`integrate`] advances it from `t0` and returns samples at the requested
//! output times, never beyond the last step taken (no extrapolation). The [`Method`] picks the
//! integrator; [`Settings`] holds tolerances and limits with named setters:
//!
//! ```
//! use stf_core::numerics::integrate::{integrate, Method, OdeSystem, Settings, SimError};
//! struct Decay;
//! impl OdeSystem for Decay {
//!     fn dim(&self) -> usize { 1 }
//!     fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
//!         dy[0] = -y[0];
//!         Ok(())
//!     }
//! }
//! let s = Settings::default().method(Method::Dopri5).rtol(1e-10).atol(1e-12);
//! let sol = integrate(&Decay, 0.0, &[1.0], &[0.0, 1.0], &s).unwrap();
//! assert!((sol.y(1)[0] - (-1.0f64).exp()).abs() < 1e-9);
//! ```

mod approach;
mod dense_lu;
mod dopri5;
mod dormand_prince;
mod error;
mod rhs_jacobian;
mod rodas4;
mod switching;

pub use error::SimError;
pub(crate) use rhs_jacobian::fd_jacobian;

use derive_setters::Setters;
use serde::{Deserialize, Serialize};

/// A first-order ODE system `dy/dt = f(t, y)`.
pub trait OdeSystem {
    /// Number of state variables.
    fn dim(&self) -> usize;

    /// Right-hand side; an error stops the integration and is returned as it is.
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError>;

    /// The Jacobian `∂f/∂y` at `(t, y)`, row-major (`jac[i·dim + j] = ∂f_i/∂y_j`), given
    /// `fy = f(t, y)`; returns how many right-hand-side calls it made. Used by the stiff
    /// methods; the default takes forward finite differences column by column (`dim` calls).
    fn jacobian(&self, t: f64, y: &[f64], fy: &[f64], jac: &mut [f64]) -> Result<u64, SimError> {
        let mut work = vec![0.0; y.len()];
        rhs_jacobian::fd_jacobian(|t, y, dy| self.rhs(t, y, dy), t, y, fy, jac, &mut work)
    }

    /// A state component across whose zero the right-hand side changes abruptly (a smoothed
    /// sign function, as dry friction in the velocity), if any. The explicit method then
    /// approaches a predicted zero of it in shrinking steps instead of stepping over it and
    /// being rejected; this changes the cost, never the error control. Default: none.
    fn switching_component(&self) -> Option<usize> {
        None
    }

    /// The first time strictly after `t` at which the right-hand side has a kink in time (the
    /// knots of an interpolated drive), if any. The default method and Rodas4 end a step there
    /// instead of stepping across it, which an error-controlled method otherwise pays for with
    /// rejected steps and a larger error; plain Dopri5 ignores it. Default: none.
    fn next_breakpoint(&self, _t: f64) -> Option<f64> {
        None
    }
}

/// Which integrator to use.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Dormand–Prince 5(4) while the problem is not stiff, Rodas4 while it is, switched step
    /// by step by stiffness detection (the default; cheap through dry-friction sticking).
    #[default]
    Auto,
    /// Explicit Dormand–Prince 5(4) from `ode_solvers`, stiffness detection off.
    Dopri5,
    /// The L-stable Rosenbrock method Rodas4 for every step (for stiff models throughout).
    Rodas4,
}

impl Method {
    /// All methods, for listings and error messages.
    pub const ALL: [Method; 3] = [Method::Auto, Method::Dopri5, Method::Rodas4];

    /// The name used in experiment files.
    pub fn name(self) -> &'static str {
        match self {
            Method::Auto => "auto",
            Method::Dopri5 => "dopri5",
            Method::Rodas4 => "rodas4",
        }
    }
}

/// Tolerances and limits of an integration.
#[derive(Clone, Debug, PartialEq, Setters)]
pub struct Settings {
    /// The integrator.
    pub method: Method,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Largest step, s (0: no limit but the span).
    pub h_max: f64,
    /// Most steps before giving up.
    pub max_steps: u32,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            method: Method::default(),
            rtol: 1e-7,
            atol: 1e-9,
            h_max: 0.0,
            max_steps: 50_000_000,
        }
    }
}

impl Settings {
    fn check(&self) -> Result<(), SimError> {
        let ok = self.rtol > 0.0 && self.atol > 0.0 && self.h_max >= 0.0 && self.max_steps > 0;
        if ok && self.rtol.is_finite() && self.atol.is_finite() && self.h_max.is_finite() {
            Ok(())
        } else {
            Err(SimError::BadSettings(format!(
                "tolerances must be positive and finite, h_max ≥ 0, max_steps > 0 (got rtol {}, atol {}, h_max {}, max_steps {})",
                self.rtol, self.atol, self.h_max, self.max_steps
            )))
        }
    }
}

/// Work done by an integration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Stats {
    /// Right-hand-side evaluations.
    pub rhs_calls: u64,
    /// Accepted steps.
    pub accepted: u64,
    /// Rejected steps.
    pub rejected: u64,
}

/// Samples of an integrated solution.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Output times.
    pub t: Vec<f64>,
    /// States, row after row (`dim` values each).
    pub states: Vec<f64>,
    /// Number of state variables.
    pub dim: usize,
    /// Work done.
    pub stats: Stats,
}

impl Solution {
    /// The state at output sample `i`.
    pub fn y(&self, i: usize) -> &[f64] {
        &self.states[i * self.dim..(i + 1) * self.dim]
    }
}

/// Integrate `sys` from `(t0, y0)` and sample it at `t_out` (increasing, all ≥ t0).
pub fn integrate(
    sys: &dyn OdeSystem,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    settings: &Settings,
) -> Result<Solution, SimError> {
    let (states, stats) = integrate_states(sys, t0, y0, t_out, settings)?;
    Ok(Solution {
        t: t_out.to_vec(),
        states,
        dim: y0.len(),
        stats,
    })
}

/// [`integrate`] without the copy of `t_out`: the sampled states (row after row) and the work,
/// for callers that keep the output times themselves.
pub(crate) fn integrate_states(
    sys: &dyn OdeSystem,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    settings: &Settings,
) -> Result<(Vec<f64>, Stats), SimError> {
    settings.check()?;
    if y0.len() != sys.dim() {
        return Err(SimError::BadSettings(format!(
            "initial state has {} values, the system {}",
            y0.len(),
            sys.dim()
        )));
    }
    // One branch-free pass over the times (it vectorises); the offending pair is looked up
    // only when there is one.
    let increasing = t_out.windows(2).fold(true, |ok, w| ok & (w[1] > w[0]));
    if !increasing {
        if let Some(w) = t_out.windows(2).find(|w| !(w[1] > w[0])) {
            return Err(SimError::BadSettings(format!(
                "output times must increase strictly ({} then {})",
                w[0], w[1]
            )));
        }
    }
    match t_out.first() {
        None => return Ok((vec![], Stats::default())),
        Some(&first) if first < t0 || !first.is_finite() => {
            return Err(SimError::BadSettings(format!(
                "output time {first} lies before the start {t0}"
            )))
        }
        _ => {}
    }
    match settings.method {
        Method::Auto => {
            switching::integrate(sys, t0, y0, t_out, settings, switching::Policy::Switching)
        }
        Method::Dopri5 => dopri5::integrate(sys, t0, y0, t_out, settings),
        Method::Rodas4 => {
            switching::integrate(sys, t0, y0, t_out, settings, switching::Policy::StiffOnly)
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    struct Decay;
    impl OdeSystem for Decay {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
            dy[0] = -y[0];
            Ok(())
        }
    }

    #[test]
    fn output_times_that_do_not_increase_are_named_in_the_error() {
        let s = Settings::default();
        let bad: [&[f64]; 3] = [
            &[0.0, 0.5, 0.5, 1.0],
            &[0.0, 0.7, 0.6, 1.0],
            &[0.0, 0.2, f64::NAN, 1.0],
        ];
        for t_out in bad {
            let e = integrate(&Decay, 0.0, &[1.0], t_out, &s).unwrap_err();
            let SimError::BadSettings(msg) = e else {
                panic!("{e:?}")
            };
            assert!(msg.contains("increase strictly"), "{msg}");
        }
        let t_out: Vec<f64> = (0..1000).map(|i| i as f64 * 1e-3).collect();
        let sol = integrate(&Decay, 0.0, &[1.0], &t_out, &s).unwrap();
        assert_eq!(sol.t, t_out);
        assert_eq!(sol.states.len(), t_out.len());
        assert!((sol.y(999)[0] - (-0.999f64).exp()).abs() < 1e-6);
    }
}
