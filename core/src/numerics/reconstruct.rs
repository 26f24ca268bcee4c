//! The measured drive rebuilt as the smooth physical signal it is.
//!
//! A rotor has inertia, so its angle φ(t) is smooth; an encoder adds steps of 2π/counts, and a
//! DAQ adds noise and quantisation to a measured force `u`. Fed into `F0·ω²·sin φ` or used as
//! `u` directly, those steps drive the oscillator, and near resonance they are amplified into
//! x (a 2048-count encoder on the source study's sweep: 0.69 mm of x error against 0.05 mm of
//! x noise). So before a measured drive enters a simulation or the force balance, it is
//! smoothed by a sliding least-squares polynomial ([`PolyFilter`], order 2) whose value is the
//! reconstructed signal and whose slope is ω (for φ).
//!
//! The window is chosen from the record ([`DriveSmoothing::Auto`]). The raw signal's scatter
//! about a smooth curve is known: an encoder step `q` (found from the samples, which are
//! multiples of it) leaves σ = q/√12, and white noise is measured from third differences.
//! Windows from 1.6 s down to 20 ms are tried, longest first; the first whose residual (raw
//! minus smoothed) stays within 10 % of that σ is taken: it averages the steps out and bends
//! no more than the noise shows. A linear sweep is a quadratic φ, which an order-2 window
//! follows exactly, so sweeps get the longest window; a rotor whose speed ripples within a
//! revolution gets a shorter one. A signal with no scatter at all (an exact record) is not
//! smoothed: it is interpolated through its samples, with ω from the paper's filter.
//!
//! [`DriveReport`] says what was done: the window, the step found, the residual and its ratio
//! to the step (0.29 is pure quantisation).

use serde::Serialize;

use crate::numerics::derivative::{noise_sigma, Boundary, Derivatives, FilterError, PolyFilter};

/// Order of the smoothing polynomial: a linear sweep's φ is quadratic.
pub const DRIVE_ORDER: usize = 2;

/// Candidate windows of the automatic choice, seconds, longest first.
const WINDOWS_S: [f64; 7] = [1.6, 0.8, 0.4, 0.2, 0.1, 0.05, 0.02];

/// How much the residual may exceed the expected scatter before a window counts as biased.
const RESIDUAL_TOLERANCE: f64 = 1.1;

/// At most this many residuals are evaluated per candidate window.
const RESIDUAL_PROBES: usize = 20_000;

/// How a measured drive signal is reconstructed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DriveSmoothing {
    /// Smooth with a window chosen from the record (the default).
    #[default]
    Auto,
    /// Smooth with this filter.
    Filter(PolyFilter),
    /// Interpolate through the measured samples, with the derivative from this filter (the
    /// source study's treatment: φ as recorded, ω from order 2 over 800 samples).
    Samples(PolyFilter),
    /// A measured force `u` as a DAC held it: each sample holds until the next (zero-order
    /// hold). Interpolating such a record linearly leads the true drive by half a sample, a
    /// delay that a model with memory will "explain".
    Held,
}

/// Which signal drives the rig.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DriveSignal {
    /// The rotor angle φ, rad.
    Phi,
    /// A measured force u, N.
    U,
}

/// How a drive signal was reconstructed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DriveMethod {
    /// Smoothed with a window chosen from the record.
    Auto,
    /// Smoothed with the filter the experiment set.
    Set,
    /// Interpolated through the samples, not smoothed.
    Samples,
    /// Held from each sample to the next (a measured force only).
    Held,
}

/// What the reconstruction did, for reports.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DriveReport {
    /// The signal reconstructed.
    pub signal: DriveSignal,
    /// How the window was chosen, or that the signal was not smoothed.
    pub method: DriveMethod,
    /// Polynomial order of the filter.
    pub order: usize,
    /// Window, samples.
    pub window: usize,
    /// Window, seconds.
    pub window_s: f64,
    /// The quantisation step found in the samples (rad for φ, N for u), if any.
    pub step: Option<f64>,
    /// Encoder counts per revolution that the step corresponds to (φ only).
    pub counts_per_rev: Option<f64>,
    /// The raw signal's expected scatter about a smooth curve: step/√12 and white noise.
    pub scatter: f64,
    /// RMS of raw minus reconstructed signal (0 when interpolated through the samples).
    pub residual_rms: f64,
    /// `residual_rms` over the step (0.29 for pure quantisation).
    pub residual_over_step: Option<f64>,
}

impl DriveReport {
    /// Every how many samples a simulation needs a knot of the reconstructed signal: a
    /// sixteenth of the smoothing window (every sample when interpolated through them).
    pub fn knot_stride(&self) -> usize {
        if matches!(self.method, DriveMethod::Samples | DriveMethod::Held) {
            1
        } else {
            (self.window / 16).max(1)
        }
    }
}

impl std::fmt::Display for DriveReport {
    /// One sentence: what was reconstructed, how, and how far the samples scatter about it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let what = match self.signal {
            DriveSignal::Phi => "rotor angle φ",
            DriveSignal::U => "drive force u",
        };
        let how = match (self.method, self.signal) {
            (DriveMethod::Held, _) => {
                return write!(
                    f,
                    "{what} held from each sample to the next (zero-order hold)"
                )
            }
            (DriveMethod::Samples, DriveSignal::U) => {
                return write!(f, "{what} interpolated linearly between its samples")
            }
            (DriveMethod::Samples, DriveSignal::Phi) => {
                return write!(
                    f,
                    "{what} interpolated through its samples (slope from order {} over {} samples)",
                    self.order, self.window
                )
            }
            (DriveMethod::Auto, _) => "auto",
            (DriveMethod::Set, _) => "set",
        };
        write!(
            f,
            "{what} smoothed ({how}): order {} over {} samples ({:.3} s)",
            self.order, self.window, self.window_s
        )?;
        match (self.counts_per_rev, self.residual_over_step) {
            (Some(counts), Some(ratio)) => write!(
                f,
                "; encoder {counts:.0} counts/rev, residual {ratio:.3} steps (0.289 is pure \
                 quantisation)"
            ),
            (None, Some(ratio)) => write!(f, "; residual {ratio:.3} quantisation steps"),
            _ => write!(
                f,
                "; residual {} against a scatter of {}",
                crate::digits::significant(self.residual_rms, 4),
                crate::digits::significant(self.scatter, 4)
            ),
        }
    }
}

/// A reconstructed drive signal: its value and slope at every sample.
#[derive(Clone, Debug)]
pub struct Reconstruction {
    /// The reconstructed signal.
    pub value: Vec<f64>,
    /// Its time derivative (ω for φ).
    pub slope: Vec<f64>,
    /// What was done.
    pub report: DriveReport,
}

/// The quantisation step of `y`: the largest `q` such that every sample sits on the grid
/// `y₀ + k·q` (to 1 % of a step), tried as the smallest non-zero step between neighbours
/// divided by 1 to 4. `None` if the samples are on no such grid (or never change).
pub fn quantisation_step(y: &[f64]) -> Option<f64> {
    let scale = y.iter().fold(0.0_f64, |m, v| m.max(v.abs())).max(1e-300);
    let smallest = y
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 1e-12 * scale)
        .fold(f64::INFINITY, f64::min);
    if !smallest.is_finite() {
        return None;
    }
    let y0 = y[0];
    (1..=4).map(|k| smallest / k as f64).find(|&q| {
        // Rounding of a long unwrapped angle leaves ~1e-13 rad; the grid test allows 1 %.
        y.iter().all(|&v| {
            let k = (v - y0) / q;
            (k - k.round()).abs() < 0.01
        })
    })
}

/// Reconstruct `y` (sampled every `dt` s) as `signal` with `how`.
pub fn reconstruct(
    signal: DriveSignal,
    dt: f64,
    y: &[f64],
    how: &DriveSmoothing,
) -> Result<Reconstruction, FilterError> {
    let step = quantisation_step(y);
    let scale = y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    // Below 1e-12 of the signal's size, scatter is rounding: the samples are exact.
    let scatter = step.map_or(0.0, |q| q / 12f64.sqrt()).max(noise_sigma(y));
    let scatter = if scatter > 1e-12 * scale {
        scatter
    } else {
        0.0
    };
    let (filter, method) = match how {
        DriveSmoothing::Filter(f) => (*f, DriveMethod::Set),
        DriveSmoothing::Samples(f) => (*f, DriveMethod::Samples),
        DriveSmoothing::Held if signal == DriveSignal::U => {
            (samples_filter(y.len())?, DriveMethod::Held)
        }
        DriveSmoothing::Held => return Err(FilterError::HeldAngle),
        DriveSmoothing::Auto if signal == DriveSignal::U && scatter > 0.0 => {
            match force_window(dt, y, scatter)? {
                Some(f) => (f, DriveMethod::Auto),
                None => (samples_filter(y.len())?, DriveMethod::Samples),
            }
        }
        DriveSmoothing::Auto => match choose_window(dt, y, scatter)? {
            Some(f) => (f, DriveMethod::Auto),
            None => (samples_filter(y.len())?, DriveMethod::Samples),
        },
    };
    let smoothed = !matches!(method, DriveMethod::Samples | DriveMethod::Held);
    // A force interpolated through its samples needs no slope; a record shorter than the
    // window is an error otherwise (the automatic choice never picks such a window).
    let d = if !smoothed && signal == DriveSignal::U {
        Derivatives {
            value: vec![],
            d1: vec![0.0; y.len()],
            d2: vec![],
        }
    } else {
        filter.apply(dt, y)?
    };
    let value = if smoothed { d.value } else { y.to_vec() };
    let residual_rms = if smoothed {
        rms_difference(y, &value, filter.boundary_handling())
    } else {
        0.0
    };
    let counts_per_rev = step
        .filter(|_| signal == DriveSignal::Phi)
        .map(|q| whole_counts(std::f64::consts::TAU / q));
    Ok(Reconstruction {
        value,
        slope: d.d1,
        report: DriveReport {
            signal,
            method,
            order: filter.order(),
            window: filter.window(),
            window_s: filter.window() as f64 * dt,
            step,
            counts_per_rev,
            scatter,
            residual_rms,
            residual_over_step: step.map(|q| residual_rms / q),
        },
    })
}

/// Encoder counts per revolution as found from the step: a whole number when the step is one
/// to rounding (2048, not 2048.00000000097: an encoder's counts are whole), else as found.
fn whole_counts(counts: f64) -> f64 {
    let whole = counts.round();
    if (counts - whole).abs() <= 1e-9 * counts {
        whole
    } else {
        counts
    }
}

/// The paper's filter for ω (order 2 over 800 samples), shortened to fit a shorter record.
fn samples_filter(n: usize) -> Result<PolyFilter, FilterError> {
    let paper = PolyFilter::paper_omega();
    if n >= paper.window() {
        return Ok(paper);
    }
    PolyFilter::new(DRIVE_ORDER, (n.saturating_sub(1) | 1).min(n))
}

/// The window for a measured force: its bias at the force's highest frequency goes straight
/// into the oscillator (at the drive frequency, where a shaker puts it near resonance), while
/// its noise is mostly filtered by the oscillator, so the window minimises the predicted RMS
/// error of the value, bias (the filter's response at that frequency times the amplitude)
/// and noise (`scatter` times the filter's noise gain) together. `None`: no window beats the
/// samples as they are (error `scatter`), as when a period spans a few samples and every
/// window would bend the force more than its noise.
fn force_window(dt: f64, y: &[f64], scatter: f64) -> Result<Option<PolyFilter>, FilterError> {
    let f = highest_frequency(y, dt);
    let mean = y.iter().sum::<f64>() / y.len().max(1) as f64;
    let amplitude = y.iter().fold(0.0_f64, |m, v| m.max((v - mean).abs()));
    let largest = ((0.5 / (f * dt)) as usize)
        .min(y.len() / 2)
        .max(DRIVE_ORDER + 3);
    let mut best = (scatter, None);
    let mut window = DRIVE_ORDER + 3;
    while window <= largest {
        let filter = PolyFilter::new(DRIVE_ORDER, window)?;
        let (re, im) = filter.relative_response(dt, f, 0);
        let bias = (re - 1.0).hypot(im) * amplitude;
        let error = bias.hypot(scatter * filter.noise_gain(dt, 0));
        if error < best.0 {
            best = (error, Some(filter));
        }
        window += 2 * (1 + window / 64);
    }
    Ok(best.1)
}

/// The highest frequency `y` carries, Hz: the largest rate of mean crossings over any tenth
/// of the record (at least 0.1 Hz).
fn highest_frequency(y: &[f64], dt: f64) -> f64 {
    let mean = y.iter().sum::<f64>() / y.len().max(1) as f64;
    let chunk = (y.len() / 10).max(16);
    y.chunks(chunk)
        .filter(|c| c.len() >= 8)
        .map(|c| {
            // Crossings by more than the noise would make: count sign changes of a 5-sample mean.
            let smooth: Vec<f64> = c
                .windows(5)
                .map(|w| w.iter().sum::<f64>() / 5.0 - mean)
                .collect();
            let crossings = smooth.windows(2).filter(|w| w[0] * w[1] < 0.0).count();
            crossings as f64 / (2.0 * c.len() as f64 * dt)
        })
        .fold(0.1, f64::max)
}

/// The longest candidate window whose residual stays within [`RESIDUAL_TOLERANCE`] of the
/// expected `scatter`; `None` for a signal without scatter (nothing to average) or one that no
/// window follows.
fn choose_window(dt: f64, y: &[f64], scatter: f64) -> Result<Option<PolyFilter>, FilterError> {
    if scatter <= 0.0 {
        return Ok(None);
    }
    let n = y.len();
    let stride = (n / RESIDUAL_PROBES).max(1);
    for seconds in WINDOWS_S {
        let window = ((seconds / dt).round() as usize) | 1;
        if window <= DRIVE_ORDER + 2 || window > n / 2 {
            continue;
        }
        let filter = PolyFilter::new(DRIVE_ORDER, window)?;
        if filter.residual_rms(y, stride)? <= RESIDUAL_TOLERANCE * scatter {
            return Ok(Some(filter));
        }
    }
    Ok(None)
}

/// RMS of `a − b` over the samples a filter with `boundary` fills (zeroed edges excluded).
fn rms_difference(a: &[f64], b: &[f64], boundary: Boundary) -> f64 {
    let pairs = a.iter().zip(b);
    let (sum, count) = pairs
        .filter(|(_, b)| boundary == Boundary::Shifted || **b != 0.0)
        .fold((0.0, 0usize), |(s, c), (a, b)| (s + (a - b).powi(2), c + 1));
    (sum / count.max(1) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// A sweep ω = 3 + 0.05·t sampled at 500 Hz for 60 s through an encoder of `counts`.
    fn encoder_sweep(counts: u32) -> (f64, Vec<f64>, Vec<f64>) {
        let dt = 2e-3;
        let q = TAU / f64::from(counts);
        let exact: Vec<f64> = (0..30_001)
            .map(|i| {
                let t = i as f64 * dt;
                3.0 * t + 0.025 * t * t
            })
            .collect();
        let measured = exact.iter().map(|p| (p / q).round() * q).collect();
        (dt, exact, measured)
    }

    #[test]
    fn finds_the_encoder_step() {
        for counts in [1024, 2048, 4096] {
            let (_, _, phi) = encoder_sweep(counts);
            let q = quantisation_step(&phi).unwrap();
            assert!((TAU / q - f64::from(counts)).abs() < 1e-6, "{counts}: {q}");
        }
        let (_, exact, _) = encoder_sweep(2048);
        assert_eq!(quantisation_step(&exact), None);
    }

    #[test]
    fn averages_the_encoder_steps_out() {
        let (dt, exact, measured) = encoder_sweep(2048);
        let r = reconstruct(DriveSignal::Phi, dt, &measured, &DriveSmoothing::Auto).unwrap();
        let q = TAU / 2048.0;
        let err = exact
            .iter()
            .zip(&r.value)
            .fold(0.0_f64, |m, (e, v)| m.max((e - v).abs()));
        // The raw samples are up to q/2 off; the reconstruction far less.
        assert!(err < 0.05 * q, "max |φ − φ_true| = {err:e} rad, step {q:e}");
        let w_err = (0..exact.len())
            .map(|i| (r.slope[i] - (3.0 + 0.05 * i as f64 * dt)).abs())
            .fold(0.0_f64, f64::max);
        assert!(w_err < 1e-3, "max |ω − ω_true| = {w_err:e}");
        assert_eq!(r.report.method, DriveMethod::Auto);
        assert_eq!(r.report.counts_per_rev, Some(2048.0));
        let ratio = r.report.residual_over_step.unwrap();
        assert!((ratio - 12f64.sqrt().recip()).abs() < 0.03, "{ratio}");
    }

    #[test]
    fn a_rippling_speed_gets_a_shorter_window_than_a_sweep() {
        let (dt, _, sweep) = encoder_sweep(2048);
        let q = TAU / 2048.0;
        // ω = 6 rad/s with a ±5 % ripple once per revolution.
        let ripple: Vec<f64> = (0..30_001)
            .map(|i| {
                let t = i as f64 * dt;
                let p = 6.0 * t + 0.05 * (6.0 * t).sin();
                (p / q).round() * q
            })
            .collect();
        let how = DriveSmoothing::Auto;
        let a = reconstruct(DriveSignal::Phi, dt, &sweep, &how).unwrap();
        let b = reconstruct(DriveSignal::Phi, dt, &ripple, &how).unwrap();
        assert!(
            b.report.window < a.report.window,
            "{:?} {:?}",
            a.report,
            b.report
        );
        let ratio = b.report.residual_over_step.unwrap();
        assert!(ratio < 0.32, "{ratio}");
    }

    #[test]
    fn a_noisy_quantised_force_is_smoothed_towards_the_truth() {
        // A chirp u(t) = 2 sin(2π(0.5 t + 0.025 t²)) N at 200 Hz through a DAQ with 0.05 N of
        // noise and a 0.02 N quantum.
        let dt = 5e-3;
        let truth: Vec<f64> = (0..4001)
            .map(|i| {
                let t = i as f64 * dt;
                2.0 * (TAU * (0.5 * t + 0.025 * t * t)).sin()
            })
            .collect();
        let mut state = 12345u64;
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let measured: Vec<f64> = truth
            .iter()
            .map(|u| {
                // Sum of 12 uniforms − 6: unit-variance noise, scaled to 0.05 N.
                let g: f64 = (0..12).map(|_| uniform()).sum::<f64>() - 6.0;
                ((u + 0.05 * g) / 0.02).round() * 0.02
            })
            .collect();
        let r = reconstruct(DriveSignal::U, dt, &measured, &DriveSmoothing::Auto).unwrap();
        let rms = |a: &[f64]| {
            (a.iter()
                .zip(&truth)
                .map(|(a, t)| (a - t).powi(2))
                .sum::<f64>()
                / a.len() as f64)
                .sqrt()
        };
        let (raw, smooth) = (rms(&measured), rms(&r.value));
        assert_eq!(r.report.method, DriveMethod::Auto);
        assert!(
            smooth < 0.4 * raw,
            "raw {raw:.4} N, smoothed {smooth:.4} N: {:?}",
            r.report
        );
    }

    #[test]
    fn exact_samples_are_interpolated_not_smoothed() {
        let (dt, exact, _) = encoder_sweep(2048);
        let r = reconstruct(DriveSignal::Phi, dt, &exact, &DriveSmoothing::Auto).unwrap();
        assert_eq!(r.value, exact);
        assert_eq!(r.report.method, DriveMethod::Samples);
    }
}
