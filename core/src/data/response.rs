//! Summaries of a response: local maxima (the frequency response of a sweep), the resonance
//! peak, the breakaway from sticking and the time motion stops.

use serde::Serialize;

/// A local maximum of the displacement.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LocalMax {
    /// Time, s.
    pub t: f64,
    /// Rotor speed at that time, rad/s.
    pub omega: f64,
    /// Displacement, m.
    pub x: f64,
}

/// Strict local maxima of `x` above zero (the upper envelope of an oscillation), with ω at each.
pub fn local_maxima(t: &[f64], x: &[f64], omega: &[f64]) -> Vec<LocalMax> {
    let n = x.len().min(t.len()).min(omega.len());
    (1..n.saturating_sub(1))
        .filter(|&i| x[i] > 0.0 && x[i] > x[i - 1] && x[i] >= x[i + 1])
        .map(|i| LocalMax {
            t: t[i],
            omega: omega[i],
            x: x[i],
        })
        .collect()
}

/// The largest |x| and where it occurs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Peak {
    /// Time, s.
    pub t: f64,
    /// Rotor speed, rad/s (NaN without a rotor).
    pub omega: f64,
    /// |x|, m.
    pub amplitude: f64,
}

/// The largest |x| of a run.
pub fn peak(t: &[f64], x: &[f64], omega: Option<&[f64]>) -> Option<Peak> {
    let (i, amplitude) = x
        .iter()
        .map(|v| v.abs())
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    Some(Peak {
        t: t[i],
        omega: omega.map_or(f64::NAN, |w| w[i]),
        amplitude,
    })
}

/// Speed above which the trolley counts as moving, m/s: far above the creep of the smoothed
/// dry friction (≈ 1e-7 m/s with the reference ε = 1e-6 m/s), far below real motion.
pub const MOVING_SPEED: f64 = 1e-4;

/// Displacement that marks the end of sticking, m: 0.1 mm, far above the creep of the stuck
/// trolley (micrometres) and the first visible oscillation of a sweep.
pub const BREAKAWAY_DISPLACEMENT: f64 = 1e-4;

/// Index of the first sample at which |x| exceeds `threshold`: the end of sticking.
///
/// On the reference sweep (0.047 rad/s²) this gives ω ≈ 3.79 rad/s, where the independent
/// implementation finds its first local maximum of x (0.10 mm at 3.80 rad/s); static friction
/// itself gives way a little earlier, at F0·ω² = T + ΔT (3.71 rad/s).
pub fn breakaway(x: &[f64], threshold: f64) -> Option<usize> {
    x.iter().position(|x| x.abs() > threshold)
}

/// Index of the last sample at which |v| exceeds `threshold`: where motion stops for good
/// (`None` if it never moved; the last index if it still moves at the end).
pub fn stop(v: &[f64], threshold: f64) -> Option<usize> {
    v.iter().rposition(|v| v.abs() > threshold)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maxima_of_a_sine_are_its_crests() {
        let t: Vec<f64> = (0..1000).map(|i| i as f64 * 0.01).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|t| (std::f64::consts::TAU * t).sin())
            .collect();
        let w = vec![1.0; t.len()];
        let m = local_maxima(&t, &x, &w);
        assert_eq!(m.len(), 10);
        assert!((m[0].t - 0.25).abs() < 0.011);
        let p = peak(&t, &x, Some(&w)).unwrap();
        assert!((p.amplitude - 1.0).abs() < 1e-3);
    }

    #[test]
    fn breakaway_and_stop_find_the_motion() {
        let v = [0.0, 1e-7, 2e-3, -5e-3, 1e-6, 0.0];
        assert_eq!(breakaway(&v, BREAKAWAY_DISPLACEMENT), Some(2));
        assert_eq!(stop(&v, MOVING_SPEED), Some(3));
        assert_eq!(breakaway(&[0.0; 3], BREAKAWAY_DISPLACEMENT), None);
    }
}
