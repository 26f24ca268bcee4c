//! What the field reads from a cycle's hysteresis loop, beside the energy ∮F dx: the equivalent
//! viscous damping, the phase of the force's fundamental against x and v, and a peak of the
//! force that noise does not inflate.
//!
//! - **Equivalent viscous damping** `c_eq = ∮F dx / (π·ω·X²)`, N·s/m: the damper c·v that
//!   dissipates the same energy per cycle on a sinusoid of amplitude X at ω (for a viscous force
//!   it is c itself).
//! - **Phase of the fundamental**: the first Fourier coefficient over the cycle,
//!   `C_s = Σ s_i·e^(−iθ_i)` with `θ_i = 2π·(t_i − t_start)/(t_end − t_start)`, of the force and
//!   of x (or v); the phase of the force against x is `arg C_F − arg C_x`, in degrees, wrapped
//!   to (−180°, 180°]. A damper leads x by 90° and is in phase with v (0°); an elastic force is
//!   in phase with x; a force in phase with the acceleration lies at ±180° against x. NaN when
//!   either has no fundamental (no force, no motion).
//! - **Smoothed peak**: the largest |F| after a centred moving average over [`peak_window`]
//!   samples (about 1/25 of the cycle). The peak of raw samples is biased upward by the noise
//!   (the largest of a few tens of samples near the peak lies ≈ 1.5 σ above it); averaging
//!   w samples divides that by √w while a pulse lasting many windows keeps its height. The
//!   negligible-force test reads this peak.
//!
//! ```
//! use stf_core::regimes::loops::{equivalent_damping, phase_deg};
//! // A damper F = 20·v on x = 10 mm·sin θ at 6 rad/s: energy π·c·ω·X², c_eq = c.
//! let e = std::f64::consts::PI * 20.0 * 6.0 * 1e-4;
//! assert!((equivalent_damping(e, 6.0, 0.01) - 20.0).abs() < 1e-9);
//! let t: Vec<f64> = (0..=100).map(|i| i as f64 / 100.0).collect();
//! let x: Vec<f64> = t.iter().map(|t| (std::f64::consts::TAU * t).sin()).collect();
//! let v: Vec<f64> = t.iter().map(|t| (std::f64::consts::TAU * t).cos()).collect();
//! assert!((phase_deg(&t, &v, &x) - 90.0).abs() < 1e-6);
//! ```

use std::f64::consts::{PI, TAU};

/// `∮F dx / (π·ω·X²)`, N·s/m; 0 when ω or X is 0.
pub fn equivalent_damping(energy: f64, omega: f64, amplitude: f64) -> f64 {
    let scale = PI * omega * amplitude * amplitude;
    if scale > 0.0 && scale.is_finite() {
        energy / scale
    } else {
        0.0
    }
}

/// The first Fourier coefficient of `s` over times `t` (one cycle, `t[0]` to its end `t_end`).
fn fundamental(t: &[f64], s: &[f64], t_end: f64) -> (f64, f64) {
    let n = t.len().min(s.len());
    if n == 0 {
        return (0.0, 0.0);
    }
    let span = t_end - t[0];
    let (mut re, mut im) = (0.0, 0.0);
    for i in 0..n {
        let th = TAU * (t[i] - t[0]) / span;
        re += s[i] * th.cos();
        im -= s[i] * th.sin();
    }
    (re / n as f64, im / n as f64)
}

/// Phase of the fundamental of `f` against that of `r` over one cycle of samples at times `t`
/// (the cycle's samples `start..end`; its period is taken as `end − start` sample steps), in
/// degrees in (−180°, 180°]; NaN if either has no fundamental.
pub fn phase_deg(t: &[f64], f: &[f64], r: &[f64]) -> f64 {
    let n = t.len();
    if n < 3 {
        return f64::NAN;
    }
    let t_end = t[n - 1] + (t[n - 1] - t[0]) / (n - 1) as f64;
    let (fr, fi) = fundamental(t, f, t_end);
    let (rr, ri) = fundamental(t, r, t_end);
    if fr.hypot(fi) == 0.0 || rr.hypot(ri) == 0.0 {
        return f64::NAN;
    }
    wrap_deg((fi.atan2(fr) - ri.atan2(rr)).to_degrees())
}

/// An angle in degrees wrapped to (−180°, 180°].
pub fn wrap_deg(a: f64) -> f64 {
    let w = a - 360.0 * (a / 360.0).round();
    if w <= -180.0 {
        w + 360.0
    } else {
        w
    }
}

/// Width of the moving average for the smoothed peak of a cycle of `n` samples: the odd number
/// nearest n/25, at least 1.
pub fn peak_window(n: usize) -> usize {
    let w = (n as f64 / 25.0).round() as usize;
    w.max(1) | 1
}

/// The largest |F| of `f` after a centred moving average over `window` samples (the window
/// shrinks at the ends of the slice). 0 for an empty slice.
pub fn smoothed_peak(f: &[f64], window: usize) -> f64 {
    let n = f.len();
    let h = window / 2;
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    for v in f {
        prefix.push(prefix[prefix.len() - 1] + v);
    }
    (0..n)
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(h), (i + h + 1).min(n));
            ((prefix[hi] - prefix[lo]) / (hi - lo) as f64).abs()
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cycle(n: usize) -> Vec<f64> {
        (0..n).map(|i| i as f64 / n as f64).collect()
    }

    #[test]
    fn phases_of_a_damper_a_spring_and_an_inertial_force() {
        let t = cycle(400);
        let x: Vec<f64> = t.iter().map(|t| (TAU * t + 0.7).sin()).collect();
        let v: Vec<f64> = t.iter().map(|t| (TAU * t + 0.7).cos()).collect();
        let a: Vec<f64> = x.iter().map(|x| -x).collect();
        assert!((phase_deg(&t, &v, &x) - 90.0).abs() < 1e-9);
        assert!(phase_deg(&t, &v, &v).abs() < 1e-9);
        assert!(phase_deg(&t, &x, &x).abs() < 1e-9);
        assert!((phase_deg(&t, &a, &x) - 180.0).abs() < 1e-9);
        assert!(phase_deg(&t, &vec![0.0; 400], &x).is_nan());
        // A Coulomb force sign(v) has its fundamental in phase with v.
        let c: Vec<f64> = v.iter().map(|v| v.signum()).collect();
        assert!(phase_deg(&t, &c, &v).abs() < 1.0);
    }

    #[test]
    fn wrapping_and_windows() {
        assert_eq!(wrap_deg(190.0), -170.0);
        assert_eq!(wrap_deg(-180.0), 180.0);
        assert_eq!(wrap_deg(540.0), 180.0);
        assert_eq!(peak_window(100), 5);
        assert_eq!(peak_window(10), 1);
        assert_eq!(peak_window(1000), 41);
    }

    #[test]
    fn the_smoothed_peak_keeps_a_broad_pulse_and_damps_noise() {
        // A half sine of 1 N over 200 samples keeps its peak within 0.3 %; an alternating
        // ±0.1 N "noise" averages out over 5 samples to 0.02 N inside, and over the 3 samples
        // the window keeps at the ends to 0.1/3 N.
        let f: Vec<f64> = (0..200).map(|i| (PI * i as f64 / 199.0).sin()).collect();
        assert!((smoothed_peak(&f, peak_window(200)) - 1.0).abs() < 3e-3);
        let noise: Vec<f64> = (0..100)
            .map(|i| if i % 2 == 0 { 0.1 } else { -0.1 })
            .collect();
        assert!((smoothed_peak(&noise, 5) - 0.1 / 3.0).abs() < 1e-12);
        assert!(smoothed_peak(&noise[2..98], 5) > 0.0);
        assert_eq!(smoothed_peak(&[], 5), 0.0);
    }
}
