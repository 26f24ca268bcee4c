//! The sliding-window polynomial derivative filter (Savitzky–Golay, generalised).
//!
//! Around each sample a least-squares polynomial of order `order` is fitted over `window`
//! samples, and its value, first and second derivative are evaluated *at* that sample. Any
//! order and any window (even or odd) are allowed. An odd window is centred on the sample; an
//! even window holds `window/2` samples before the sample and `window/2 − 1` after it.
//!
//! The source paper used order 2 over 800 samples for ω from φ ([`PolyFilter::paper_omega`])
//! and order 3 over 40 samples for v and a from x ([`PolyFilter::paper_motion`]). At the ends
//! of a signal the window is incomplete: the paper sets those outputs to zero
//! ([`Boundary::Zero`]); the default, [`Boundary::Shifted`], shifts the window inward so it
//! stays complete and evaluates the polynomial at the edge sample.
//!
//! Every output is a convolution with fixed weights. They come from a QR factorisation of the
//! Vandermonde matrix in coordinates scaled to [−1, 1] (well conditioned even for 800 samples
//! at order 3) and are computed once per call: once for the interior, and one polynomial fit
//! for each end; the interior is filtered in chunks on rayon's threads, each sample's sums its
//! own, so the result is the same to the bit on any number of cores. A filter leaves noise:
//! [`PolyFilter::noise_gain`] gives the standard deviation of each output per unit of white
//! input noise, for noise floors.
//!
//! ```
//! use stf_core::numerics::derivative::{sample_step, PolyFilter};
//! let t: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-3).collect();
//! let x: Vec<f64> = t.iter().map(|t| 0.5 * t * t).collect();
//! let dt = sample_step(&t).unwrap();
//! let d = PolyFilter::paper_motion().apply(dt, &x).unwrap();
//! assert!((d.d1[1000] - 1.0).abs() < 1e-9);   // v = t
//! assert!((d.d2[0] - 1.0).abs() < 1e-6);      // a = 1, also at the shifted edge
//! ```

use nalgebra::DMatrix;
use rayon::prelude::*;
use thiserror::Error;

/// Interior samples a thread filters at a time.
const INTERIOR_CHUNK: usize = 8192;

/// Order of the paper's filter for ω from φ.
pub const PAPER_OMEGA_ORDER: usize = 2;
/// Window (samples) of the paper's filter for ω from φ.
pub const PAPER_OMEGA_WINDOW: usize = 800;
/// Order of the paper's filter for v and a from x.
pub const PAPER_MOTION_ORDER: usize = 3;
/// Window (samples) of the paper's filter for v and a from x.
pub const PAPER_MOTION_WINDOW: usize = 40;

/// Largest relative deviation of a sample step from the mean step that still counts as
/// uniform sampling.
pub const UNIFORM_STEP_TOLERANCE: f64 = 1e-3;

/// Relative amplitude error at the bandwidth limit that [`window_for_bandwidth`] accepts.
pub const BANDWIDTH_ERROR: f64 = 0.01;

/// Why a filter could not be built or applied.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum FilterError {
    /// A zero-order hold asked of a rotor angle, which is continuous.
    #[error("a zero-order hold (`drive = \"zoh\"`) applies to a measured force u, not to a rotor angle φ, which is continuous")]
    HeldAngle,
    /// The polynomial order is zero.
    #[error("the polynomial order must be at least 1 (got {order})")]
    BadOrder {
        /// Requested order.
        order: usize,
    },
    /// The window cannot determine a polynomial of the order.
    #[error("a window of {window} samples cannot fit a polynomial of order {order}: the window must be larger than the order")]
    WindowTooSmall {
        /// Requested window, samples.
        window: usize,
        /// Requested order.
        order: usize,
    },
    /// The signal is shorter than one window.
    #[error("the signal has {len} samples, fewer than one filter window of {window}")]
    TooShort {
        /// Samples in the signal.
        len: usize,
        /// Window, samples.
        window: usize,
    },
    /// Too few time samples to define a step.
    #[error("{len} time sample(s) cannot define a sample step (need at least 2)")]
    TooFewSamples {
        /// Samples given.
        len: usize,
    },
    /// The sample step is not a positive finite number.
    #[error("the sample step must be positive and finite (got {dt})")]
    BadStep {
        /// The step, s.
        dt: f64,
    },
    /// Sampling is not uniform.
    #[error("sampling is not uniform: the step from sample {index} (t = {time} s) is {step} s, the mean step is {mean} s (more than 0.1 % off); resample the signal uniformly first")]
    NonUniform {
        /// 0-based index of the first sample of the offending step.
        index: usize,
        /// Time at that sample, s.
        time: f64,
        /// The offending step, s.
        step: f64,
        /// Mean step, s.
        mean: f64,
    },
    /// A sample is NaN or infinite.
    #[error("sample {index} is not finite ({value})")]
    NonFinite {
        /// 0-based sample index.
        index: usize,
        /// The value.
        value: f64,
    },
    /// The least-squares problem is singular (cannot happen for a valid window and order).
    #[error("the least-squares fit of order {order} over {window} samples is singular")]
    Singular {
        /// Window, samples.
        window: usize,
        /// Order.
        order: usize,
    },
}

/// What the filter does where the window around a sample would leave the signal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Boundary {
    /// The paper's behaviour: outputs at samples without a complete window are 0.
    Zero,
    /// The window is shifted inward to stay complete and the polynomial is evaluated at the
    /// edge sample (the default).
    #[default]
    Shifted,
}

/// Filtered value and first two time derivatives of a signal, one per input sample.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Derivatives {
    /// Smoothed value (units of the input).
    pub value: Vec<f64>,
    /// First time derivative (input units per second).
    pub d1: Vec<f64>,
    /// Second time derivative (input units per second²); zero for an order-1 filter.
    pub d2: Vec<f64>,
}

/// A sliding-window least-squares polynomial derivative filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PolyFilter {
    order: usize,
    window: usize,
    boundary: Boundary,
}

impl PolyFilter {
    /// A filter fitting polynomials of order `order` (≥ 1; ≥ 2 for a meaningful second
    /// derivative) over `window` samples (> `order`), with [`Boundary::Shifted`] edges.
    pub fn new(order: usize, window: usize) -> Result<Self, FilterError> {
        if order == 0 {
            return Err(FilterError::BadOrder { order });
        }
        if window <= order {
            return Err(FilterError::WindowTooSmall { window, order });
        }
        Ok(Self::checked(order, window))
    }

    /// The paper's filter for ω from φ: order 2 over 800 samples. Edges are
    /// [`Boundary::Shifted`]; add `.boundary(Boundary::Zero)` for the paper's zeroed edges.
    pub const fn paper_omega() -> Self {
        Self::checked(PAPER_OMEGA_ORDER, PAPER_OMEGA_WINDOW)
    }

    /// The paper's filter for v and a from x: order 3 over 40 samples. Edges are
    /// [`Boundary::Shifted`]; add `.boundary(Boundary::Zero)` for the paper's zeroed edges.
    pub const fn paper_motion() -> Self {
        Self::checked(PAPER_MOTION_ORDER, PAPER_MOTION_WINDOW)
    }

    /// A filter of an order and window already known to be valid, with shifted edges.
    const fn checked(order: usize, window: usize) -> Self {
        PolyFilter {
            order,
            window,
            boundary: Boundary::Shifted,
        }
    }

    /// The same filter with boundary handling `b`.
    pub const fn boundary(self, b: Boundary) -> Self {
        PolyFilter {
            boundary: b,
            ..self
        }
    }

    /// Polynomial order.
    pub const fn order(&self) -> usize {
        self.order
    }

    /// Window length, samples.
    pub const fn window(&self) -> usize {
        self.window
    }

    /// How the ends of a signal are handled.
    pub const fn boundary_handling(&self) -> Boundary {
        self.boundary
    }

    /// Number of samples before the evaluated sample inside an interior window.
    const fn lead(&self) -> usize {
        self.window / 2
    }

    /// Filter `y`, sampled uniformly every `dt` seconds (see [`sample_step`]).
    pub fn apply(&self, dt: f64, y: &[f64]) -> Result<Derivatives, FilterError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(FilterError::BadStep { dt });
        }
        let (n, w, lead) = (y.len(), self.window, self.lead());
        if n < w {
            return Err(FilterError::TooShort { len: n, window: w });
        }
        if let Some((index, &value)) = y.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(FilterError::NonFinite { index, value });
        }
        let fit = Fit::new(self.order, w)?;
        let mut out = Derivatives {
            value: vec![0.0; n],
            d1: vec![0.0; n],
            d2: vec![0.0; n],
        };
        let (s1, s2) = (1.0 / dt, 1.0 / (dt * dt));

        // Interior: samples lead ..= n − w + lead have a complete window.
        // In chunks of samples on the threads there are: each sample's sums are its own, the
        // same to the bit in any chunking (a 1 600-sample window over 150 001 samples was
        // 0.13 s on one core while the record loaded).
        let wv = fit.weights(lead, 0);
        let w1 = fit.weights(lead, 1);
        let w2 = fit.weights(lead, 2);
        let interior = lead..=(n - w + lead);
        let Derivatives { value, d1, d2 } = &mut out;
        value[interior.clone()]
            .par_chunks_mut(INTERIOR_CHUNK)
            .zip(d1[interior.clone()].par_chunks_mut(INTERIOR_CHUNK))
            .zip(d2[interior].par_chunks_mut(INTERIOR_CHUNK))
            .enumerate()
            .for_each(|(k, ((value, d1), d2))| {
                let first = k * INTERIOR_CHUNK;
                for (j, ((v, a), b)) in value.iter_mut().zip(d1).zip(d2).enumerate() {
                    let start = first + j;
                    let (sv, sa, sb) = dot3(&y[start..start + w], &wv, &w1, &w2);
                    (*v, *a, *b) = (sv, sa * s1, sb * s2);
                }
            });

        if self.boundary == Boundary::Shifted {
            // One fit over the first and one over the last complete window; the polynomial
            // is evaluated at each edge sample.
            for (start, edge) in [(0, 0..lead), (n - w, (n - w + lead + 1)..n)] {
                let c = fit.coefficients(&y[start..start + w]);
                for i in edge {
                    out.value[i] = fit.evaluate(&c, i - start, 0);
                    out.d1[i] = fit.evaluate(&c, i - start, 1) * s1;
                    out.d2[i] = fit.evaluate(&c, i - start, 2) * s2;
                }
            }
        }
        Ok(out)
    }

    /// RMS of `y` minus its smoothed value at every `stride`-th sample with a complete window
    /// (interior samples only): how far the filter's polynomial passes from the samples. A
    /// window that only averages noise leaves the noise's σ; one too long for the signal adds
    /// its bias on top.
    pub fn residual_rms(&self, y: &[f64], stride: usize) -> Result<f64, FilterError> {
        let (n, w, lead) = (y.len(), self.window, self.lead());
        if n < w {
            return Err(FilterError::TooShort { len: n, window: w });
        }
        let weights = Fit::new(self.order, w)?.weights(lead, 0);
        // Each sample's residual on the threads there are, summed in sample order after.
        let starts: Vec<usize> = (0..=(n - w)).step_by(stride.max(1)).collect();
        let residuals: Vec<f64> = starts
            .par_iter()
            .with_min_len(INTERIOR_CHUNK / 8)
            .map(|&start| {
                let window = &y[start..start + w];
                let value: f64 = window.iter().zip(&weights).map(|(y, w)| y * w).sum();
                window[lead] - value
            })
            .collect();
        let sum = residuals.iter().fold(0.0, |sum, r| sum + r * r);
        Ok((sum / residuals.len().max(1) as f64).sqrt())
    }

    /// White-noise gain of the `derivative`-th output (0 = value) at interior samples: the
    /// standard deviation of the output per unit standard deviation of independent input
    /// noise, `sqrt(Σ wⱼ²) / dtᵏ`. Zero for a derivative above the order; NaN only if the fit
    /// is singular, which a valid filter never is.
    pub fn noise_gain(&self, dt: f64, derivative: usize) -> f64 {
        match Fit::new(self.order, self.window) {
            Ok(fit) => {
                let w = fit.weights(self.lead(), derivative);
                w.iter().map(|w| w * w).sum::<f64>().sqrt() / dt.powi(derivative as i32)
            }
            Err(_) => f64::NAN,
        }
    }

    /// Complex response of the interior `derivative`-th output to a sinusoid of frequency `f`
    /// (Hz) sampled every `dt` seconds, relative to the exact derivative `(i·2πf)ᵏ`: 1 + 0i is
    /// perfect. Used to choose windows from a signal's bandwidth.
    pub fn relative_response(&self, dt: f64, f: f64, derivative: usize) -> (f64, f64) {
        let Ok(fit) = Fit::new(self.order, self.window) else {
            return (f64::NAN, f64::NAN);
        };
        let w = fit.weights(self.lead(), derivative);
        let omega = 2.0 * std::f64::consts::PI * f;
        let (mut re, mut im) = (0.0, 0.0);
        for (j, wj) in w.iter().enumerate() {
            let phase = omega * (j as f64 - self.lead() as f64) * dt;
            re += wj * phase.cos();
            im += wj * phase.sin();
        }
        let scale = dt.powi(derivative as i32);
        let (re, im) = (re / scale, im / scale);
        // Divide by (iω)^k = ω^k · i^k.
        let mag = omega.powi(derivative as i32);
        let (re, im) = match derivative % 4 {
            0 => (re, im),
            1 => (im, -re),
            2 => (-re, -im),
            _ => (-im, re),
        };
        (re / mag, im / mag)
    }
}

/// The least-squares machinery for one (order, window): the pseudo-inverse of the Vandermonde
/// matrix in the scaled coordinate `u = (j − c)/h ∈ [−1, 1]`, `c = h = (window − 1)/2`.
struct Fit {
    /// (order + 1) × window; row m gives the coefficient of uᵐ.
    pinv: DMatrix<f64>,
    centre: f64,
    half: f64,
}

impl Fit {
    fn new(order: usize, window: usize) -> Result<Self, FilterError> {
        let centre = (window as f64 - 1.0) / 2.0;
        let half = centre.max(0.5);
        let a = DMatrix::from_fn(window, order + 1, |j, m| {
            ((j as f64 - centre) / half).powi(m as i32)
        });
        let qr = a.qr();
        let r_inv = qr
            .r()
            .try_inverse()
            .ok_or(FilterError::Singular { window, order })?;
        let pinv = r_inv * qr.q().transpose();
        Ok(Fit { pinv, centre, half })
    }

    fn order(&self) -> usize {
        self.pinv.nrows() - 1
    }

    /// Factors turning coefficients into the k-th derivative (per sample) at window position
    /// `p`: `m!/(m−k)! · u^{m−k} / hᵏ`.
    fn derivative_row(&self, p: usize, k: usize) -> Vec<f64> {
        let u = (p as f64 - self.centre) / self.half;
        (0..=self.order())
            .map(|m| {
                if m < k {
                    0.0
                } else {
                    let falling: f64 = ((m - k + 1)..=m).map(|f| f as f64).product();
                    falling * u.powi((m - k) as i32) / self.half.powi(k as i32)
                }
            })
            .collect()
    }

    /// Convolution weights (per sample) of the k-th derivative at window position `p`.
    fn weights(&self, p: usize, k: usize) -> Vec<f64> {
        let row = self.derivative_row(p, k);
        let mut w = vec![0.0; self.pinv.ncols()];
        for (m, factor) in row.iter().enumerate() {
            if *factor != 0.0 {
                for (wj, pj) in w.iter_mut().zip(self.pinv.row(m).iter()) {
                    *wj += factor * pj;
                }
            }
        }
        w
    }

    /// Polynomial coefficients fitted to one window of samples.
    fn coefficients(&self, y: &[f64]) -> Vec<f64> {
        (0..=self.order())
            .map(|m| self.pinv.row(m).iter().zip(y).map(|(p, y)| p * y).sum())
            .collect()
    }

    /// k-th derivative (per sample) of the fitted polynomial at window position `p`.
    fn evaluate(&self, coefficients: &[f64], p: usize, k: usize) -> f64 {
        self.derivative_row(p, k)
            .iter()
            .zip(coefficients)
            .map(|(f, c)| f * c)
            .sum()
    }
}

/// Three dot products of `y` with `a`, `b`, `c` in one pass, with four partial sums each so
/// the compiler can vectorise.
fn dot3(y: &[f64], a: &[f64], b: &[f64], c: &[f64]) -> (f64, f64, f64) {
    let (mut sa, mut sb, mut sc) = ([0.0; 4], [0.0; 4], [0.0; 4]);
    let chunks = y
        .chunks_exact(4)
        .zip(a.chunks_exact(4))
        .zip(b.chunks_exact(4).zip(c.chunks_exact(4)));
    for ((yc, ac), (bc, cc)) in chunks {
        for k in 0..4 {
            sa[k] += yc[k] * ac[k];
            sb[k] += yc[k] * bc[k];
            sc[k] += yc[k] * cc[k];
        }
    }
    let tail = y.len() - y.len() % 4;
    let (mut ra, mut rb, mut rc) = (0.0, 0.0, 0.0);
    for j in tail..y.len() {
        ra += y[j] * a[j];
        rb += y[j] * b[j];
        rc += y[j] * c[j];
    }
    (
        sa.iter().sum::<f64>() + ra,
        sb.iter().sum::<f64>() + rb,
        sc.iter().sum::<f64>() + rc,
    )
}

/// Robust σ of white noise on a signal, from two estimates that can each only err high:
///
/// - [`third_difference_sigma`]: the MAD of third differences, robust to spikes, but it counts
///   the signal's own third differences as noise when a period spans few samples (a sine with
///   9 samples per period keeps 32 % of its amplitude there).
/// - [`spectral_floor_sigma`]: the floor of the spectrum's upper half, which holds at a few
///   samples per period as long as some band of the upper half is free of signal.
///
/// The first is the estimate unless it reads more than [`SIGNAL_IN_DIFFERENCES`] times the
/// second: then the differences hold signal and the spectrum's floor is taken. On a densely
/// sampled record the two agree within it and the first stands; on an electronic oscillator
/// sampled at 9 points a period the first read 4.66 mV of "noise" where the noise is below
/// 0.1 mV.
pub fn noise_sigma(y: &[f64]) -> f64 {
    noise_estimate(y).sigma
}

/// How [`noise_sigma`] was estimated: both estimates and the one taken.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct NoiseEstimate {
    /// The σ taken.
    pub sigma: f64,
    /// Which estimate it is: `"third_differences"` or `"spectrum_floor"`.
    pub method: &'static str,
    /// The third differences' estimate.
    pub third_differences: f64,
    /// The spectrum's floor (`None` on records shorter than a segment).
    pub spectrum_floor: Option<f64>,
}

/// [`noise_sigma`] with how it was estimated.
pub fn noise_estimate(y: &[f64]) -> NoiseEstimate {
    let third = third_difference_sigma(y);
    let floor = spectral_floor_sigma(y);
    let (sigma, method) = match floor {
        Some(f) if third > SIGNAL_IN_DIFFERENCES * f => (f, "spectrum_floor"),
        _ => (third, "third_differences"),
    };
    NoiseEstimate {
        sigma,
        method,
        third_differences: third,
        spectrum_floor: floor,
    }
}

/// How many times the spectrum's floor the third-difference estimate may read before it is
/// taken to hold signal ([`noise_sigma`]).
pub const SIGNAL_IN_DIFFERENCES: f64 = 2.0;

/// σ of white noise from the MAD of third differences (whose variance is 20σ² for white noise),
/// over 0.6745·√20.
pub fn third_difference_sigma(y: &[f64]) -> f64 {
    if y.len() < 8 {
        return 0.0;
    }
    let mut d: Vec<f64> = y
        .windows(4)
        .map(|w| (w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]).abs())
        .collect();
    let mid = d.len() / 2;
    let (_, median, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
    *median / (0.6745 * 20f64.sqrt())
}

/// Length of the segments of [`spectral_floor_sigma`], samples.
const SPECTRUM_SEGMENT: usize = 128;
/// Bins per band of [`spectral_floor_sigma`]: the upper half of a segment's spectrum is cut into
/// `SPECTRUM_SEGMENT / 2 / SPECTRUM_BAND` bands.
const SPECTRUM_BAND: usize = 8;
/// At most this many segments are averaged (spread over the record).
const SPECTRUM_SEGMENTS: usize = 1024;

/// σ of white noise from the floor of the spectrum (Welch: Hann-windowed segments of 128
/// samples, normalised so that white noise of variance σ² has a flat periodogram σ²): the
/// lowest mean over 8-bin bands of the upper half of the band (a quarter of the sampling rate
/// up to Nyquist). `None` for records shorter than a segment.
pub fn spectral_floor_sigma(y: &[f64]) -> Option<f64> {
    let l = SPECTRUM_SEGMENT;
    if y.len() < l {
        return None;
    }
    let window: Vec<f64> = (0..l)
        .map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / l as f64).cos())
        .collect();
    let power: f64 = window.iter().map(|w| w * w).sum();
    let starts = (y.len() - l) / (l / 2) + 1;
    let stride = starts.div_ceil(SPECTRUM_SEGMENTS).max(1);
    let bins: Vec<usize> = (l / 4..l / 2).collect();
    let (cos, sin): (Vec<f64>, Vec<f64>) = bins
        .iter()
        .flat_map(|&k| (0..l).map(move |n| std::f64::consts::TAU * (k * n) as f64 / l as f64))
        .map(|phase| (phase.cos(), phase.sin()))
        .unzip();
    let mut sum = vec![0.0; bins.len()];
    let mut count = 0usize;
    for s in (0..starts).step_by(stride) {
        let seg = &y[s * l / 2..s * l / 2 + l];
        let mean = seg.iter().sum::<f64>() / l as f64;
        for (b, total) in sum.iter_mut().enumerate() {
            let (c, d) = (&cos[b * l..(b + 1) * l], &sin[b * l..(b + 1) * l]);
            let (mut re, mut im) = (0.0, 0.0);
            for n in 0..l {
                let v = (seg[n] - mean) * window[n];
                re += v * c[n];
                im += v * d[n];
            }
            *total += (re * re + im * im) / power;
        }
        count += 1;
    }
    sum.chunks(SPECTRUM_BAND)
        .map(|band| band.iter().sum::<f64>() / (band.len() * count) as f64)
        .min_by(f64::total_cmp)
        .map(f64::sqrt)
}

/// The mean sample step of increasing times `t`, after checking that every step is within
/// 0.1 % ([`UNIFORM_STEP_TOLERANCE`]) of it; the error names the first offending sample.
pub fn sample_step(t: &[f64]) -> Result<f64, FilterError> {
    let n = t.len();
    if n < 2 {
        return Err(FilterError::TooFewSamples { len: n });
    }
    let mean = (t[n - 1] - t[0]) / (n - 1) as f64;
    if !(mean.is_finite() && mean > 0.0) {
        return Err(FilterError::BadStep { dt: mean });
    }
    for (index, pair) in t.windows(2).enumerate() {
        let step = pair[1] - pair[0];
        let off = (step - mean).abs();
        if off.is_nan() || off > UNIFORM_STEP_TOLERANCE * mean {
            return Err(FilterError::NonUniform {
                index,
                time: pair[0],
                step,
                mean,
            });
        }
    }
    Ok(mean)
}

/// A window (samples) for a filter of order `order` on a signal sampled at `rate` (Hz) whose
/// content reaches up to `f_max` (Hz).
///
/// The rule: the largest odd window whose highest derivative of interest — the second
/// derivative for order ≥ 2, the first for order 1 — reproduces a sinusoid at `f_max` within
/// 1 % ([`BANDWIDTH_ERROR`]) in amplitude and phase, never spanning more than one period of
/// `f_max`. A larger window leaves less noise (see [`PolyFilter::noise_gain`]) but starts to
/// flatten the signal's highest frequencies. `f_max` must cover the harmonics that matter, not
/// just the rotor's ≈ 1 Hz: impact-like spikes reach far higher. Invalid inputs (non-positive
/// or non-finite `rate`/`f_max`, order 0) give the smallest window, `order + 1` (or 2).
pub fn window_for_bandwidth(rate: f64, f_max: f64, order: usize) -> usize {
    let smallest = order.max(1) + 1;
    if order == 0 || !(rate.is_finite() && rate > 0.0 && f_max.is_finite() && f_max > 0.0) {
        return smallest;
    }
    let dt = 1.0 / rate;
    let k = order.min(2);
    let error = |window: usize| -> f64 {
        match PolyFilter::new(order, window) {
            Ok(f) => {
                let (re, im) = f.relative_response(dt, f_max, k);
                ((re - 1.0).powi(2) + im * im).sqrt()
            }
            Err(_) => f64::INFINITY,
        }
    };
    // Odd windows only: symmetric, no phase error. Search over half-widths.
    let max_window = ((rate / f_max).floor() as usize).max(smallest);
    // Smallest half-width whose window 2·lo + 1 exceeds the order.
    let mut lo = order.div_ceil(2);
    if error(2 * lo + 1) > BANDWIDTH_ERROR {
        return 2 * lo + 1;
    }
    let mut hi = (max_window.saturating_sub(1) / 2).max(lo);
    if error(2 * hi + 1) <= BANDWIDTH_ERROR {
        return 2 * hi + 1;
    }
    // Invariant: error(lo) ≤ tolerance < error(hi).
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if error(2 * mid + 1) <= BANDWIDTH_ERROR {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    2 * lo + 1
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use rand::{rngs::StdRng, SeedableRng};
    use rand_distr::{Distribution, Normal};

    /// White noise of σ 1e-4 on a sine sampled at `per_period` points a period, amplitude 1e-2
    /// plus a second tone, over `n` samples (seed 7).
    fn noisy_tones(per_period: f64, n: usize) -> Vec<f64> {
        let mut rng = StdRng::seed_from_u64(7);
        let noise = Normal::new(0.0, 1e-4).unwrap();
        (0..n)
            .map(|i| {
                let p = std::f64::consts::TAU * i as f64 / per_period;
                1e-2 * p.sin() + 3e-3 * (0.37 * p).cos() + noise.sample(&mut rng)
            })
            .collect()
    }

    /// Both estimates find the noise where a period spans many samples; at 9 samples a period
    /// third differences read the signal (≈ 7× the noise), the spectrum's floor does not.
    #[test]
    fn noise_sigma_holds_at_few_samples_per_period() {
        let dense = noisy_tones(1000.0, 50_000);
        assert_relative_eq!(third_difference_sigma(&dense), 1e-4, max_relative = 0.05);
        assert_relative_eq!(
            spectral_floor_sigma(&dense).unwrap(),
            1e-4,
            max_relative = 0.1
        );
        let sparse = noisy_tones(9.0, 50_000);
        assert!(third_difference_sigma(&sparse) > 5.0 * 1e-4);
        assert_relative_eq!(noise_sigma(&sparse), 1e-4, max_relative = 0.1);
        assert_eq!(noise_estimate(&sparse).method, "spectrum_floor");
        assert_eq!(noise_estimate(&dense).method, "third_differences");
        assert!(spectral_floor_sigma(&sparse[..100]).is_none());
    }

    fn poly(t: f64, c: &[f64]) -> (f64, f64, f64) {
        let mut v = 0.0;
        let mut d1 = 0.0;
        let mut d2 = 0.0;
        for (m, cm) in c.iter().enumerate() {
            let m_f = m as f64;
            v += cm * t.powi(m as i32);
            if m >= 1 {
                d1 += m_f * cm * t.powi(m as i32 - 1);
            }
            if m >= 2 {
                d2 += m_f * (m_f - 1.0) * cm * t.powi(m as i32 - 2);
            }
        }
        (v, d1, d2)
    }

    #[test]
    fn new_rejects_bad_order_and_window() {
        assert_eq!(
            PolyFilter::new(0, 10),
            Err(FilterError::BadOrder { order: 0 })
        );
        assert_eq!(
            PolyFilter::new(3, 3),
            Err(FilterError::WindowTooSmall {
                window: 3,
                order: 3
            })
        );
        assert!(PolyFilter::new(3, 4).is_ok());
    }

    #[test]
    fn exact_on_polynomials_up_to_the_order_interior_and_shifted_edges() {
        let dt = 0.01;
        let t: Vec<f64> = (0..300).map(|i| 1.0 + i as f64 * dt).collect();
        for (order, window) in [(1, 7), (2, 10), (2, 11), (3, 40), (3, 41), (4, 25)] {
            let c: Vec<f64> = (0..=order).map(|m| 0.7 - 0.3 * m as f64).collect();
            let y: Vec<f64> = t.iter().map(|&t| poly(t, &c).0).collect();
            let d = PolyFilter::new(order, window)
                .unwrap()
                .apply(dt, &y)
                .unwrap();
            for (i, &ti) in t.iter().enumerate() {
                let (v, d1, d2) = poly(ti, &c);
                assert!(
                    (d.value[i] - v).abs() < 1e-9,
                    "order {order} w {window} i {i}"
                );
                assert!(
                    (d.d1[i] - d1).abs() < 1e-7,
                    "order {order} w {window} i {i}"
                );
                assert!(
                    (d.d2[i] - d2).abs() < 1e-4,
                    "order {order} w {window} i {i}"
                );
            }
        }
    }

    #[test]
    fn paper_omega_window_is_exact_on_a_quadratic_phase() {
        // A sweep φ = 0.0235 t² sampled at 1 kHz: ω = 0.047 t, exact for an order-2 fit.
        let dt = 1e-3;
        let t: Vec<f64> = (0..5000).map(|i| 50.0 + i as f64 * dt).collect();
        let phi: Vec<f64> = t.iter().map(|t| 0.0235 * t * t).collect();
        let d = PolyFilter::paper_omega().apply(dt, &phi).unwrap();
        for i in [0, 1, 399, 400, 2500, 4600, 4999] {
            assert_relative_eq!(d.d1[i], 0.047 * t[i], max_relative = 1e-9);
        }
    }

    #[test]
    fn zero_boundary_zeroes_incomplete_windows_only() {
        let dt = 0.1;
        let y: Vec<f64> = (0..50).map(|i| (i as f64 * dt).powi(2)).collect();
        for window in [10, 11] {
            let f = PolyFilter::new(2, window).unwrap().boundary(Boundary::Zero);
            let d = f.apply(dt, &y).unwrap();
            let lead = window / 2;
            let last_complete = 50 - window + lead;
            for i in 0..50 {
                let complete = i >= lead && i <= last_complete;
                if complete {
                    assert_relative_eq!(d.d2[i], 2.0, max_relative = 1e-9);
                    assert_relative_eq!(d.d1[i], 2.0 * i as f64 * dt, max_relative = 1e-9);
                } else {
                    assert_eq!((d.value[i], d.d1[i], d.d2[i]), (0.0, 0.0, 0.0), "i {i}");
                }
            }
        }
    }

    #[test]
    fn sine_derivatives_are_accurate() {
        // 1 Hz sine at 1 kHz through the paper's motion filter.
        let dt = 1e-3;
        let w = 2.0 * std::f64::consts::PI;
        let y: Vec<f64> = (0..3000).map(|i| (w * i as f64 * dt).sin()).collect();
        let d = PolyFilter::paper_motion().apply(dt, &y).unwrap();
        for i in 0..3000 {
            let t = i as f64 * dt;
            assert!((d.d1[i] - w * (w * t).cos()).abs() < 1e-4 * w, "i {i}");
            assert!(
                (d.d2[i] + w * w * (w * t).sin()).abs() < 2e-3 * w * w,
                "i {i}"
            );
        }
    }

    #[test]
    fn noise_gain_matches_empirical_std_on_white_noise() {
        let dt = 1e-3;
        let f = PolyFilter::new(3, 60).unwrap();
        let mut rng = StdRng::seed_from_u64(7);
        let normal = Normal::new(0.0, 1.0).unwrap();
        let y: Vec<f64> = (0..40_000).map(|_| normal.sample(&mut rng)).collect();
        let d = f.apply(dt, &y).unwrap();
        let std = |v: &[f64]| {
            let inner = &v[100..v.len() - 100];
            let mean = inner.iter().sum::<f64>() / inner.len() as f64;
            (inner.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / inner.len() as f64).sqrt()
        };
        for (k, out) in [(0, &d.value), (1, &d.d1), (2, &d.d2)] {
            let gain = f.noise_gain(dt, k);
            let empirical = std(out);
            assert!(
                (empirical / gain - 1.0).abs() < 0.05,
                "k {k}: gain {gain}, empirical {empirical}"
            );
        }
        assert_eq!(f.noise_gain(dt, 4), 0.0);
    }

    #[test]
    fn design_figure_acceleration_noise_of_the_paper_window() {
        // The source study's 40-sample order-3 window at 1 kHz, σ = 0.05 mm → a ≈ 0.13 m/s².
        let sigma = 0.05e-3;
        let a_noise = PolyFilter::paper_motion().noise_gain(1e-3, 2) * sigma;
        assert!((a_noise / 0.13 - 1.0).abs() < 0.2, "a noise {a_noise}");
        // The 0.2 N force residual it implies for a 1.5 kg added mass.
        assert!(
            (1.5 * a_noise / 0.2 - 1.0).abs() < 0.2,
            "force noise {}",
            1.5 * a_noise
        );
    }

    #[test]
    fn sample_step_checks_uniformity_and_names_the_sample() {
        let t: Vec<f64> = (0..100).map(|i| i as f64 * 0.01).collect();
        assert_relative_eq!(sample_step(&t).unwrap(), 0.01, max_relative = 1e-12);
        let mut bad = t.clone();
        bad[40] += 0.002;
        match sample_step(&bad) {
            Err(FilterError::NonUniform { index, .. }) => assert_eq!(index, 39),
            other => panic!("{other:?}"),
        }
        assert!(sample_step(&t[..1]).is_err());
        assert!(sample_step(&[1.0, 1.0]).is_err());
        let msg = sample_step(&bad).unwrap_err().to_string();
        assert!(msg.contains("sample 39"), "{msg}");
    }

    #[test]
    fn apply_rejects_short_nonfinite_and_bad_step() {
        let f = PolyFilter::new(2, 5).unwrap();
        assert!(matches!(
            f.apply(0.1, &[1.0; 4]),
            Err(FilterError::TooShort { len: 4, window: 5 })
        ));
        assert!(matches!(
            f.apply(0.0, &[1.0; 10]),
            Err(FilterError::BadStep { .. })
        ));
        let mut y = vec![1.0; 10];
        y[3] = f64::NAN;
        assert!(matches!(
            f.apply(0.1, &y),
            Err(FilterError::NonFinite { index: 3, .. })
        ));
    }

    #[test]
    fn window_for_bandwidth_meets_its_tolerance_and_is_the_largest() {
        let rate = 1000.0;
        for (f_max, order) in [(5.0, 3), (10.0, 3), (2.0, 2), (20.0, 1)] {
            let w = window_for_bandwidth(rate, f_max, order);
            assert!(w % 2 == 1 && w > order, "w {w}");
            let k = order.min(2);
            let err = |w: usize| {
                let (re, im) =
                    PolyFilter::new(order, w)
                        .unwrap()
                        .relative_response(1.0 / rate, f_max, k);
                ((re - 1.0).powi(2) + im * im).sqrt()
            };
            assert!(err(w) <= BANDWIDTH_ERROR, "f {f_max} order {order} w {w}");
            assert!(
                err(w + 2) > BANDWIDTH_ERROR,
                "f {f_max} order {order} w {w}"
            );
        }
        // Wider bandwidth, smaller window.
        assert!(window_for_bandwidth(rate, 20.0, 3) < window_for_bandwidth(rate, 5.0, 3));
        assert_eq!(window_for_bandwidth(-1.0, 5.0, 3), 4);
    }

    #[test]
    fn relative_response_is_one_at_low_frequency() {
        let f = PolyFilter::paper_motion();
        for k in 0..=2 {
            let (re, im) = f.relative_response(1e-3, 0.01, k);
            assert!(
                (re - 1.0).abs() < 1e-6 && im.abs() < 1e-6,
                "k {k}: {re} {im}"
            );
        }
    }

    /// The interior filtered in chunks on threads: each sample the same to the bit as its own
    /// window's sums, across chunk edges and in the last, short chunk; and the residual's RMS
    /// the sum in sample order.
    #[test]
    fn the_chunked_interior_and_residual_are_each_windows_own_sums() {
        let n = 2 * INTERIOR_CHUNK + 777;
        let y: Vec<f64> = (0..n)
            .map(|i| (i as f64 * 1e-3).sin() + 1e-3 * ((i * 7919) % 13) as f64)
            .collect();
        for (order, w) in [(2, 801), (3, 40)] {
            let f = PolyFilter::new(order, w).unwrap();
            let d = f.apply(1e-3, &y).unwrap();
            let fit = Fit::new(order, w).unwrap();
            let lead = f.lead();
            let weights = [0, 1, 2].map(|k| fit.weights(lead, k));
            for start in
                (0..=(n - w)).filter(|s| s % 97 == 0 || s % INTERIOR_CHUNK < 2 || *s == n - w)
            {
                let (v, a, b) = dot3(&y[start..start + w], &weights[0], &weights[1], &weights[2]);
                let i = start + lead;
                assert_eq!(d.value[i].to_bits(), v.to_bits(), "value at {i}");
                assert_eq!(d.d1[i].to_bits(), (a * (1.0 / 1e-3)).to_bits(), "d1 at {i}");
                assert_eq!(
                    d.d2[i].to_bits(),
                    (b * (1.0 / (1e-3 * 1e-3))).to_bits(),
                    "d2 at {i}"
                );
            }
            // The residual's RMS: each sample's residual, summed in sample order.
            for stride in [1, 7] {
                let mut sum = 0.0;
                let starts = (0..=(n - w)).step_by(stride);
                let count = starts.clone().count();
                for start in starts {
                    let window = &y[start..start + w];
                    let value: f64 = window.iter().zip(&weights[0]).map(|(y, w)| y * w).sum();
                    let r = y[start + lead] - value;
                    sum += r * r;
                }
                let rms = f.residual_rms(&y, stride).unwrap();
                let want = (sum / count as f64).sqrt();
                assert_eq!(rms.to_bits(), want.to_bits(), "stride {stride}");
            }
        }
    }

    /// Speed on the paper's data size: `cargo test -p stf-core --release -- --ignored --nocapture timing`
    #[test]
    #[ignore]
    fn timing_150k_samples_window_800() {
        let y: Vec<f64> = (0..150_000).map(|i| (i as f64 * 1e-3).sin()).collect();
        let start = std::time::Instant::now();
        let d = PolyFilter::new(3, 800).unwrap().apply(1e-3, &y).unwrap();
        let wall = start.elapsed().as_secs_f64() * 1e3;
        // CPU time of this thread (ticks of 10 ms), since the machine may be shared.
        let cpu_ms = std::fs::read_to_string("/proc/thread-self/stat")
            .ok()
            .and_then(|s| s.rsplit(')').next().map(str::to_owned))
            .and_then(|s| {
                s.split_whitespace()
                    .nth(11)
                    .and_then(|v| v.parse::<f64>().ok())
            })
            .map(|ticks| ticks * 10.0);
        println!(
            "150 000 samples, window 800, order 3: {wall:.1} ms wall, thread CPU {cpu_ms:?} ms (d1[75000] = {})",
            d.d1[75_000]
        );
    }
}
