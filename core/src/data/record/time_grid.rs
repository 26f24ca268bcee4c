//! Time stamps rounded to a coarse resolution, read as the uniform grid they round.
//!
//! A logger that writes its time column with few digits (0.1 ms at 610.35 Hz, say) makes a
//! uniformly sampled record look irregular: its steps take two values a rounding quantum `q`
//! apart (1.6 and 1.7 ms). Such a column is uniform within its rounding when its steps take at
//! most three values, each next one `q` above the last, `q` at most half the mean step, every
//! stamp lies on the grid of `q` from the first, and within `q` of the least-squares line
//! through them. The
//! reader then replaces the stamps by that line, `t_i = a + b·i`. Anything else — jitter,
//! dropped samples (steps of one and two periods), a gap — is left as it is, for the sample-
//! rate check of the kinematics to refuse.
//!
//! ```
//! use stf_core::data::record::Record;
//! // 610.35 Hz with its time written to 0.1 ms.
//! let mut text = String::from("t,x\n");
//! for i in 0..200 {
//!     let t = i as f64 / 610.35;
//!     text += &format!("{:.4},{}\n", t, (40.0 * t).sin());
//! }
//! let rec = Record::read_csv_from(text.as_bytes(), "rounded.csv").unwrap();
//! let step = rec.t[1] - rec.t[0];
//! assert!(rec.t.windows(2).all(|w| ((w[1] - w[0]) / step - 1.0).abs() < 1e-9));
//! assert!((step * 610.35 - 1.0).abs() < 1e-4);
//! ```

use crate::numerics::derivative::UNIFORM_STEP_TOLERANCE;

/// The most distinct step values a rounded uniform column shows (two, or three when the
/// clock itself was slightly off the stated rate).
const MOST_STEP_VALUES: usize = 3;

/// How far beyond `q/2` a stamp may lie from the fitted line, as a share of `q`: the line is
/// itself estimated from the rounded stamps, and stamps whose true times sit on a rounding
/// boundary (1 kHz from t = 0.05 ms, to 0.1 ms) round up or down with the last bit of the
/// clock, which tilts it (0.79 q seen).
const LINE_SLACK: f64 = 0.5;

/// The uniform grid `t` rounds, if it is a rounded uniform grid and not uniform already
/// (within [`UNIFORM_STEP_TOLERANCE`]); `None` otherwise.
pub(crate) fn regular_within_rounding(t: &[f64]) -> Option<Vec<f64>> {
    let n = t.len();
    if n < 3 {
        return None;
    }
    let mean = (t[n - 1] - t[0]) / (n - 1) as f64;
    if !(mean.is_finite() && mean > 0.0) {
        return None;
    }
    let steps = || t.windows(2).map(|w| w[1] - w[0]);
    if steps().all(|s| (s - mean).abs() <= UNIFORM_STEP_TOLERANCE * mean) {
        return None;
    }
    let q = quantum(steps(), mean)?;
    // Rounded stamps lie on the rounding's own grid; a stamp moved off it (a logger's jitter,
    // one sample written late) is not rounding, however few step values it makes.
    let on_grid = t.iter().all(|&ti| {
        let k = (ti - t[0]) / q;
        (k - k.round()).abs() <= 0.01
    });
    if !on_grid {
        return None;
    }
    let (a, b) = line(t);
    let worst = t
        .iter()
        .enumerate()
        .map(|(i, &ti)| (ti - (a + b * i as f64)).abs())
        .fold(0.0_f64, f64::max);
    (worst <= (0.5 + LINE_SLACK) * q).then(|| (0..n).map(|i| a + b * i as f64).collect())
}

/// The rounding quantum of steps that take at most [`MOST_STEP_VALUES`] values, each `q`
/// above the last, with `q` at most half the `mean` step.
fn quantum(steps: impl Iterator<Item = f64>, mean: f64) -> Option<f64> {
    // Values within this of each other are the same step written twice in binary.
    let same = 1e-6 * mean;
    let mut values: Vec<f64> = Vec::new();
    for s in steps {
        if !values.iter().any(|v| (v - s).abs() <= same) {
            if values.len() == MOST_STEP_VALUES {
                return None;
            }
            values.push(s);
        }
    }
    values.sort_by(f64::total_cmp);
    let gaps: Vec<f64> = values.windows(2).map(|w| w[1] - w[0]).collect();
    let q = *gaps.first()?;
    let even = gaps.iter().all(|g| (g - q).abs() <= 0.01 * q);
    (even && q <= 0.5 * mean).then_some(q)
}

/// The least-squares line `t_i ≈ a + b·i`, about the middle sample (no cancellation on long
/// records).
fn line(t: &[f64]) -> (f64, f64) {
    let n = t.len() as f64;
    let mid = 0.5 * (n - 1.0);
    let t_mean = t.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, &ti) in t.iter().enumerate() {
        let di = i as f64 - mid;
        sxy += di * (ti - t_mean);
        sxx += di * di;
    }
    let b = sxy / sxx;
    (t_mean - b * mid, b)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::*;

    fn rounded(rate: f64, t0: f64, n: usize, q: f64) -> Vec<f64> {
        (0..n)
            .map(|i| ((t0 + i as f64 / rate) / q).round() * q)
            .collect()
    }

    #[test]
    fn rounded_stamps_become_the_grid_they_round() {
        for (rate, t0, q) in [
            (610.35, 0.0, 1e-4),
            (1000.0, 0.00005, 1e-4),
            (333.0, 1.2, 1e-3),
        ] {
            let t = rounded(rate, t0, 5000, q);
            let grid = regular_within_rounding(&t).unwrap();
            assert!(
                (grid[1] - grid[0] - 1.0 / rate).abs() < 1e-3 / rate,
                "{rate}"
            );
            let off = t.iter().zip(&grid).map(|(a, b)| (a - b).abs());
            assert!(off.fold(0.0, f64::max) <= q, "{rate}");
        }
    }

    #[test]
    fn uniform_jittered_and_gapped_stamps_are_left_alone() {
        let uniform: Vec<f64> = (0..100).map(|i| i as f64 * 0.01).collect();
        assert!(regular_within_rounding(&uniform).is_none());
        // One stamp written 0.3 ms late among 10 ms steps: three step values 0.3 ms apart,
        // but off any grid of 0.3 ms.
        let mut late = uniform.clone();
        late[50] += 0.0003;
        assert!(regular_within_rounding(&late).is_none());
        // One sample dropped: steps of one and two periods.
        let mut gapped = uniform.clone();
        gapped.remove(50);
        assert!(regular_within_rounding(&gapped).is_none());
        // Jitter of many values.
        let jittered: Vec<f64> = (0..100u64)
            .map(|i| {
                let hash = i.wrapping_mul(2_654_435_761) >> 7;
                i as f64 * 0.01 + 1e-3 * (hash % 1000) as f64 / 1000.0
            })
            .collect();
        assert!(regular_within_rounding(&jittered).is_none());
        // A rate that drifts, rounded: the stamps leave the line.
        let drifting: Vec<f64> = (0..2000)
            .map(|i| {
                let t = i as f64 * 1e-3 * (1.0 + 1e-4 * i as f64);
                (t / 1e-4).round() * 1e-4
            })
            .collect();
        assert!(regular_within_rounding(&drifting).is_none());
    }
}
