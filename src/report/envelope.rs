//! The envelope of a long oscillating series: over a record of hundreds of cycles a line
//! drawn sample by sample fills its band solid, so the overview draws the band itself — the
//! smallest and largest value in each of a few hundred time buckets — and leaves the shape of
//! the cycles to the zoomed windows ([`super::regime_windows`]).

use super::figure::finite_points;
use super::plot_range::finite_bounds;

/// How many time buckets an envelope has (about two pixels each on a 1000-pixel figure).
pub const BUCKETS: usize = 400;
/// More crossings of the mid-range than this in one plot, and a line is a solid band.
const DENSE_CROSSINGS: usize = 150;

/// Whether `y` oscillates too often to be drawn as a line across one plot: it crosses the
/// middle of its range more than [`DENSE_CROSSINGS`] times.
pub fn dense(y: &[f64]) -> bool {
    crossings(y) > DENSE_CROSSINGS
}

/// How many times `y` crosses the middle of its range (with a margin).
fn crossings(y: &[f64]) -> usize {
    let Some((lo, hi)) = finite_bounds(y).filter(|(lo, hi)| lo < hi) else {
        return 0;
    };
    // A crossing counts once the value is a fifth of the half-range past the middle, so noise
    // about the middle of a quiet stretch is not counted.
    let (mid, band) = (0.5 * (lo + hi), 0.1 * (hi - lo));
    let mut side = 0;
    let mut count = 0;
    for &v in y.iter().filter(|v| v.is_finite()) {
        let now = if v > mid + band {
            1
        } else if v < mid - band {
            -1
        } else {
            side
        };
        if side != 0 && now != side {
            count += 1;
        }
        side = now;
    }
    count
}

/// The buckets an envelope of `y` takes: about two cycles each (a bucket shorter than a cycle
/// misses its peak, and the edge then swings with the beat of bucket and cycle), at most
/// [`BUCKETS`].
pub fn buckets_for(y: &[f64]) -> usize {
    (crossings(y) / 4).clamp(20, BUCKETS)
}

/// The lower and upper edge of `y` over `buckets` equal stretches of `t`: `(t_mid, min, max)`
/// of each stretch that has a finite sample.
pub fn envelope(t: &[f64], y: &[f64], buckets: usize) -> Vec<(f64, f64, f64)> {
    let finite = finite_points(t, y);
    let (Some(first), Some(last)) = (finite.first(), finite.last()) else {
        return Vec::new();
    };
    let (t0, span) = (first.0, (last.0 - first.0).max(f64::MIN_POSITIVE));
    let n = buckets.max(1);
    let mut edges = vec![(f64::INFINITY, f64::NEG_INFINITY); n];
    for (tk, v) in finite {
        let b = (((tk - t0) / span * n as f64) as usize).min(n - 1);
        edges[b] = (edges[b].0.min(v), edges[b].1.max(v));
    }
    edges
        .iter()
        .enumerate()
        .filter(|(_, (lo, hi))| lo <= hi)
        .map(|(b, (lo, hi))| (t0 + span * (b as f64 + 0.5) / n as f64, *lo, *hi))
        .collect()
}

/// The envelope as a closed outline: along the upper edge, back along the lower.
pub fn band(edges: &[(f64, f64, f64)]) -> Vec<(f64, f64)> {
    edges
        .iter()
        .map(|&(t, _, hi)| (t, hi))
        .chain(edges.iter().rev().map(|&(t, lo, _)| (t, lo)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fast_oscillation_is_dense_and_its_envelope_holds_its_extremes() {
        let t: Vec<f64> = (0..20_000).map(|i| i as f64 * 0.01).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|t| (1.0 + 0.01 * t) * (5.0 * t).sin())
            .collect();
        assert!(dense(&y));
        assert!(!dense(&y[..1_000]));
        let e = envelope(&t, &y, 100);
        assert_eq!(e.len(), 100);
        let max = y.iter().cloned().fold(f64::MIN, f64::max);
        assert_eq!(e.iter().map(|e| e.2).fold(f64::MIN, f64::max), max);
        assert!(e.iter().all(|(_, lo, hi)| lo <= hi));
        assert_eq!(band(&e).len(), 200);
        assert!(envelope(&[], &[], 10).is_empty());
        // 200 s of 5 rad/s: 318 crossings, an envelope of 79 buckets, about two cycles each.
        assert_eq!(buckets_for(&y), 79);
        // Noise about a flat line is not a crossing.
        let quiet: Vec<f64> = (0..5_000)
            .map(|i| if i % 2 == 0 { 1e-3 } else { -1e-3 })
            .collect();
        let mut quiet_then_sine = quiet.clone();
        quiet_then_sine.extend(&y[..1_000]);
        assert!(!dense(&quiet_then_sine));
    }
}
