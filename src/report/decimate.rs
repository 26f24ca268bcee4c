//! Decimation of long series for plotting: the series is cut into buckets and each bucket keeps
//! its smallest and largest sample, so peaks, spikes and the envelope survive while a line has
//! at most a few thousand points. The CSV of a figure holds exactly the decimated samples.

/// The most points drawn for one line of a figure.
pub const MAX_POINTS_PER_LINE: usize = 20_000;

/// Indices (increasing) of at most `max_points` samples of `y` that keep, in each of
/// `max_points / 2 - 1` equal buckets, the smallest and the largest finite value, plus the first
/// and the last sample. A series no longer than `max_points` is kept whole.
pub fn decimate_indices(y: &[f64], max_points: usize) -> Vec<usize> {
    let n = y.len();
    if n <= max_points.max(4) {
        return (0..n).collect();
    }
    let buckets = (max_points.max(4) / 2 - 1).max(1);
    let size = n.div_ceil(buckets);
    let mut keep = Vec::with_capacity(2 * buckets + 2);
    keep.push(0);
    for start in (0..n).step_by(size) {
        let end = (start + size).min(n);
        let mut lo: Option<usize> = None;
        let mut hi: Option<usize> = None;
        for i in start..end {
            if !y[i].is_finite() {
                continue;
            }
            if lo.is_none_or(|j| y[i] < y[j]) {
                lo = Some(i);
            }
            if hi.is_none_or(|j| y[i] > y[j]) {
                hi = Some(i);
            }
        }
        match (lo, hi) {
            (Some(a), Some(b)) => {
                keep.push(a.min(b));
                keep.push(a.max(b));
            }
            _ => keep.push(start),
        }
    }
    keep.push(n - 1);
    keep.dedup();
    keep
}

/// Indices that decimate several series of equal length together: each gets an equal share of
/// `max_points`, and the union of their kept samples is returned (increasing, at most
/// `max_points` long), so one set of rows serves every series of a figure.
pub fn decimate_union(series: &[&[f64]], max_points: usize) -> Vec<usize> {
    let Some(n) = series.iter().map(|s| s.len()).min() else {
        return Vec::new();
    };
    if n <= max_points {
        return (0..n).collect();
    }
    let share = (max_points / series.len().max(1)).max(4);
    let mut keep: Vec<usize> = series
        .iter()
        .flat_map(|s| decimate_indices(&s[..n], share))
        .collect();
    keep.sort_unstable();
    keep.dedup();
    keep
}

/// The samples of `y` at `indices`.
pub fn pick(y: &[f64], indices: &[usize]) -> Vec<f64> {
    indices.iter().filter_map(|&i| y.get(i).copied()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noisy_sine(n: usize) -> Vec<f64> {
        // Deterministic pseudo-noise (a linear congruential generator), no dependency.
        let mut state = 12345u64;
        (0..n)
            .map(|i| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
                let noise = ((state >> 33) as f64 / (1u64 << 31) as f64) - 0.5;
                (i as f64 * 0.001).sin() + 0.1 * noise
            })
            .collect()
    }

    #[test]
    fn short_series_are_kept_whole() {
        let y = noisy_sine(100);
        assert_eq!(decimate_indices(&y, 1000), (0..100).collect::<Vec<_>>());
    }

    #[test]
    fn keeps_global_and_local_extremes_within_the_budget() {
        let mut y = noisy_sine(200_000);
        let spikes = [(1_234, 5.0), (77_777, -6.0), (150_001, 7.5)];
        for (i, v) in spikes {
            y[i] = v;
        }
        let keep = decimate_indices(&y, 2_000);
        assert!(keep.len() <= 2_000, "{} points", keep.len());
        assert!(keep.windows(2).all(|w| w[0] < w[1]));
        for (i, _) in spikes {
            assert!(keep.contains(&i), "spike at {i} lost");
        }
        assert_eq!(keep.first(), Some(&0));
        assert_eq!(keep.last(), Some(&(y.len() - 1)));
        let kept = pick(&y, &keep);
        let max = |v: &[f64]| v.iter().cloned().fold(f64::MIN, f64::max);
        let min = |v: &[f64]| v.iter().cloned().fold(f64::MAX, f64::min);
        assert_eq!(max(&kept), max(&y));
        assert_eq!(min(&kept), min(&y));
    }

    #[test]
    fn union_keeps_the_extremes_of_every_series() {
        let a = noisy_sine(100_000);
        let mut b: Vec<f64> = a.iter().map(|v| -v * 2.0).collect();
        b[4242] = 100.0;
        let keep = decimate_union(&[&a, &b], 4_000);
        assert!(keep.len() <= 4_000);
        assert!(keep.contains(&4242));
        let argmax_a = (0..a.len()).max_by(|&i, &j| a[i].total_cmp(&a[j])).unwrap();
        assert!(keep.contains(&argmax_a));
    }

    #[test]
    fn non_finite_samples_do_not_hide_extremes() {
        let mut y = noisy_sine(50_000);
        y[10] = f64::NAN;
        y[20] = 9.0;
        let keep = decimate_indices(&y, 500);
        assert!(keep.contains(&20));
    }
}
