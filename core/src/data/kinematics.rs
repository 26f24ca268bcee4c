//! The kinematics of a record: ω from φ, v and a from x by the derivative filter, the drive
//! force, and the STF force recovered from them.
//!
//! Unless given, the motion filter's window is chosen from the record itself: the position
//! noise σ_x is estimated (robust σ of third differences), the dominant frequency is the
//! rotor's top speed (or the zero-crossing rate of x), and the window minimises the predicted
//! acceleration error — the filter's bias on a sinusoid of that frequency and amplitude, plus
//! the noise it lets through ([`choose_motion_window`]). An exact record gets a short window
//! (no bias), a noisy one a long window. Both errors are carried downstream, so every noise
//! floor reported includes the derivative noise.
//!
//! ```
//! use stf_core::data::kinematics::{Kinematics, KinematicsSettings};
//! use stf_core::data::record::Record;
//! let t: Vec<f64> = (0..2001).map(|i| i as f64 * 1e-3).collect();
//! let record = Record {
//!     source: "(memory)".into(),
//!     x: t.iter().map(|t| 0.01 * (6.0 * t).sin()).collect(),
//!     phi: Some(t.iter().map(|t| 6.0 * t).collect()),
//!     f_stf: None, omega: None, u: None, t,
//! };
//! let k = Kinematics::from_record(&record, &KinematicsSettings::default()).unwrap();
//! assert!((k.v[1000] - 0.06 * 6.0f64.cos()).abs() < 1e-6);
//! ```

use serde::Serialize;

use crate::data::record::Record;
use crate::data::recover::{recover_force, rotor_drive};
use crate::numerics::derivative::{noise_sigma, sample_step, Boundary, FilterError, PolyFilter};
use crate::numerics::interpolate::Linear;
use crate::numerics::reconstruct::{
    reconstruct, DriveMethod, DriveReport, DriveSignal, DriveSmoothing,
};
use crate::numerics::unwrap::unwrap_phase;
use crate::physics::excitation::{Excitation, RotorAngle};
use crate::physics::oscillator_params::OscillatorParams;

/// Which filters to use; `None` picks a window from the record's bandwidth.
#[derive(Clone, Debug, PartialEq)]
pub struct KinematicsSettings {
    /// How the measured drive (φ and ω, or u) is reconstructed (default: smoothed with a
    /// window chosen from the record).
    pub drive: DriveSmoothing,
    /// Filter for v and a from x (default: order 3, window from the bandwidth).
    pub motion: Option<PolyFilter>,
    /// Order of the motion filter when its window is chosen from the bandwidth.
    pub motion_order: usize,
    /// Boundary handling of the motion filter when its window is chosen.
    pub boundary: Boundary,
}

impl Default for KinematicsSettings {
    fn default() -> Self {
        KinematicsSettings {
            drive: DriveSmoothing::Auto,
            motion: None,
            motion_order: 3,
            boundary: Boundary::Shifted,
        }
    }
}

impl KinematicsSettings {
    /// The source study's filters: φ as recorded with ω from order 2 / 800, v and a order
    /// 3 / 40, zeroed edges.
    pub fn paper() -> Self {
        KinematicsSettings {
            drive: DriveSmoothing::Samples(PolyFilter::paper_omega().boundary(Boundary::Zero)),
            motion: Some(PolyFilter::paper_motion().boundary(Boundary::Zero)),
            motion_order: 3,
            boundary: Boundary::Zero,
        }
    }
}

/// Noise σ of the measured kinematics, SI units.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct MotionNoise {
    /// Position noise, m.
    pub x: f64,
    /// Velocity noise left by the derivative filter, m/s.
    pub v: f64,
    /// Acceleration noise left by the derivative filter, m/s².
    pub a: f64,
}

/// Samples of a record with their derivatives.
#[derive(Clone, Debug)]
pub struct Kinematics {
    /// Time, s.
    pub t: Vec<f64>,
    /// Displacement, m (as measured).
    pub x: Vec<f64>,
    /// Velocity, m/s (filtered).
    pub v: Vec<f64>,
    /// Acceleration, m/s² (filtered).
    pub a: Vec<f64>,
    /// Unwrapped rotor angle, rad (rotor rigs), as reconstructed from the record.
    pub phi: Option<Vec<f64>>,
    /// Rotor speed, rad/s (from the record's `omega` column, or the slope of the
    /// reconstructed φ).
    pub omega: Option<Vec<f64>>,
    /// Measured drive force, N (shaker rigs), as reconstructed from the record.
    pub u: Option<Vec<f64>>,
    /// How the measured drive was reconstructed (none for free vibration).
    pub drive: Option<DriveReport>,
    /// Displacement at the first sample, m, smoothed by the motion filter (a simulation
    /// started from the raw sample starts off by the noise, and a trolley that sticks keeps
    /// that offset until it breaks away).
    pub x0: f64,
    /// Velocity at the first sample, m/s, from the same fit as `x0`.
    pub v0: f64,
    /// The motion filter used.
    pub motion_filter: PolyFilter,
    /// Estimated position noise σ, m.
    pub sigma_x: f64,
    /// Velocity noise the filter leaves, m/s.
    pub sigma_v: f64,
    /// Acceleration noise the filter leaves, m/s².
    pub sigma_a: f64,
}

impl Kinematics {
    /// Derive the kinematics of `record`.
    pub fn from_record(record: &Record, s: &KinematicsSettings) -> Result<Self, FilterError> {
        let dt = sample_step(&record.t)?;
        let rate = 1.0 / dt;
        let (phi, omega, u, drive) = reconstruct_drive(record, dt, &s.drive)?;
        let sigma_x = noise_sigma(&record.x);
        let motion = match &s.motion {
            Some(f) => *f,
            None => {
                let f = dominant_frequency(omega.as_deref(), &record.x, dt);
                let x_amp = largest_deviation(&record.x);
                let window =
                    choose_motion_window(rate, f, x_amp, sigma_x, s.motion_order, record.t.len());
                PolyFilter::new(s.motion_order, window)?.boundary(s.boundary)
            }
        };
        let d = motion.apply(dt, &record.x)?;
        let fallback = if motion.boundary_handling() == Boundary::Shifted {
            (d.value[0], d.d1[0])
        } else {
            (record.x[0], d.d1[0])
        };
        let (x0, v0) = initial_state(dt, &record.x, sigma_x, motion.window(), fallback)?;
        Ok(Kinematics {
            t: record.t.clone(),
            x: record.x.clone(),
            v: d.d1,
            a: d.d2,
            phi,
            omega,
            u,
            drive,
            x0,
            v0,
            sigma_v: sigma_x * motion.noise_gain(dt, 1),
            sigma_a: sigma_x * motion.noise_gain(dt, 2),
            motion_filter: motion,
            sigma_x,
        })
    }

    /// The state a simulation of the record starts from, (m, m/s): see [`initial_state`].
    pub fn initial_state(&self) -> (f64, f64) {
        (self.x0, self.v0)
    }

    /// The record's own range of x and v, (m, m/s): the largest |x − mean x| and |v|.
    pub fn state_span(&self) -> (f64, f64) {
        let v_span = self.v.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        (largest_deviation(&self.x), v_span)
    }

    /// The drive force at each sample, N: F0·ω²·sin(φ − phi_off) for a rotor, u − u_off for
    /// a shaker, 0 without.
    pub fn drive(&self, p: &OscillatorParams) -> Vec<f64> {
        match (&self.phi, &self.omega, &self.u) {
            (Some(phi), Some(w), _) => rotor_drive(p, phi, w),
            (_, _, Some(u)) => u.iter().map(|u| u - p.u_off).collect(),
            _ => vec![0.0; self.t.len()],
        }
    }

    /// The STF force recovered from the kinematics, N.
    pub fn recovered_force(&self, p: &OscillatorParams) -> Vec<f64> {
        recover_force(p, &self.drive(p), &self.x, &self.v, &self.a)
    }

    /// The noise σ of x as measured and of v and a as filtered.
    pub fn motion_noise(&self) -> MotionNoise {
        MotionNoise {
            x: self.sigma_x,
            v: self.sigma_v,
            a: self.sigma_a,
        }
    }

    /// The noise floor of the recovered force, N (derivative noise through m and c).
    pub fn recovered_force_noise(&self, p: &OscillatorParams) -> f64 {
        crate::data::recover::recovery_noise(p, self.sigma_a, self.sigma_v)
    }

    /// The record's drive as an excitation for simulations: the reconstructed rotor angle
    /// (Hermite-interpolated with ω) or the measured force.
    ///
    /// A smoothed φ carries nothing between knots a sixteenth of its window apart (a cubic
    /// through values and slopes there matches it to ~1e-9 rad on the paper's sweep), so
    /// only those knots are kept: an integrator ends a step at every knot, and a knot per
    /// sample would cost a step per sample.
    pub fn excitation(&self) -> Excitation {
        match (&self.phi, &self.omega, &self.u) {
            (Some(phi), Some(w), _) => {
                let stride = self.drive.as_ref().map_or(1, DriveReport::knot_stride);
                let n = self.t.len();
                let mut knots: Vec<usize> = (0..n).step_by(stride).collect();
                if knots.last() != Some(&(n - 1)) {
                    knots.push(n - 1);
                }
                let pick = |v: &[f64]| knots.iter().map(|&i| v[i]).collect::<Vec<_>>();
                Excitation::Rotor(RotorAngle::measured(pick(&self.t), pick(phi), pick(w)))
            }
            (_, _, Some(u)) => {
                let held = self
                    .drive
                    .as_ref()
                    .is_some_and(|d| d.method == DriveMethod::Held);
                let (t, u) = (self.t.clone(), u.clone());
                Excitation::Force(if held {
                    Linear::held(t, u)
                } else {
                    Linear::new(t, u)
                })
            }
            _ => Excitation::None,
        }
    }
}

/// The largest |x − mean x| (0 without samples).
fn largest_deviation(x: &[f64]) -> f64 {
    let mean = x.iter().sum::<f64>() / x.len().max(1) as f64;
    x.iter().fold(0.0_f64, |m, x| m.max((x - mean).abs()))
}

/// The state at the first sample, (x0 m, v0 m/s), from the longest opening stretch of the
/// record that a quadratic follows to within its noise: the longest of 2 s, 1 s, 0.5 s … down to
/// the motion filter's `window` whose residual RMS stays within 10 % of `sigma_x` (and of the
/// quantum). The motion filter's own edge value is the `fallback`. A simulation started from a
/// noisy first sample or an edge derivative (σ_v of several mm/s) kicks the trolley: a
/// trolley that sticks keeps the offset that kick leaves until it breaks away.
pub fn initial_state(
    dt: f64,
    x: &[f64],
    sigma_x: f64,
    window: usize,
    fallback: (f64, f64),
) -> Result<(f64, f64), FilterError> {
    let scatter = sigma_x
        .max(crate::numerics::reconstruct::quantisation_step(x).map_or(0.0, |q| q / 12f64.sqrt()));
    if scatter <= 0.0 {
        return Ok(fallback);
    }
    let mut seconds = 2.0;
    loop {
        let w = ((seconds / dt) as usize).min(x.len());
        if w <= window.max(4) {
            return Ok(fallback);
        }
        let fit = PolyFilter::new(2, w)?.apply(dt, &x[..w])?;
        let rss: f64 = x[..w]
            .iter()
            .zip(&fit.value)
            .map(|(a, b)| (a - b).powi(2))
            .sum();
        if (rss / w as f64).sqrt() <= 1.1 * scatter {
            return Ok((fit.value[0], fit.d1[0]));
        }
        seconds /= 2.0;
    }
}

/// The record's drive reconstructed as a smooth signal: `(φ, ω, u, report)`. A record's own
/// `omega` column is kept as ω.
type Drive = (
    Option<Vec<f64>>,
    Option<Vec<f64>>,
    Option<Vec<f64>>,
    Option<DriveReport>,
);

fn reconstruct_drive(record: &Record, dt: f64, how: &DriveSmoothing) -> Result<Drive, FilterError> {
    if let Some(phi) = &record.phi {
        let r = reconstruct(DriveSignal::Phi, dt, &unwrap_phase(phi), how)?;
        let omega = record.omega.clone().unwrap_or(r.slope);
        return Ok((Some(r.value), Some(omega), None, Some(r.report)));
    }
    if let Some(u) = &record.u {
        let r = reconstruct(DriveSignal::U, dt, u, how)?;
        return Ok((None, record.omega.clone(), Some(r.value), Some(r.report)));
    }
    Ok((None, record.omega.clone(), None, None))
}

/// The motion-filter window (odd, samples) that minimises the predicted RMS error of the
/// acceleration of a sinusoid of frequency `f` (Hz) and amplitude `x_amp` (m) sampled at
/// `rate` (Hz) with white position noise `sigma_x` (m): bias² + noise², where the bias is the
/// filter's relative error at `f` times the acceleration amplitude (2πf)²·x_amp and the noise is
/// σ_x times the filter's noise gain. Windows span at most one period of `f` and `n` samples.
pub fn choose_motion_window(
    rate: f64,
    f: f64,
    x_amp: f64,
    sigma_x: f64,
    order: usize,
    n: usize,
) -> usize {
    let smallest = (order + 1) | 1;
    let largest = ((rate / f.max(1e-3)) as usize)
        .min(n.saturating_sub(1))
        .max(smallest);
    let dt = 1.0 / rate;
    let a_amp = (std::f64::consts::TAU * f).powi(2) * x_amp;
    let mut best = (f64::INFINITY, smallest);
    let mut window = smallest;
    while window <= largest {
        if let Ok(filter) = PolyFilter::new(order, window) {
            let (re, im) = filter.relative_response(dt, f, 2);
            let bias = ((re - 1.0).powi(2) + im * im).sqrt() * a_amp;
            let noise = sigma_x * filter.noise_gain(dt, 2);
            let error = bias.hypot(noise);
            if error < best.0 {
                best = (error, window);
            }
        }
        // Finer steps where windows are short, coarser where long.
        window += 2 * (1 + window / 64);
    }
    best.1
}

/// The highest frequency the motion carries, Hz: the rotor's top speed, or else the rate of
/// zero crossings of x (at least 0.5 Hz).
fn dominant_frequency(omega: Option<&[f64]>, x: &[f64], dt: f64) -> f64 {
    let from_rotor = omega
        .map(|w| w.iter().fold(0.0_f64, |m, w| m.max(w.abs())) / std::f64::consts::TAU)
        .filter(|f| *f > 0.0);
    from_rotor.unwrap_or_else(|| {
        // Half a period between successive crossings of the mean, over the span where the
        // signal crosses (a decaying or stopping motion does not dilute the estimate).
        let mean = x.iter().sum::<f64>() / x.len().max(1) as f64;
        let crossings: Vec<usize> = x
            .windows(2)
            .enumerate()
            .filter(|(_, w)| (w[0] - mean) * (w[1] - mean) < 0.0)
            .map(|(i, _)| i)
            .collect();
        match (crossings.first(), crossings.last()) {
            (Some(&a), Some(&b)) if b > a => {
                let span = (b - a) as f64 * dt;
                ((crossings.len() - 1) as f64 / (2.0 * span)).max(0.1)
            }
            _ => 0.5,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{rngs::StdRng, SeedableRng};
    use rand_distr::{Distribution, Normal};

    #[test]
    fn exact_signals_get_short_windows_noisy_ones_long() {
        let exact = choose_motion_window(1000.0, 1.0, 0.03, 0.0, 3, 100_000);
        let noisy = choose_motion_window(1000.0, 1.0, 0.03, 5e-5, 3, 100_000);
        assert_eq!(exact, 5);
        assert!(noisy > 60 && noisy < 1000, "{noisy}");
    }

    #[test]
    fn position_noise_finds_sigma_under_a_slow_signal() {
        let mut rng = StdRng::seed_from_u64(4);
        let n = Normal::new(0.0, 5e-5).unwrap();
        let x: Vec<f64> = (0..20000)
            .map(|i| 0.04 * (i as f64 * 1e-3 * 6.0).sin() + n.sample(&mut rng))
            .collect();
        let s = noise_sigma(&x);
        assert!((s - 5e-5).abs() < 0.05 * 5e-5, "{s}");
    }
}
