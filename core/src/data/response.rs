//! Summaries of a response: local maxima (the frequency response of a sweep), the resonance
//! peak, the breakaway from sticking and the time motion stops.

use serde::Serialize;

use crate::numerics::derivative::noise_sigma;

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

/// The local maxima of `x` above zero that stand out from its noise (the upper envelope of an
/// oscillation), with ω at each. A maximum counts once `x` has fallen below it by more than
/// [`noise_step`] and by more than half of its rise from the trough before it; the next is
/// looked for once `x` has risen more than `noise_step` above the lowest value since. So
/// noise at a crest (whose swings reach 6 σ over a slow cycle's top) makes no second maximum
/// while the oscillation is well above the noise. On a record with the rig's sensors (x
/// noise σ ≈ 0.05 mm in 10 µm steps) the strict maxima were 8 412 on the paper's sweep,
/// most of them noise, drawn as a band from zero to the envelope; these are one a cycle
/// where the trolley moves (27, 47 and 41 over ω 4.5–6, 6–8 and 8–9.4 rad/s, where the
/// sweep makes 26.7, 47.4 and 41.2 cycles), while where it stands still the noise's own
/// swings of more than 4 σ still count (596 below 3.8 rad/s, 0.06–0.22 mm high). On a
/// noiseless run they are the strict maxima (the first of a flat top); the ends of the record
/// are never maxima.
pub fn local_maxima(t: &[f64], x: &[f64], omega: &[f64]) -> Vec<LocalMax> {
    let n = x.len().min(t.len()).min(omega.len());
    let x = &x[..n];
    let delta = noise_step(x);
    let mut out = Vec::new();
    let first = x.iter().position(|v| v.is_finite());
    // Looking for a maximum: the highest sample since the trough `low`; looking for a trough
    // (`top` none): the lowest value since the last maximum.
    let (mut top, mut low): (Option<usize>, f64) = (first, first.map_or(0.0, |i| x[i]));
    for (i, &v) in x.iter().enumerate().filter(|(_, v)| v.is_finite()) {
        match top {
            Some(k) if v > x[k] => top = Some(i),
            Some(k) if x[k] - v > delta.max(0.5 * (x[k] - low)) => {
                if Some(k) != first && x[k] > 0.0 {
                    out.push(LocalMax {
                        t: t[k],
                        omega: omega[k],
                        x: x[k],
                    });
                }
                (top, low) = (None, v);
            }
            Some(_) => {}
            None if v > low + delta => top = Some(i),
            None => low = low.min(v),
        }
    }
    out
}

/// How far `x` must fall from a maximum for it to count ([`local_maxima`]): four noise
/// standard deviations ([`noise_sigma`], as a record's kinematics estimate it), and at least
/// one and a half of the smallest nonzero step between samples, so an encoder's flicker
/// between two counts makes no maxima.
pub fn noise_step(x: &[f64]) -> f64 {
    let finite: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
    let sigma = noise_sigma(&finite);
    let quantum = finite
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 0.0)
        .fold(f64::INFINITY, f64::min);
    let quantum = if quantum.is_finite() { quantum } else { 0.0 };
    (4.0 * sigma).max(1.5 * quantum)
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
    fn maxima_of_a_noisy_stepped_sweep_are_one_a_cycle() {
        // A growing sine, 1 Hz over 20 s at 1 kHz, with noise of σ = 0.05 (a deterministic
        // pseudo-random sequence) rounded to steps of 0.01, as the rig's encoder gives x.
        let n = 20_000;
        let mut seed = 12345_u64;
        let mut noise = || {
            // The sum of four uniforms: near Gaussian, σ = 0.05.
            (0..4)
                .map(|_| {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
                })
                .sum::<f64>()
                * 0.05
                * 3f64.sqrt()
        };
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|t| {
                let clean = (1.0 + 0.5 * t) * (std::f64::consts::TAU * (t + 0.1)).sin();
                ((clean + noise()) / 0.01).round() * 0.01
            })
            .collect();
        let w = vec![1.0; n];
        let strict = (1..n - 1)
            .filter(|&i| x[i] > 0.0 && x[i] > x[i - 1] && x[i] >= x[i + 1])
            .count();
        assert!(
            strict > 1000,
            "{strict}: the noise makes many strict maxima"
        );
        let m = local_maxima(&t, &x, &w);
        assert_eq!(
            m.len(),
            20,
            "{:?}",
            m.iter().map(|m| m.t).collect::<Vec<_>>()
        );
        for (k, m) in m.iter().enumerate() {
            // Each near its crest (t = k + 0.15) and its height within 0.25 of the clean one.
            assert!((m.t - (k as f64 + 0.15)).abs() < 0.1, "{k}: {}", m.t);
            assert!((m.x - (1.0 + 0.5 * m.t)).abs() < 0.25, "{k}: {}", m.x);
        }
        // Steps without noise: flicker between two counts makes no maxima.
        let flicker = [0.0, 0.01, 0.0, 0.01, 0.0, 0.01, 0.0];
        assert!(local_maxima(&flicker, &flicker, &flicker).is_empty());
    }

    #[test]
    fn breakaway_and_stop_find_the_motion() {
        let v = [0.0, 1e-7, 2e-3, -5e-3, 1e-6, 0.0];
        assert_eq!(breakaway(&v, BREAKAWAY_DISPLACEMENT), Some(2));
        assert_eq!(stop(&v, MOVING_SPEED), Some(3));
        assert_eq!(breakaway(&[0.0; 3], BREAKAWAY_DISPLACEMENT), None);
    }
}
