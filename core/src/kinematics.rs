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
//! use stf_core::kinematics::{Kinematics, KinematicsSettings};
//! use stf_core::record::Record;
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

use crate::derivative::{sample_step, Boundary, FilterError, PolyFilter};
use crate::excitation::{Excitation, RotorAngle};
use crate::interpolate::Linear;
use crate::record::Record;
use crate::recover::{recover_force, rotor_drive};
use crate::system::OscillatorParams;
use crate::unwrap::unwrap_phase;

/// Which filters to use; `None` picks a window from the record's bandwidth.
#[derive(Clone, Debug, PartialEq)]
pub struct KinematicsSettings {
    /// Filter for ω from φ (default: the paper's order 2 over 800 samples, shifted edges).
    pub omega: PolyFilter,
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
            omega: PolyFilter::paper_omega(),
            motion: None,
            motion_order: 3,
            boundary: Boundary::Shifted,
        }
    }
}

impl KinematicsSettings {
    /// The source study's filters: ω order 2 / 800, v and a order 3 / 40, zeroed edges.
    pub fn paper() -> Self {
        KinematicsSettings {
            omega: PolyFilter::paper_omega().boundary(Boundary::Zero),
            motion: Some(PolyFilter::paper_motion().boundary(Boundary::Zero)),
            motion_order: 3,
            boundary: Boundary::Zero,
        }
    }
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
    /// Unwrapped rotor angle, rad (rotor rigs).
    pub phi: Option<Vec<f64>>,
    /// Rotor speed, rad/s (from the record's `omega` column, or filtered from φ).
    pub omega: Option<Vec<f64>>,
    /// Measured drive force, N (shaker rigs).
    pub u: Option<Vec<f64>>,
    /// The motion filter used.
    pub motion_filter: PolyFilter,
    /// Estimated position noise σ, m.
    pub sigma_x: f64,
    /// Velocity noise the filter leaves, m/s.
    pub sigma_v: f64,
    /// Acceleration noise the filter leaves, m/s².
    pub sigma_a: f64,
}

/// Robust σ of white noise on a smooth signal: the MAD of third differences (whose variance
/// is 20σ² for white noise) over 0.6745·√20.
pub fn position_noise(x: &[f64]) -> f64 {
    if x.len() < 8 {
        return 0.0;
    }
    let mut d: Vec<f64> = x
        .windows(4)
        .map(|w| (w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]).abs())
        .collect();
    let mid = d.len() / 2;
    let (_, median, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
    *median / (0.6745 * 20f64.sqrt())
}

impl Kinematics {
    /// Derive the kinematics of `record`.
    pub fn from_record(record: &Record, s: &KinematicsSettings) -> Result<Self, FilterError> {
        let dt = sample_step(&record.t)?;
        let rate = 1.0 / dt;
        let phi = record.phi.as_deref().map(unwrap_phase);
        let omega = match (&record.omega, &phi) {
            (Some(w), _) => Some(w.clone()),
            (None, Some(phi)) => Some(s.omega.apply(dt, phi)?.d1),
            (None, None) => None,
        };
        let motion = match &s.motion {
            Some(f) => *f,
            None => {
                let f = dominant_frequency(omega.as_deref(), &record.x, dt);
                let mean = record.x.iter().sum::<f64>() / record.x.len() as f64;
                let x_amp = record
                    .x
                    .iter()
                    .fold(0.0_f64, |m, x| m.max((x - mean).abs()));
                let window = choose_motion_window(
                    rate,
                    f,
                    x_amp,
                    position_noise(&record.x),
                    s.motion_order,
                    record.t.len(),
                );
                PolyFilter::new(s.motion_order, window)?.boundary(s.boundary)
            }
        };
        let d = motion.apply(dt, &record.x)?;
        let sigma_x = position_noise(&record.x);
        Ok(Kinematics {
            t: record.t.clone(),
            x: record.x.clone(),
            v: d.d1,
            a: d.d2,
            phi,
            omega,
            u: record.u.clone(),
            sigma_v: sigma_x * motion.noise_gain(dt, 1),
            sigma_a: sigma_x * motion.noise_gain(dt, 2),
            motion_filter: motion,
            sigma_x,
        })
    }

    /// The drive force at each sample, N: F0·ω²·sin φ for a rotor, u for a shaker, 0 without.
    pub fn drive(&self, p: &OscillatorParams) -> Vec<f64> {
        match (&self.phi, &self.omega, &self.u) {
            (Some(phi), Some(w), _) => rotor_drive(p, phi, w),
            (_, _, Some(u)) => u.clone(),
            _ => vec![0.0; self.t.len()],
        }
    }

    /// The STF force recovered from the kinematics, N.
    pub fn recovered_force(&self, p: &OscillatorParams) -> Vec<f64> {
        recover_force(p, &self.drive(p), &self.x, &self.v, &self.a)
    }

    /// The noise σ of x as measured and of v and a as filtered.
    pub fn motion_noise(&self) -> crate::fit::MotionNoise {
        crate::fit::MotionNoise {
            x: self.sigma_x,
            v: self.sigma_v,
            a: self.sigma_a,
        }
    }

    /// The noise floor of the recovered force, N (derivative noise through m and c).
    pub fn recovered_force_noise(&self, p: &OscillatorParams) -> f64 {
        crate::recover::recovery_noise(p, self.sigma_a, self.sigma_v)
    }

    /// The record's drive as an excitation for simulations: the measured rotor angle
    /// (Hermite-interpolated with the filtered ω) or the measured force.
    pub fn excitation(&self) -> Excitation {
        match (&self.phi, &self.omega, &self.u) {
            (Some(phi), Some(w), _) => {
                Excitation::Rotor(RotorAngle::measured(self.t.clone(), phi.clone(), w.clone()))
            }
            (_, _, Some(u)) => Excitation::Force(Linear::new(self.t.clone(), u.clone())),
            _ => Excitation::None,
        }
    }
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
        let s = position_noise(&x);
        assert!((s - 5e-5).abs() < 0.05 * 5e-5, "{s}");
    }
}
