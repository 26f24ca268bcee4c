//! Simulation of the oscillator: samples of x, v, a and F_STF at a rate or at given times.
//!
//! A run integrates the oscillator once and then evaluates the forces at every sample; from
//! 20 000 samples on it uses a second thread (`rayon::join`) for the drive (during the
//! integration) and for half of the samples' forces (after it), which leaves the integration
//! as the run's critical path.
//!
//! ```
//! use stf_core::physics::{excitation::{Excitation, RotorAngle}, oscillator::Oscillator,
//!                         oscillator_params::OscillatorParams};
//! use stf_core::simulate::Simulation;
//! let osc = Oscillator::new(OscillatorParams::FORCED, Excitation::Rotor(RotorAngle::constant(3.0)));
//! let run = Simulation::new(&osc).rate(50.0).run(0.0, 1.0).unwrap();
//! assert_eq!(run.x.len(), 51);
//! ```

use derive_setters::Setters;

use crate::numerics::integrate::{integrate_states, Method, Settings, SimError, Stats};
use crate::physics::oscillator::Oscillator;

mod columns;
pub mod control;
pub mod synthetic;

use columns::{Columns, DriveColumns, Rows, PARALLEL_SAMPLES};

/// The most samples a run makes unless told otherwise: 10⁷. A run holds about 140 bytes a
/// sample while it is written (measured: 140 MB peak for 10⁶ samples with `stf-lab simulate`),
/// so 10⁷ samples — 2.8 hours at 1 kHz, 67 times the source study's 150 s sweep — take about
/// 1.4 GB and a 0.6 GB CSV file; 5·10⁷ would already ask 7 GB of a lab laptop.
pub const DEFAULT_MAX_SAMPLES: u64 = 10_000_000;

/// Bytes a run holds a sample, about (measured: see [`DEFAULT_MAX_SAMPLES`]), plus 16 for each
/// internal state of the model: what a run's count is checked against the machine's memory
/// with ([`crate::data::memory`]) before anything is allocated.
pub fn bytes_per_sample(internal_states: usize) -> f64 {
    140.0 + 16.0 * internal_states as f64
}

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
#[derive(Setters)]
pub struct Simulation<'a> {
    #[setters(skip)]
    osc: &'a Oscillator,
    /// Integrator settings.
    settings: Settings,
    /// Output rate, samples per second (for [`Simulation::run`]).
    rate: f64,
    /// Refuse a [`Simulation::run`] of more than this many samples (default
    /// [`DEFAULT_MAX_SAMPLES`]).
    max_samples: u64,
    #[setters(skip)]
    x0: f64,
    #[setters(skip)]
    v0: f64,
}

impl<'a> Simulation<'a> {
    /// Simulate `osc` from rest, sampled at 1 kHz, with the default integrator.
    pub fn new(osc: &'a Oscillator) -> Self {
        Simulation {
            osc,
            settings: Settings::default(),
            rate: 1000.0,
            max_samples: DEFAULT_MAX_SAMPLES,
            x0: 0.0,
            v0: 0.0,
        }
    }
    /// Integrator.
    pub fn method(mut self, method: Method) -> Self {
        self.settings.method = method;
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
        let count = sample_count(t0, t1, self.rate);
        if !(count <= self.max_samples as f64) {
            return Err(SimError::BadSettings(format!(
                "{t0} to {t1} s at {} samples/s asks for {} samples, over the limit of {} \
                 (`max_samples`)",
                self.rate,
                count_text(count),
                self.max_samples
            )));
        }
        let internal = self
            .osc
            .initial_state(self.x0, self.v0)
            .len()
            .saturating_sub(2);
        let bytes = count * bytes_per_sample(internal);
        crate::data::memory::check(bytes, crate::data::memory::available()).map_err(|why| {
            SimError::BadSettings(format!(
                "{t0} to {t1} s at {} samples/s is {} samples, which {why} (`max_samples` \
                 allows {})",
                self.rate,
                count_text(count),
                self.max_samples
            ))
        })?;
        let n = count as usize;
        let mut times: Vec<f64> = Vec::new();
        times.try_reserve_exact(n).map_err(|e| {
            SimError::BadSettings(format!("cannot hold {} samples: {e}", count_text(count)))
        })?;
        times.extend((0..n).map(|i| t0 + i as f64 / self.rate));
        self.sample(times)
    }

    /// Run from `times[0]` and sample at `times` (strictly increasing; the caller made them,
    /// so no limit applies).
    pub fn run_at(&self, times: &[f64]) -> Result<Trajectory, SimError> {
        self.sample(times.to_vec())
    }

    /// [`Simulation::run_at`], keeping `times` as the trajectory's time column (no copy).
    fn sample(&self, times: Vec<f64>) -> Result<Trajectory, SimError> {
        let Some(&t0) = times.first() else {
            return Ok(Trajectory::default());
        };
        let y0 = self.osc.initial_state(self.x0, self.v0);
        let excitation = &*self.osc.excitation;
        let params = &self.osc.params;
        // The drive and the rotor angle depend on time alone: on long runs they are evaluated
        // on a second thread while the integration runs (one `sin` a sample is as much work as
        // the integration of a smooth sweep).
        let (integrated, drive) = if times.len() >= PARALLEL_SAMPLES {
            rayon::join(
                || integrate_states(self.osc, t0, &y0, &times, &self.settings),
                || DriveColumns::at(excitation, params, &times),
            )
        } else {
            let integrated = integrate_states(self.osc, t0, &y0, &times, &self.settings);
            (integrated, DriveColumns::at(excitation, params, &times))
        };
        let (states, stats) = integrated?;
        let n = times.len();
        let dim = y0.len();
        let (mut x, mut v, mut a, mut f_stf) =
            (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let mut z = vec![vec![0.0; n]; dim - 2];
        let columns = Columns(
            [&mut x, &mut v, &mut a, &mut f_stf]
                .into_iter()
                .chain(&mut z)
                .map(Vec::as_mut_slice)
                .collect(),
        );
        let rows = Rows {
            states: &states,
            dim,
            times: &times,
            drive: &drive.force,
        };
        if n >= PARALLEL_SAMPLES {
            // The samples are independent: each half is filled on its own thread.
            let mid = n / 2;
            let (first, second) = (rows.window(0, mid), rows.window(mid, n));
            let (into_first, into_second) = columns.split_at(mid);
            let (first, second) = rayon::join(
                || first.fill(self.osc, into_first),
                || second.fill(self.osc, into_second),
            );
            first.and(second)?;
        } else {
            rows.fill(self.osc, columns)?;
        }
        Ok(Trajectory {
            t: times,
            x,
            v,
            a,
            f_stf,
            drive: drive.force,
            phi: drive.phi,
            omega: drive.omega,
            z,
            stats,
        })
    }
}

/// How many samples `t0` to `t1` at `rate` makes, both ends included, as a float: too many
/// for memory shows as a large (or infinite) number, never as a wrapped integer.
pub fn sample_count(t0: f64, t1: f64, rate: f64) -> f64 {
    ((t1 - t0) * rate).round() + 1.0
}

/// A sample count for messages: whole below 10⁹, else in exponent form (`1.00e15`).
pub fn count_text(count: f64) -> String {
    if count < 1e9 {
        format!("{count:.0}")
    } else {
        format!("{count:.2e}")
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::physics::excitation::{Excitation, RotorAngle};
    use crate::physics::oscillator_params::OscillatorParams;

    #[test]
    fn a_run_too_long_for_memory_is_refused_before_anything_is_allocated() {
        let osc = Oscillator::new(
            OscillatorParams::FORCED,
            Excitation::Rotor(RotorAngle::constant(6.0)),
        );
        let e = Simulation::new(&osc).rate(1e6).run(0.0, 1e9).unwrap_err();
        assert_eq!(
            e.to_string(),
            "invalid simulation request: 0 to 1000000000 s at 1000000 samples/s asks for \
             1.00e15 samples, over the limit of 10000000 (`max_samples`)"
        );
        let e = Simulation::new(&osc).rate(1e300).run(0.0, 1.0).unwrap_err();
        assert!(e.to_string().contains("asks for 1.00e300 samples"), "{e}");
        let e = Simulation::new(&osc)
            .rate(100.0)
            .max_samples(100)
            .run(0.0, 1.0)
            .unwrap_err();
        assert!(
            e.to_string().contains("101 samples, over the limit of 100"),
            "{e}"
        );
        let run = Simulation::new(&osc)
            .rate(100.0)
            .max_samples(101)
            .run(0.0, 1.0);
        assert_eq!(run.unwrap().t.len(), 101);
    }

    #[test]
    fn force_columns_are_the_forces_at_the_sampled_states() {
        let osc = Oscillator::new(
            OscillatorParams::FORCED,
            Excitation::Rotor(RotorAngle::sweep(5.0, 0.047, 0.0)),
        );
        let run = Simulation::new(&osc)
            .rate(200.0)
            .initial(0.01, 0.0)
            .run(0.0, 3.0)
            .unwrap();
        let (phi, omega) = (run.phi.as_ref().unwrap(), run.omega.as_ref().unwrap());
        assert_eq!(run.t.len(), 601);
        assert!(run.z.is_empty());
        for i in 0..run.t.len() {
            let f = osc
                .forces(run.t[i], &[run.x[i], run.v[i]], &mut [])
                .unwrap();
            assert_eq!(
                (run.a[i], run.f_stf[i], run.drive[i]),
                (f.a, f.f_stf, f.drive)
            );
            assert_eq!(phi[i], osc.excitation.angle(run.t[i]).unwrap().0);
            assert_eq!(omega[i], osc.excitation.angle(run.t[i]).unwrap().1);
        }
        // A long run takes the drive from a second thread: the same columns.
        let long = Simulation::new(&osc).rate(1000.0).run(0.0, 25.0).unwrap();
        assert!(long.t.len() >= PARALLEL_SAMPLES);
        let (phi, omega) = (long.phi.as_ref().unwrap(), long.omega.as_ref().unwrap());
        for i in (0..long.t.len()).step_by(7) {
            let t = long.t[i];
            let f = osc.forces(t, &[long.x[i], long.v[i]], &mut []).unwrap();
            assert_eq!((long.a[i], long.drive[i]), (f.a, f.drive));
            assert_eq!(phi[i], osc.excitation.angle(t).unwrap().0);
            assert_eq!(omega[i], osc.excitation.angle(t).unwrap().1);
        }
        let free = Oscillator::new(OscillatorParams::FREE, Excitation::None);
        let run = Simulation::new(&free)
            .rate(100.0)
            .initial(0.02, 0.0)
            .run(0.0, 1.0)
            .unwrap();
        assert!(run.phi.is_none() && run.omega.is_none());
        assert!(run.drive.iter().all(|&d| d == 0.0));
        for i in 0..run.t.len() {
            let f = free
                .forces(run.t[i], &[run.x[i], run.v[i]], &mut [])
                .unwrap();
            assert_eq!(run.a[i], f.a);
        }
    }
}
