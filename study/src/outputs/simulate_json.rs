//! The JSON sidecar `simulate` writes beside a record (`F.json` for `F.csv`): how the record
//! was made — the experiment (its text too), the oscillator, the integrator, the true model,
//! the sensor noise and seed — and what the run shows (resonance peak, breakaway).

use std::collections::BTreeMap;

use serde::Serialize;
use stf_core::numerics::integrate::Settings as IntegratorSettings;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::synthetic::SensorNoise;

/// The whole sidecar.
#[derive(Serialize)]
pub struct SimulateJson<'a> {
    /// Always `stf-lab simulate`.
    pub generator: &'static str,
    /// The program's version.
    pub version: &'static str,
    /// The experiment file, as given.
    pub experiment_file: String,
    /// Its text, as read.
    pub experiment: String,
    /// The `[simulate]` section as read (drive, `rate`, `noise`, `seed`, `x0`, `v0`).
    pub simulate: &'a serde_json::Value,
    /// The oscillator simulated.
    pub system: OscillatorParams,
    /// The integrator's settings.
    pub integrator: Integrator,
    /// The true STF model (empty: none), with its values.
    pub truth: Vec<Truth>,
    /// The sensor noise added to the samples.
    pub noise: SensorNoise,
    /// The noise's random seed.
    pub seed: u64,
    /// The record written (its path).
    pub record: String,
    /// What the run shows.
    pub summary: Summary,
}

/// The integrator's settings.
#[derive(Serialize)]
pub struct Integrator {
    /// `auto`, `dopri5` or `rodas4`.
    pub method: &'static str,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Largest step, s.
    pub h_max: f64,
}

impl From<&IntegratorSettings> for Integrator {
    fn from(s: &IntegratorSettings) -> Self {
        Integrator {
            method: s.method.name(),
            rtol: s.rtol,
            atol: s.atol,
            h_max: s.h_max,
        }
    }
}

/// The true STF model.
#[derive(Clone, Debug, Serialize)]
pub struct Truth {
    /// Its name (`power_law + cubic_stiffness`).
    pub model: String,
    /// Its values by parameter name, SI units.
    pub params: BTreeMap<String, f64>,
}

/// What the simulated run shows.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    /// Largest |x|, m.
    pub peak_x_m: Option<f64>,
    /// When it was reached, s.
    pub peak_t_s: Option<f64>,
    /// ω there, rad/s (null without a rotor).
    pub peak_omega_rad_s: Option<f64>,
    /// ω where |x| first exceeds the breakaway displacement, rad/s.
    pub breakaway_omega_rad_s: Option<f64>,
    /// When that is, s (null without a rotor).
    pub breakaway_t_s: Option<f64>,
    /// The breakaway displacement, m.
    pub breakaway_displacement_m: f64,
    /// When free vibration stops, s (free vibration only).
    pub motion_stops_t_s: Option<f64>,
    /// |x| where it stops, m.
    pub motion_stops_x_m: Option<f64>,
    /// Samples written.
    pub samples: usize,
    /// Right-hand-side evaluations of the integrator.
    pub rhs_calls: u64,
    /// Accepted integrator steps.
    pub steps: u64,
}
