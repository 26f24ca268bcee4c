//! The constant offset of a measured signal as a fitted parameter — the force sensor's
//! `f_off` (N) or the displacement's `x_off` (m) — set by one rule wherever an offset is
//! fitted: a plain fit with `[fit] offset = true` and the scoring of a fitted model on a
//! second record, whose sensor has its own offset.
//!
//! The bounds follow the record's own scale: ± twice the largest |value| of the measured
//! signal. A record is its signal plus the offset, and the signal swings about zero, so the
//! offset is never larger than that (a damper's −124 N offset on a force of hundreds of N lies
//! well inside; a fixed ±100 N stopped it at −99.93 N). The typical size is a thousandth of
//! the reach for a force offset and at most 1 mm (a tenth of the reach on a smaller record)
//! for a displacement offset. An offset that ends at or is held by a bound is flagged as any
//! parameter is ([`super::fit_warnings`]).

use super::fit_param::FitParam;
use super::trajectory_fit::DISPLACEMENT_OFFSET;

/// The bounds ± this of an offset of the measured `signal`: twice its largest |value|
/// (non-finite values ignored; 1 for a signal of zeros).
pub fn offset_reach(signal: &[f64]) -> f64 {
    let largest = signal
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    if largest > 0.0 {
        2.0 * largest
    } else {
        1.0
    }
}

/// The offset `name` ([`super::FORCE_OFFSET`] or [`DISPLACEMENT_OFFSET`]) of the measured
/// `signal` as a free parameter starting at `start` (clamped into its bounds): bounds and
/// typical size from the signal (see the module's doc).
pub fn offset_param(name: &str, signal: &[f64], start: f64) -> FitParam {
    let b = offset_reach(signal);
    let scale = if name == DISPLACEMENT_OFFSET {
        1e-3_f64.min(0.1 * b)
    } else {
        1e-3 * b
    };
    let start = if start.is_finite() { start } else { 0.0 };
    FitParam::new(name, start.clamp(-b, b))
        .bounds(-b, b)
        .scale(scale)
}

/// The least-squares offset of `measured` against `predicted` (equal lengths): the mean of
/// their differences (0 when there are none or it is not finite).
pub fn least_squares_offset(measured: &[f64], predicted: &[f64]) -> f64 {
    let n = measured.len().min(predicted.len());
    let mean = measured
        .iter()
        .zip(predicted)
        .map(|(m, p)| m - p)
        .sum::<f64>()
        / n.max(1) as f64;
    if mean.is_finite() {
        mean
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::FORCE_OFFSET;

    #[test]
    fn bounds_follow_the_signal_and_the_start_is_kept_inside() {
        let f = [-300.0, 120.0, f64::NAN];
        let p = offset_param(FORCE_OFFSET, &f, -124.0);
        assert_eq!((p.min, p.max, p.value), (-600.0, 600.0, -124.0));
        assert_eq!(p.scale, Some(0.6));
        let p = offset_param(FORCE_OFFSET, &f, 1e4);
        assert_eq!(p.value, 600.0);
        let x = [2e-3, -1e-3];
        let p = offset_param(DISPLACEMENT_OFFSET, &x, 0.0);
        assert_eq!((p.min, p.max), (-4e-3, 4e-3));
        assert!((p.scale.unwrap() - 4e-4).abs() < 1e-18);
        assert_eq!(offset_reach(&[0.0, 0.0]), 1.0);
        assert_eq!(least_squares_offset(&[3.0, 5.0], &[1.0, 1.0]), 3.0);
    }
}
