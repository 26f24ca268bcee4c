//! Axis ranges: the span of the finite values of the data, padded so that lines do not touch
//! the frame, and widened when the data are constant.

use std::ops::Range;

/// The smallest and largest finite value, or `None` when there is none.
pub fn finite_bounds<'a>(values: impl IntoIterator<Item = &'a f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    (lo <= hi).then_some((lo, hi))
}

/// The range of the finite values widened by `fraction` of their span on each side; a
/// constant is widened by 10 % of its size (or by 1 around zero).
fn widened(lo: f64, hi: f64, fraction: f64) -> Range<f64> {
    let span = hi - lo;
    if span > 0.0 {
        lo - fraction * span..hi + fraction * span
    } else {
        let pad = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
        lo - pad..hi + pad
    }
}

/// The range of the finite values padded by 5 %, or `None` when there are none.
pub fn padded_range<'a>(values: impl IntoIterator<Item = &'a f64>) -> Option<Range<f64>> {
    finite_bounds(values).map(|(lo, hi)| widened(lo, hi, 0.05))
}

/// The range of the finite values with no padding (a time axis), or `None`.
pub fn exact_range<'a>(values: impl IntoIterator<Item = &'a f64>) -> Option<Range<f64>> {
    finite_bounds(values).map(|(lo, hi)| widened(lo, hi, 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pads_ignores_nan_and_widens_constants() {
        let r = padded_range(&[1.0, f64::NAN, 3.0]).unwrap();
        assert!(r.start < 1.0 && r.end > 3.0 && r.end - r.start < 2.5);
        let c = padded_range(&[2.0, 2.0]).unwrap();
        assert!(c.start < 2.0 && c.end > 2.0);
        let z = padded_range(&[0.0]).unwrap();
        assert!(z.start < 0.0 && z.end > 0.0);
        assert!(padded_range(&[f64::NAN]).is_none());
        assert_eq!(exact_range(&[0.0, 10.0]).unwrap(), 0.0..10.0);
    }
}
