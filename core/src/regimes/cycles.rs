//! Cutting a record into cycles: rotor revolutions, or oscillations of x without a rotor.
//!
//! A rotor cycle starts at the first sample at which the unwrapped angle φ has passed a new
//! multiple of 2π (in the direction the rotor turns; jitter back across a multiple does not
//! start a second cycle). Without a rotor, a cycle starts at an upward zero crossing of x
//! (`x[i-1] < 0 ≤ x[i]`) that follows a dip below `−hysteresis`, so noise around zero does not
//! cut extra cycles. The partial cycles before the first and after the last cut are dropped.
//!
//! A [`Cycle`] holds sample indices: `start` is its first sample, `end` the first sample of the
//! next cycle. Per-sample quantities (duty, peaks, RMS) use `start..end`; integrals over the
//! cycle (∮F dx) run from sample `start` to sample `end`.

use serde::Serialize;
use std::f64::consts::TAU;

use super::error::{check_finite, check_len, RegimeError};

/// One cycle of the record.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Cycle {
    /// First sample of the cycle.
    pub start: usize,
    /// First sample of the next cycle (exclusive end).
    pub end: usize,
    /// Time at the middle of the cycle, s.
    pub t_mid: f64,
    /// Mean rotor speed over the cycle (Δφ/Δt), or 2π/period for cycles of x, rad/s.
    pub omega: f64,
}

impl Cycle {
    /// Number of samples in `start..end`.
    pub fn len(&self) -> usize {
        self.end.saturating_sub(self.start)
    }

    /// Whether the cycle has no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

fn check_time(t: &[f64]) -> Result<(), RegimeError> {
    check_finite("t", t)?;
    match t.windows(2).position(|w| !(w[1] > w[0])) {
        Some(i) => Err(RegimeError::TimeNotIncreasing { index: i + 1 }),
        None => Ok(()),
    }
}

/// Cycles of the rotor from the unwrapped angle `phi` (rad) sampled at times `t` (s).
///
/// Works for either direction of rotation; ω of a cycle is |Δφ|/Δt over it (positive).
pub fn cycles_from_phase(t: &[f64], phi: &[f64]) -> Result<Vec<Cycle>, RegimeError> {
    check_len("phi", phi, t.len())?;
    check_time(t)?;
    check_finite("phi", phi)?;
    let (Some(&first), Some(&last)) = (phi.first(), phi.last()) else {
        return Ok(Vec::new());
    };
    let dir = if last >= first { 1.0 } else { -1.0 };
    let turn = |p: f64| (dir * p / TAU).floor();
    let mut k_max = turn(first);
    let mut cuts = Vec::new();
    for (i, &p) in phi.iter().enumerate().skip(1) {
        let k = turn(p);
        if k > k_max {
            k_max = k;
            cuts.push(i);
        }
    }
    Ok(between(&cuts, t, |s, e| {
        (phi[e] - phi[s]).abs() / (t[e] - t[s])
    }))
}

/// The cycles between consecutive `cuts` (sample indices) at times `t`, each's ω from
/// `omega(start, end)`.
fn between(cuts: &[usize], t: &[f64], omega: impl Fn(usize, usize) -> f64) -> Vec<Cycle> {
    cuts.windows(2)
        .map(|w| {
            let (s, e) = (w[0], w[1]);
            Cycle {
                start: s,
                end: e,
                t_mid: 0.5 * (t[s] + t[e]),
                omega: omega(s, e),
            }
        })
        .collect()
}

/// `count` equal stretches of a record that has too few cycles of its own to hold some out
/// (a positioning stroke, a single transient): each stretch is scored as a cycle would be,
/// with `omega` 2π over its duration. Like a cycle, each ends at the first sample of the next
/// (the last at the record's last sample), so integrals over a stretch have the sample they
/// close on: every `end` is below `t.len()`.
pub fn segments(t: &[f64], count: usize) -> Vec<Cycle> {
    let Some(last) = t.len().checked_sub(1) else {
        return Vec::new();
    };
    let count = count.clamp(1, last.max(1));
    (0..count)
        .map(|i| (i * last / count, (i + 1) * last / count))
        .filter(|(a, b)| b > a)
        .map(|(start, end)| {
            let span = (t[end] - t[start]).max(f64::MIN_POSITIVE);
            Cycle {
                start,
                end,
                t_mid: 0.5 * (t[start] + t[end]),
                omega: std::f64::consts::TAU / span,
            }
        })
        .collect()
}

/// Cycles of the displacement `x` (m) at times `t` (s): upward zero crossings, each armed by a
/// dip below `−hysteresis` (m, ≥ 0; e.g. a few σ of the position noise).
pub fn cycles_from_x(t: &[f64], x: &[f64], hysteresis: f64) -> Result<Vec<Cycle>, RegimeError> {
    check_len("x", x, t.len())?;
    check_time(t)?;
    check_finite("x", x)?;
    if !(hysteresis >= 0.0 && hysteresis.is_finite()) {
        return Err(RegimeError::BadThreshold {
            name: "hysteresis",
            value: hysteresis,
            why: "must be finite and ≥ 0",
        });
    }
    let mut armed = false;
    let mut cuts = Vec::new();
    for i in 1..x.len() {
        if x[i] < -hysteresis {
            armed = true;
        }
        if armed && x[i - 1] < 0.0 && x[i] >= 0.0 {
            cuts.push(i);
            armed = false;
        }
    }
    Ok(between(&cuts, t, |s, e| TAU / (t[e] - t[s])))
}

/// The rotor angle (rad, from 0) integrated from its speed `omega` (rad/s) by the trapezoid
/// rule, for records that carry ω but not φ.
pub fn phase_from_omega(t: &[f64], omega: &[f64]) -> Result<Vec<f64>, RegimeError> {
    check_len("omega", omega, t.len())?;
    check_time(t)?;
    check_finite("omega", omega)?;
    let mut acc = 0.0;
    let steps = (0..t.len()).map(|i| {
        if i > 0 {
            acc += 0.5 * (omega[i] + omega[i - 1]) * (t[i] - t[i - 1]);
        }
        acc
    });
    Ok(steps.collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, rate: f64) -> Vec<f64> {
        (0..n).map(|i| i as f64 / rate).collect()
    }

    #[test]
    fn segments_end_inside_the_record_so_their_features_can_be_read() {
        // The bundled chirp record's shape: 4 001 samples at 200 Hz, cut into 10 stretches.
        // The last stretch once ended at 4 001, past the last sample an integral over it
        // closes on ("cycle 3875..4001 does not fit 4001 samples").
        for n in [4001, 6001, 2, 3, 10] {
            let t = grid(n, 200.0);
            let segs = segments(&t, 10);
            assert!(!segs.is_empty(), "{n}");
            assert_eq!(segs[0].start, 0);
            assert_eq!(segs.last().unwrap().end, n - 1, "{n}");
            assert!(segs.windows(2).all(|w| w[0].end == w[1].start));
            let x: Vec<f64> = t.iter().map(|t| (6.0 * t).sin()).collect();
            let f: Vec<f64> = x.iter().map(|x| 0.5 * x).collect();
            let sig = crate::data::force_data::ForceData {
                t: &t,
                x: &x,
                v: &x,
                a: &x,
                f: &f,
            };
            for c in &segs {
                assert!(
                    c.end < n && c.omega.is_finite() && c.omega > 0.0,
                    "{n}: {c:?}"
                );
                crate::regimes::features::cycle_features(&sig, c, 0.1, 0.5).unwrap();
            }
        }
        assert!(segments(&[], 10).is_empty());
        assert!(segments(&[0.0], 10).is_empty());
    }

    #[test]
    fn constant_speed_gives_the_right_number_of_cycles() {
        // 100 s at ω = 3 rad/s from φ = 0.1: φ ends at 300.1 rad, 47 whole turns are crossed
        // (2π·1 … 2π·47), so 46 complete cycles lie between the crossings.
        let t = grid(100_001, 1000.0);
        let phi: Vec<f64> = t.iter().map(|t| 0.1 + 3.0 * t).collect();
        let c = cycles_from_phase(&t, &phi).unwrap();
        let crossed = ((0.1 + 300.0) / TAU).floor() as usize;
        assert_eq!(c.len(), crossed - 1);
        for cy in &c {
            assert!((cy.omega - 3.0).abs() < 3.0 * 2e-3, "ω {}", cy.omega);
            assert!((cy.t_mid - 0.5 * (t[cy.start] + t[cy.end])).abs() < 1e-12);
        }
        // Consecutive cycles share their boundary sample.
        assert!(c.windows(2).all(|w| w[0].end == w[1].start));
    }

    #[test]
    fn a_reversed_rotor_and_jitter_cut_the_same_cycles() {
        let t = grid(20_001, 1000.0);
        let fwd: Vec<f64> = t.iter().map(|t| 5.0 * t).collect();
        let rev: Vec<f64> = fwd.iter().map(|p| -p).collect();
        // Jitter of ±0.01 rad back and forth across each multiple of 2π.
        let jit: Vec<f64> = fwd
            .iter()
            .enumerate()
            .map(|(i, p)| p + if i % 2 == 0 { 0.01 } else { -0.01 })
            .collect();
        let a = cycles_from_phase(&t, &fwd).unwrap();
        let b = cycles_from_phase(&t, &rev).unwrap();
        let c = cycles_from_phase(&t, &jit).unwrap();
        assert_eq!(a.len(), b.len());
        assert_eq!(a.len(), c.len());
        assert!(b.iter().all(|c| c.omega > 0.0));
    }

    #[test]
    fn cycles_of_x_ignore_noise_around_zero() {
        // x = sin(2π·t) for 10 s, with a chatter of ±0.01 (more than a sample's step near zero).
        let t = grid(10_001, 1000.0);
        let x: Vec<f64> = t
            .iter()
            .enumerate()
            .map(|(i, t)| (TAU * t).sin() + if i % 2 == 0 { 0.01 } else { -0.01 })
            .collect();
        let c = cycles_from_x(&t, &x, 0.05).unwrap();
        assert_eq!(c.len(), 9);
        for cy in &c {
            assert!((cy.omega - TAU).abs() < 0.02, "ω {}", cy.omega);
        }
        // Without hysteresis the chatter cuts extra cycles.
        assert!(cycles_from_x(&t, &x, 0.0).unwrap().len() > 9);
    }

    #[test]
    fn phase_from_omega_integrates_a_sweep() {
        let t = grid(1001, 100.0);
        let w: Vec<f64> = t.iter().map(|t| 2.0 + 0.5 * t).collect();
        let phi = phase_from_omega(&t, &w).unwrap();
        assert!((phi[1000] - (2.0 * 10.0 + 0.25 * 100.0)).abs() < 1e-9);
    }

    #[test]
    fn bad_inputs_are_errors() {
        assert!(matches!(
            cycles_from_phase(&[0.0, 1.0], &[0.0]),
            Err(RegimeError::LengthMismatch { .. })
        ));
        assert!(cycles_from_phase(&[0.0, 1.0], &[0.0, f64::NAN]).is_err());
        assert!(cycles_from_x(&[0.0, 0.0], &[0.0, 1.0], 0.0).is_err());
        assert!(cycles_from_x(&[0.0, 1.0], &[0.0, 1.0], -1.0).is_err());
        assert!(cycles_from_phase(&[], &[]).unwrap().is_empty());
    }
}
