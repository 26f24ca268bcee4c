//! Phase unwrapping: turn a wrapped rotor angle back into a continuous one.
//!
//! Encoders and many loggers report φ wrapped into [0, 2π) or (−π, π]. Between two samples
//! the rotor turns far less than half a revolution, so a jump of more than π between
//! neighbours is a wrap: it is removed by adding the multiple of 2π that brings the step
//! back into [−π, π]. Input that is already continuous comes back unchanged.
//!
//! ```
//! use stf_core::numerics::unwrap::unwrap_phase;
//! use std::f64::consts::PI;
//! let phi = unwrap_phase(&[6.0, 0.2, 0.5]);   // wrapped in [0, 2π) after 6.0
//! assert!((phi[1] - (0.2 + 2.0 * PI)).abs() < 1e-12);
//! ```

use std::f64::consts::{PI, TAU};

/// Unwrap a sampled phase (rad): every step larger than π in magnitude is reduced by the
/// multiple of 2π that brings it into [−π, π]. Steps of at most π, and the first sample, are
/// kept as they are. Non-finite samples are passed through and do not disturb the rest.
pub fn unwrap_phase(phi: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(phi.len());
    let mut offset = 0.0;
    let mut previous: Option<f64> = None;
    for &p in phi {
        if !p.is_finite() {
            out.push(p);
            continue;
        }
        if let Some(prev) = previous {
            let step = p - prev;
            if step.abs() > PI {
                // Into [−π, π): the wrap-free step.
                let mut reduced = (step + PI).rem_euclid(TAU) - PI;
                if reduced == -PI && step > 0.0 {
                    reduced = PI;
                }
                offset += reduced - step;
            }
        }
        previous = Some(p);
        out.push(p + offset);
    }
    out
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::*;

    #[test]
    fn continuous_input_is_unchanged() {
        let phi: Vec<f64> = (0..1000)
            .map(|i| 0.003 * (i as f64).powi(2) / 100.0)
            .collect();
        assert_eq!(unwrap_phase(&phi), phi);
        let slow: Vec<f64> = (0..100).map(|i| -0.9 * PI * i as f64).collect();
        assert_eq!(unwrap_phase(&slow), slow);
    }

    #[test]
    fn wrapped_ramps_come_back_both_ways() {
        for sign in [1.0, -1.0] {
            let truth: Vec<f64> = (0..5000).map(|i| sign * 0.01 * i as f64 + 0.3).collect();
            for wrap in [
                |p: f64| p.rem_euclid(TAU),
                |p: f64| (p + PI).rem_euclid(TAU) - PI,
            ] {
                let wrapped: Vec<f64> = truth.iter().map(|&p| wrap(p)).collect();
                let un = unwrap_phase(&wrapped);
                for (u, t) in un.iter().zip(&truth) {
                    assert!((u - t).abs() < 1e-9, "{u} vs {t}");
                }
            }
        }
    }

    #[test]
    fn encoder_quantized_wrapped_sweep() {
        // A 1024-count encoder on a sweep ω = 0.047 t sampled at 1 kHz, logged wrapped in
        // [0, 2π): the unwrapped angle equals the quantized continuous angle.
        let counts = 1024.0;
        let q = TAU / counts;
        let truth: Vec<f64> = (0..200_000)
            .map(|i| {
                let t = 50.0 + i as f64 * 1e-3;
                (0.0235 * t * t / q).floor() * q
            })
            .collect();
        let wrapped: Vec<f64> = truth.iter().map(|p| p.rem_euclid(TAU)).collect();
        assert!(wrapped.iter().all(|p| (0.0..TAU).contains(p)));
        let un = unwrap_phase(&wrapped);
        let offset = un[0] - truth[0];
        assert!((offset / TAU - (offset / TAU).round()).abs() < 1e-9);
        let worst = un
            .iter()
            .zip(&truth)
            .map(|(u, t)| (u - t - offset).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-6, "worst {worst}");
    }

    #[test]
    fn multiple_turn_jumps_and_nonfinite_samples() {
        let un = unwrap_phase(&[0.0, 0.1 + 2.0 * TAU, f64::NAN, 0.2 - TAU]);
        assert!((un[1] - 0.1).abs() < 1e-12);
        assert!(un[2].is_nan());
        assert!((un[3] - 0.2).abs() < 1e-12);
        assert!(unwrap_phase(&[]).is_empty());
    }
}
