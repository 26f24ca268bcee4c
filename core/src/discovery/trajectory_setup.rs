//! The oscillator side of a trajectory-level discovery ([`TrajectorySetup`]): the oscillator,
//! its drive and the parameters refitted with every model, and the force recovered from the
//! record's kinematics that starts every model ([`ForceHint`]).

use crate::fit::TrajectoryFit;

/// The oscillator side of a trajectory-level discovery: the oscillator, its drive, its
/// initial state and integrator, and its parameters refitted with every model (names of
/// [`OscillatorParams::NAMES`] or the initial state, with start values and bounds) — a
/// [`TrajectoryFit`] without a model, whose free parameters are those refitted — and the
/// force hint.
///
/// ```
/// use std::sync::Arc;
/// use stf_core::discovery::TrajectorySetup;
/// use stf_core::physics::excitation::Excitation;
/// use stf_core::fit::{FitParam, TrajectoryFit};
/// use stf_core::physics::oscillator_params::OscillatorParams;
/// let fit = TrajectoryFit::new(OscillatorParams::FREE, Arc::new(Excitation::None))
///     .free(FitParam::new("k", 268.0).bounds(100.0, 400.0))
///     .initial(0.03, 0.0);
/// let setup = TrajectorySetup::new(fit);
/// assert_eq!(setup.fit.free_params().len(), 1);
/// ```
#[derive(Clone)]
pub struct TrajectorySetup {
    /// The oscillator and its refitted parameters (the fit's settings and model unused).
    pub fit: TrajectoryFit,
    /// The STF force recovered from the record's kinematics with the setup's oscillator, if
    /// known: every model is first fitted to it at force level (milliseconds) for its start.
    pub force_hint: Option<ForceHint>,
}

/// The record's filtered velocity and acceleration and the STF force recovered from them
/// (the drive − m·a − k·x − F_R(v), with the setup's oscillator).
#[derive(Clone, Debug)]
pub struct ForceHint {
    /// Velocity, m/s.
    pub v: Vec<f64>,
    /// Acceleration, m/s².
    pub a: Vec<f64>,
    /// Recovered STF force, N.
    pub f: Vec<f64>,
}

impl TrajectorySetup {
    /// The oscillator of `fit`, its free parameters refitted with every model, no force hint.
    pub fn new(fit: TrajectoryFit) -> Self {
        TrajectorySetup {
            fit,
            force_hint: None,
        }
    }
    /// Start every model from its force-level fit to `hint`.
    pub fn force_hint(mut self, hint: ForceHint) -> Self {
        self.force_hint = Some(hint);
        self
    }
}
