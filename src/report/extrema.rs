//! Extrema of a noisy signal (the maxima and minima of F_STF marked on time histories): a
//! maximum counts only once the signal has fallen `delta` below it, a minimum only once it has
//! risen `delta` above it, so noise smaller than `delta` makes no extra extrema.

use super::plot_range::finite_bounds;

/// Whether an extremum is a maximum or a minimum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExtremumKind {
    /// A local maximum.
    Max,
    /// A local minimum.
    Min,
}

/// A local extremum at sample `index`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Extremum {
    /// Sample index.
    pub index: usize,
    /// Maximum or minimum.
    pub kind: ExtremumKind,
}

/// Alternating maxima and minima of `y` that stand out by more than `delta` (non-finite
/// samples are skipped). A non-positive or non-finite `delta` finds nothing.
pub fn extrema(y: &[f64], delta: f64) -> Vec<Extremum> {
    let mut out = Vec::new();
    if !delta.is_finite() || delta <= 0.0 {
        return out;
    }
    let (mut mx, mut mx_i) = (f64::NEG_INFINITY, 0);
    let (mut mn, mut mn_i) = (f64::INFINITY, 0);
    let mut looking_for: Option<ExtremumKind> = None;
    // The first sample is a boundary, not an extremum, even when the signal moves away from it.
    let mut first: Option<usize> = None;
    for (i, &v) in y.iter().enumerate() {
        if !v.is_finite() {
            continue;
        }
        let first = *first.get_or_insert(i);
        if v > mx {
            (mx, mx_i) = (v, i);
        }
        if v < mn {
            (mn, mn_i) = (v, i);
        }
        let max_done = v < mx - delta && looking_for != Some(ExtremumKind::Min);
        let min_done = v > mn + delta && looking_for != Some(ExtremumKind::Max);
        if max_done {
            if mx_i != first {
                out.push(Extremum {
                    index: mx_i,
                    kind: ExtremumKind::Max,
                });
            }
            (mn, mn_i) = (v, i);
            looking_for = Some(ExtremumKind::Min);
        } else if min_done {
            if mn_i != first {
                out.push(Extremum {
                    index: mn_i,
                    kind: ExtremumKind::Min,
                });
            }
            (mx, mx_i) = (v, i);
            looking_for = Some(ExtremumKind::Max);
        }
    }
    out
}

/// The threshold above which an extremum of `y` is not noise: the larger of 5 % of the range
/// and four noise standard deviations, the noise estimated from second differences
/// (σ ≈ 1.4826 · median|Δ²y| / √6, which ignores a smooth trend).
pub fn noise_delta(y: &[f64]) -> f64 {
    let finite: Vec<f64> = y.iter().copied().filter(|v| v.is_finite()).collect();
    let Some((lo, hi)) = finite_bounds(&finite).filter(|(lo, hi)| hi > lo) else {
        return 0.0;
    };
    let mut d2: Vec<f64> = finite
        .windows(3)
        .map(|w| (w[0] - 2.0 * w[1] + w[2]).abs())
        .collect();
    d2.sort_unstable_by(f64::total_cmp);
    let sigma = d2
        .get(d2.len() / 2)
        .map_or(0.0, |m| 1.4826 * m / 6f64.sqrt());
    (0.05 * (hi - lo)).max(4.0 * sigma)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_peaks_and_troughs_of_a_sine() {
        // sin(t) on [0, 4π): maxima at π/2, 5π/2; minima at 3π/2, 7π/2 (confirmed by the
        // rise back to 0 at the end); the start at 0 is a boundary, not a minimum.
        let n = 4000;
        let t: Vec<f64> = (0..n)
            .map(|i| i as f64 * 4.0 * std::f64::consts::PI / n as f64)
            .collect();
        let y: Vec<f64> = t.iter().map(|t| t.sin()).collect();
        let e = extrema(&y, 0.1);
        let kinds: Vec<ExtremumKind> = e.iter().map(|e| e.kind).collect();
        use ExtremumKind::*;
        assert_eq!(kinds, vec![Max, Min, Max, Min]);
        let expected = [0.5, 1.5, 2.5, 3.5].map(|k| k * std::f64::consts::PI);
        for (e, want) in e.iter().zip(expected) {
            assert!((t[e.index] - want).abs() < 0.01, "{} vs {want}", t[e.index]);
        }
    }

    #[test]
    fn noise_below_delta_makes_no_extra_extrema() {
        // A slow sine with a fast ripple of amplitude 0.02.
        let y: Vec<f64> = (0..5000)
            .map(|i| {
                let t = i as f64 * 1e-3;
                (2.0 * t).sin() + 0.02 * (400.0 * t).sin()
            })
            .collect();
        let delta = noise_delta(&y);
        assert!(delta > 0.04, "delta {delta}");
        let e = extrema(&y, delta);
        let kinds: Vec<ExtremumKind> = e.iter().map(|e| e.kind).collect();
        assert_eq!(
            kinds,
            vec![ExtremumKind::Max, ExtremumKind::Min, ExtremumKind::Max]
        );
        assert!(extrema(&y, 0.001).len() > 10, "the ripple is there");
    }

    #[test]
    fn degenerate_inputs_find_nothing() {
        assert!(extrema(&[1.0, 2.0, 1.0], 0.0).is_empty());
        assert!(extrema(&[1.0, 2.0, 1.0], f64::NAN).is_empty());
        assert_eq!(noise_delta(&[3.0; 10]), 0.0);
    }
}
