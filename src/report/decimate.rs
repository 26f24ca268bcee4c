//! Decimation of long series for plotting: the series is cut into buckets and each bucket keeps
//! its smallest and largest sample, so peaks, spikes and the envelope survive while a line has
//! at most a few thousand points. The CSV of a figure holds exactly the decimated samples.

/// The most points drawn for one line of a figure.
pub const MAX_POINTS_PER_LINE: usize = 20_000;

/// Indices (increasing) of at most `max_points` samples of `y` that keep, in each of
/// `(max_points - 2) / 3` equal buckets, the smallest and the largest finite value, plus the
/// first and the last sample. A bucket holding a non-finite sample (a gap) also keeps the
/// first of them, so a line drawn through the kept samples breaks there instead of bridging
/// the gap with a chord. A series no longer than `max_points` is kept whole.
pub fn decimate_indices(y: &[f64], max_points: usize) -> Vec<usize> {
    let n = y.len();
    if n <= max_points.max(5) {
        return (0..n).collect();
    }
    let buckets = ((max_points.max(5) - 2) / 3).max(1);
    let size = n.div_ceil(buckets);
    let mut keep = Vec::with_capacity(3 * buckets + 2);
    keep.push(0);
    for start in (0..n).step_by(size) {
        let end = (start + size).min(n);
        keep.extend(bucket_keeps(y, start..end));
    }
    keep.push(n - 1);
    keep.dedup();
    keep
}

/// What one bucket `range` of `y` keeps, increasing: its smallest and largest finite sample
/// and its first non-finite one (or its first sample, if none is finite).
fn bucket_keeps(y: &[f64], range: std::ops::Range<usize>) -> Vec<usize> {
    let start = range.start;
    let mut lo: Option<usize> = None;
    let mut hi: Option<usize> = None;
    let mut gap: Option<usize> = None;
    for i in range {
        if !y[i].is_finite() {
            gap = gap.or(Some(i));
            continue;
        }
        if lo.is_none_or(|j| y[i] < y[j]) {
            lo = Some(i);
        }
        if hi.is_none_or(|j| y[i] > y[j]) {
            hi = Some(i);
        }
    }
    let mut kept: Vec<usize> = [lo, hi, gap].into_iter().flatten().collect();
    if kept.is_empty() {
        kept.push(start);
    }
    kept.sort_unstable();
    kept.dedup();
    kept
}

/// Indices that decimate several series of equal length together: each gets an equal share of
/// `max_points` (five at least), and the union of their kept samples is returned (increasing,
/// at most `max_points` long, or five per series when there are more series than
/// `max_points / 5`), so one set of rows serves every series of a figure.
pub fn decimate_union(series: &[&[f64]], max_points: usize) -> Vec<usize> {
    let Some(n) = series.iter().map(|s| s.len()).min() else {
        return Vec::new();
    };
    if n <= max_points {
        return (0..n).collect();
    }
    let share = (max_points / series.len().max(1)).max(5);
    let mut keep: Vec<usize> = series
        .iter()
        .flat_map(|s| decimate_indices(&s[..n], share))
        .collect();
    keep.sort_unstable();
    keep.dedup();
    keep
}

/// [`decimate_union`] within each of several stretches `ranges` of the series (windows of a
/// record, regimes), each stretch with an equal share of `max_points`: the kept indices of
/// every stretch in turn (each stretch's increasing), into the whole series.
pub fn decimate_ranges(
    series: &[&[f64]],
    ranges: &[std::ops::Range<usize>],
    max_points: usize,
) -> Vec<Vec<usize>> {
    let share = max_points / ranges.len().max(1);
    ranges
        .iter()
        .map(|r| {
            let parts: Vec<&[f64]> = series.iter().map(|s| &s[r.clone()]).collect();
            let kept = decimate_union(&parts, share);
            kept.into_iter().map(|i| i + r.start).collect()
        })
        .collect()
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
    fn a_gap_is_kept_so_lines_break_there() {
        let mut y = noisy_sine(100_000);
        for v in &mut y[40_000..40_010] {
            *v = f64::NAN;
        }
        let keep = decimate_indices(&y, 1_000);
        assert!(keep.len() <= 1_000, "{} points", keep.len());
        let gaps: Vec<usize> = keep.iter().copied().filter(|&i| y[i].is_nan()).collect();
        assert_eq!(gaps, [40_000]);
    }

    #[test]
    fn ranges_are_decimated_apart_within_their_share() {
        let y = noisy_sine(300_000);
        let ranges = [1_000..101_000, 200_000..200_500];
        let kept = decimate_ranges(&[&y], &ranges, 2_000);
        assert!(
            kept[0].len() <= 1_000 && kept[0].len() > 600,
            "{}",
            kept[0].len()
        );
        assert!(kept[0].iter().all(|i| ranges[0].contains(i)));
        assert_eq!(kept[1], (200_000..200_500).collect::<Vec<_>>());
        let max = (1_000..101_000)
            .max_by(|&i, &j| y[i].total_cmp(&y[j]))
            .unwrap();
        assert!(kept[0].contains(&max));
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
