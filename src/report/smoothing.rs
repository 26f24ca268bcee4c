//! The smoothed trend of a frequency response, as the source study draws it: outliers are
//! replaced by the mean of their neighbours, then a centred moving average is taken.
//!
//! A point is an outlier when it departs from the median of its five-point neighbourhood by
//! more than `outlier_k` times a scale: the robust standard deviation of those departures
//! (1.4826 × their median absolute value) or, when larger, the median step between successive
//! points (so a clean, noise-free curve has no outliers but its spikes). It is replaced by the
//! mean of its nearest non-outlier neighbours.

/// Settings of [`smooth_trend`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Smoothing {
    /// How many robust standard deviations from the local median make an outlier.
    pub outlier_k: f64,
    /// Width of the centred moving average, in points (made odd; 1 = no averaging).
    pub window: usize,
}

impl Default for Smoothing {
    fn default() -> Self {
        Self {
            outlier_k: 4.0,
            window: 9,
        }
    }
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_unstable_by(f64::total_cmp);
    let n = values.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

/// Which points of `y` are outliers (see the module doc).
pub fn outliers(y: &[f64], outlier_k: f64) -> Vec<bool> {
    let n = y.len();
    if n < 3 {
        return vec![false; n];
    }
    let departure: Vec<f64> = (0..n)
        .map(|i| {
            let lo = i.saturating_sub(2);
            let hi = (i + 3).min(n);
            let mut around: Vec<f64> = (lo..hi).filter(|&j| j != i).map(|j| y[j]).collect();
            y[i] - median(&mut around)
        })
        .collect();
    let mut abs: Vec<f64> = departure.iter().map(|d| d.abs()).collect();
    let mut steps: Vec<f64> = y.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    let scale = (1.4826 * median(&mut abs)).max(median(&mut steps));
    // A floor so that an exactly flat series with one spike still flags the spike only.
    let floor = 1e-12 * y.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let limit = outlier_k * scale.max(floor);
    departure.iter().map(|d| d.abs() > limit).collect()
}

/// Replace outliers by the mean of their nearest non-outlier neighbours, then take a centred
/// moving average of width `window` (shrunk at the ends). Non-finite input points count as
/// outliers. Returns a series as long as `y`.
pub fn smooth_trend(y: &[f64], settings: &Smoothing) -> Vec<f64> {
    let n = y.len();
    let mut bad = outliers(y, settings.outlier_k);
    for (flag, v) in bad.iter_mut().zip(y) {
        *flag |= !v.is_finite();
    }
    let cleaned: Vec<f64> = (0..n)
        .map(|i| {
            if !bad[i] {
                return y[i];
            }
            let before = (0..i).rev().find(|&j| !bad[j]).map(|j| y[j]);
            let after = (i + 1..n).find(|&j| !bad[j]).map(|j| y[j]);
            match (before, after) {
                (Some(a), Some(b)) => 0.5 * (a + b),
                (Some(a), None) | (None, Some(a)) => a,
                (None, None) => y[i],
            }
        })
        .collect();
    moving_average(&cleaned, settings.window)
}

/// Centred moving average of width `window` (rounded up to odd), the window shrunk
/// symmetrically at the ends so that every output is an average of real points.
pub fn moving_average(y: &[f64], window: usize) -> Vec<f64> {
    let half = window / 2;
    let n = y.len();
    (0..n)
        .map(|i| {
            let h = half.min(i).min(n - 1 - i);
            let slice = &y[i - h..=i + h];
            slice.iter().sum::<f64>() / slice.len() as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn an_outlier_is_replaced_by_the_mean_of_its_neighbours() {
        let mut y: Vec<f64> = (0..30).map(|i| 1.0 + 0.1 * i as f64).collect();
        y[12] = 50.0;
        let flags = outliers(&y, 4.0);
        assert_eq!(flags.iter().filter(|f| **f).count(), 1);
        assert!(flags[12]);
        let s = smooth_trend(
            &y,
            &Smoothing {
                outlier_k: 4.0,
                window: 1,
            },
        );
        assert_relative_eq!(s[12], 0.5 * (y[11] + y[13]), epsilon = 1e-12);
        for i in (0..30).filter(|&i| i != 12) {
            assert_eq!(s[i], y[i], "point {i} changed");
        }
    }

    #[test]
    fn a_spike_on_a_flat_series_is_the_only_outlier() {
        let mut y = vec![2.0; 20];
        y[5] = -3.0;
        let flags = outliers(&y, 4.0);
        assert_eq!(flags.iter().filter(|f| **f).count(), 1);
        assert!(flags[5]);
    }

    #[test]
    fn moving_average_of_a_constant_is_the_constant() {
        let y = vec![3.7; 25];
        for w in [1, 3, 4, 9, 51] {
            for v in moving_average(&y, w) {
                assert_relative_eq!(v, 3.7, max_relative = 1e-14);
            }
        }
    }

    #[test]
    fn moving_average_keeps_a_straight_line_and_averages_noise() {
        let line: Vec<f64> = (0..40).map(|i| 2.0 * i as f64 - 5.0).collect();
        for (a, b) in moving_average(&line, 7).iter().zip(&line) {
            assert_relative_eq!(*a, *b, epsilon = 1e-12);
        }
        let zigzag: Vec<f64> = (0..40)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let s = moving_average(&zigzag, 9);
        assert!(s[10..30].iter().all(|v| v.abs() < 0.2));
    }

    #[test]
    fn non_finite_points_are_replaced() {
        let mut y: Vec<f64> = (0..10).map(|i| i as f64).collect();
        y[4] = f64::NAN;
        let s = smooth_trend(
            &y,
            &Smoothing {
                outlier_k: 4.0,
                window: 1,
            },
        );
        assert_relative_eq!(s[4], 4.0, epsilon = 1e-12);
    }
}
