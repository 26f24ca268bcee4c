//! Simulation of the oscillator: samples of x, v, a and F_STF at a rate or at given times.
//!
//! ```
//! use stf_core::{excitation::{Excitation, RotorAngle}, oscillator::Oscillator,
//!                simulate::Simulation, system::OscillatorParams};
//! let osc = Oscillator::new(OscillatorParams::FORCED, Excitation::Rotor(RotorAngle::constant(3.0)));
//! let run = Simulation::new(&osc).rate(50.0).run(0.0, 1.0).unwrap();
//! assert_eq!(run.x.len(), 51);
//! ```

use crate::integrate::{integrate, Method, Settings, SimError, Stats};
use crate::oscillator::Oscillator;

/// Samples of a simulated run.
#[derive(Clone, Debug, Default)]
pub struct Trajectory {
    /// Time, s.
    pub t: Vec<f64>,
    /// Displacement, m.
    pub x: Vec<f64>,
    /// Velocity, m/s.
    pub v: Vec<f64>,
    /// Acceleration, m/s².
    pub a: Vec<f64>,
    /// STF force, N.
    pub f_stf: Vec<f64>,
    /// Driving force, N.
    pub drive: Vec<f64>,
    /// Rotor angle φ, rad (rotor drive only).
    pub phi: Option<Vec<f64>>,
    /// Rotor speed ω, rad/s (rotor drive only).
    pub omega: Option<Vec<f64>>,
    /// Internal states of the model, one vector per state.
    pub z: Vec<Vec<f64>>,
    /// Work the integrator did.
    pub stats: Stats,
}

/// A simulation request: an oscillator, integrator settings and an initial state.
pub struct Simulation<'a> {
    osc: &'a Oscillator,
    settings: Settings,
    rate: f64,
    x0: f64,
    v0: f64,
}

impl<'a> Simulation<'a> {
    /// Simulate `osc` from rest, sampled at 1 kHz, with the default integrator.
    pub fn new(osc: &'a Oscillator) -> Self {
        Simulation {
            osc,
            settings: Settings::default(),
            rate: 1000.0,
            x0: 0.0,
            v0: 0.0,
        }
    }
    /// Integrator settings.
    pub fn settings(mut self, settings: Settings) -> Self {
        self.settings = settings;
        self
    }
    /// Integrator.
    pub fn method(mut self, method: Method) -> Self {
        self.settings.method = method;
        self
    }
    /// Output rate, samples per second (for [`Simulation::run`]).
    pub fn rate(mut self, rate: f64) -> Self {
        self.rate = rate;
        self
    }
    /// Initial displacement (m) and velocity (m/s).
    pub fn initial(mut self, x0: f64, v0: f64) -> Self {
        self.x0 = x0;
        self.v0 = v0;
        self
    }

    /// Run from `t0` to `t1`, sampled at the rate (both ends included).
    pub fn run(&self, t0: f64, t1: f64) -> Result<Trajectory, SimError> {
        if !(self.rate > 0.0 && self.rate.is_finite() && t1 > t0) {
            return Err(SimError::BadSettings(format!(
                "need a positive rate and t1 > t0 (rate {}, t0 {t0}, t1 {t1})",
                self.rate
            )));
        }
        let n = ((t1 - t0) * self.rate).round() as usize + 1;
        let times: Vec<f64> = (0..n).map(|i| t0 + i as f64 / self.rate).collect();
        self.run_at(&times)
    }

    /// Run from `times[0]` and sample at `times` (strictly increasing).
    pub fn run_at(&self, times: &[f64]) -> Result<Trajectory, SimError> {
        let Some(&t0) = times.first() else {
            return Ok(Trajectory::default());
        };
        let y0 = self.osc.initial_state(self.x0, self.v0);
        let sol = integrate(self.osc, t0, &y0, times, &self.settings)?;
        let n = times.len();
        let nz = self.osc.n_internal();
        let mut out = Trajectory {
            t: times.to_vec(),
            x: Vec::with_capacity(n),
            v: Vec::with_capacity(n),
            a: Vec::with_capacity(n),
            f_stf: Vec::with_capacity(n),
            drive: Vec::with_capacity(n),
            phi: None,
            omega: None,
            z: vec![Vec::with_capacity(n); nz],
            stats: sol.stats,
        };
        let rotor = self.osc.excitation.omega(t0).is_some();
        let (mut phi, mut omega) = if rotor {
            (Vec::with_capacity(n), Vec::with_capacity(n))
        } else {
            (Vec::new(), Vec::new())
        };
        let mut dz = vec![0.0; nz];
        // One pass: the rotor angle is evaluated once per sample for the drive, φ and ω.
        for (i, &t) in times.iter().enumerate() {
            let y = sol.y(i);
            let (drive, angle) = self.osc.excitation.force_and_angle(t, self.osc.params.f0);
            let f = self.osc.forces_with_drive(t, y, drive, &mut dz)?;
            out.x.push(y[0]);
            out.v.push(y[1]);
            out.a.push(f.a);
            out.f_stf.push(f.f_stf);
            out.drive.push(f.drive);
            for (j, zj) in out.z.iter_mut().enumerate() {
                zj.push(y[2 + j]);
            }
            if let (true, Some((p, w))) = (rotor, angle) {
                phi.push(p);
                omega.push(w);
            }
        }
        if rotor {
            out.phi = Some(phi);
            out.omega = Some(omega);
        }
        Ok(out)
    }
}
