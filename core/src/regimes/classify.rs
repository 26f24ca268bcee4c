//! Labelling each cycle pre-resonance, resonance or post-resonance.
//!
//! The rules, with the thresholds of [`RegimeThresholds`] (docs/ARCHITECTURE.md §1 describes the regimes
//! these defaults reproduce):
//!
//! 1. The noise σ of the force is `noise_sigma` if given, else [`noise_floor`] of the record.
//! 2. A cycle's force is *negligible* if its peak |F| ≤ max(`negligible_force` (0.2 N),
//!    `negligible_k`·σ). If every cycle's force is negligible the record has no STF effect:
//!    [`Classification::no_stf`] is set and every cycle is labelled
//!    [`Regime::PreResonance`] ("force negligible") — no regime is invented from noise.
//! 3. Otherwise, by default, the boundaries follow the source study's behavioural definitions
//!    ([`super::rules`]): pre → resonance where the force stops being negligible; resonance →
//!    post where the force, after being on for most of the cycle, becomes on–off (zero for more
//!    than 1 − `resonance_duty` of the cycle) or falls back to negligible. The labels follow the
//!    boundaries; each [`Boundary`](super::Boundary) names the rule that placed it.
//! 4. With `amplitude_rule` (an option, off by default) the earlier amplitude criterion runs
//!    instead ([`label_cycles`]): a cycle is [`Regime::Resonance`] when its force is not
//!    negligible, on for at least `resonance_duty` of the cycle and its amplitude at least
//!    `resonance_amplitude` (0.6) of the record's largest; any other cycle is
//!    [`Regime::PreResonance`] below ω of the largest-amplitude cycle and
//!    [`Regime::PostResonance`] above it. The labels are smoothed by a median filter over
//!    `smoothing_cycles` (5) cycles, ordered Pre < Resonance < Post, and [`find_boundaries`]
//!    places their changes in ω, with an uncertainty.

use serde::Serialize;

use super::boundaries::{find_boundaries, Boundaries};
use super::cycles::Cycle;
use super::error::RegimeError;
use super::features::{features, CycleFeatures};
use super::median::median_filter;
use super::noise::noise_floor;
pub use super::regime::Regime;
use super::rules::place;
use super::thresholds::RegimeThresholds;
use crate::data::force_data::ForceData;

/// A record's cycles, their features and labels.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Classification {
    /// σ of the force noise used, N (given or estimated).
    pub noise_sigma: f64,
    /// The on-threshold used for the duty, N.
    pub on_threshold: f64,
    /// Peak force at or below which a cycle's force counted as negligible, N.
    pub negligible_level: f64,
    /// Whether every cycle's force is negligible (no STF effect in the record).
    pub no_stf: bool,
    /// ω of the largest-amplitude cycle (the resonance peak), rad/s; NaN without cycles.
    pub peak_omega: f64,
    /// The cycles.
    pub cycles: Vec<Cycle>,
    /// Their features.
    pub features: Vec<CycleFeatures>,
    /// Labels before smoothing: by the definitions, what each cycle's own behaviour says — on:
    /// resonance; negligible: pre-resonance where labelled so, else post-resonance; on–off:
    /// post-resonance where labelled so, else resonance (pulses of a force that is starting);
    /// with `amplitude_rule`, rules 2–4 of the amplitude criterion.
    pub raw_labels: Vec<Regime>,
    /// The labels: by the definitions, those the boundaries give; with `amplitude_rule`, the
    /// median-filtered raw labels.
    pub labels: Vec<Regime>,
    /// Where the smoothed labels change, rad/s.
    pub boundaries: Boundaries,
}

impl Classification {
    /// Number of cycles labelled `regime`.
    pub fn count(&self, regime: Regime) -> usize {
        self.labels.iter().filter(|&&r| r == regime).count()
    }

    /// The indices of the cycles labelled `regime`.
    pub fn cycles_in(&self, regime: Regime) -> Vec<usize> {
        (0..self.labels.len())
            .filter(|&i| self.labels[i] == regime)
            .collect()
    }
}

/// Raw labels of cycles with `features` (rules 2–4 of the [module doc](self)), given the
/// negligible-force level (N). Returns the labels, whether the record has no STF effect and ω
/// of the largest-amplitude cycle.
pub fn label_cycles(
    features: &[CycleFeatures],
    th: &RegimeThresholds,
    negligible_level: f64,
) -> (Vec<Regime>, bool, f64) {
    let peak = features
        .iter()
        .max_by(|a, b| a.amplitude.total_cmp(&b.amplitude));
    let (a_max, peak_omega) = peak.map_or((0.0, f64::NAN), |p| (p.amplitude, p.omega));
    let significant = |f: &CycleFeatures| f.f_peak > negligible_level;
    let no_stf = !features.iter().any(significant);
    let labels = features
        .iter()
        .map(|f| {
            if no_stf {
                Regime::PreResonance
            } else if significant(f)
                && f.duty >= th.resonance_duty
                && f.amplitude >= th.resonance_amplitude * a_max
            {
                Regime::Resonance
            } else if f.omega < peak_omega {
                Regime::PreResonance
            } else {
                Regime::PostResonance
            }
        })
        .collect();
    (labels, no_stf, peak_omega)
}

/// Classify the cycles of a record (see the [module doc](self) for the rules).
pub fn classify(
    sig: &ForceData,
    cycles: Vec<Cycle>,
    th: &RegimeThresholds,
) -> Result<Classification, RegimeError> {
    th.check()?;
    sig.check()?;
    let noise_sigma = match th.noise_sigma {
        Some(s) => s,
        None => noise_floor(sig.f)?,
    };
    let features = features(sig, &cycles, th, noise_sigma)?;
    let negligible_level = th.negligible_level(noise_sigma);
    let (amp_raw, no_stf, peak_omega) = label_cycles(&features, th, negligible_level);
    let (raw_labels, labels, boundaries) = if no_stf {
        let l = vec![Regime::PreResonance; features.len()];
        (l.clone(), l, Boundaries::default())
    } else if th.amplitude_rule {
        let labels = median_filter(&amp_raw, th.smoothing_cycles);
        let omega: Vec<f64> = features.iter().map(|f| f.omega).collect();
        let b = find_boundaries(&omega, &amp_raw, &labels, th.smoothing_cycles);
        (amp_raw, labels, b)
    } else {
        let p = place(&features, th, negligible_level);
        (p.raw, p.labels, p.boundaries)
    };
    Ok(Classification {
        noise_sigma,
        on_threshold: th.on_threshold(noise_sigma),
        negligible_level,
        no_stf,
        peak_omega,
        cycles,
        features,
        raw_labels,
        labels,
        boundaries,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use Regime::{PostResonance as Post, PreResonance as Pre, Resonance as Res};

    fn feat(omega: f64, amplitude: f64, f_peak: f64, duty: f64) -> CycleFeatures {
        CycleFeatures {
            t_mid: omega,
            omega,
            amplitude,
            f_peak,
            f_rms: f_peak / 2.0,
            duty,
            energy: 0.0,
            energy_ratio: 0.0,
            corr_x: 0.0,
            corr_v: 0.0,
            corr_a: 0.0,
            f_peak_smooth: f_peak,
            c_eq: 0.0,
            phase_x: f64::NAN,
            phase_v: f64::NAN,
        }
    }

    #[test]
    fn the_rules_label_a_hand_made_sweep() {
        let th = RegimeThresholds::default();
        let f = [
            feat(3.0, 0.0001, 0.05, 0.0), // stuck, no force
            feat(4.0, 0.005, 0.5, 0.3),   // starting, on–off below the peak
            feat(5.0, 0.02, 3.0, 0.9),    // resonance
            feat(6.0, 0.03, 5.0, 0.95),   // the peak
            feat(8.0, 0.02, 3.0, 0.8),    // resonance
            feat(10.0, 0.008, 1.0, 0.4),  // on–off after the peak
            feat(12.0, 0.004, 0.1, 0.0),  // negligible after the peak
            feat(13.0, 0.02, 3.0, 0.4),   // big but on–off (duty below resonance_duty)
        ];
        let (l, no_stf, peak) = label_cycles(&f, &th, 0.2);
        assert!(!no_stf);
        assert_eq!(peak, 6.0);
        assert_eq!(l, vec![Pre, Pre, Res, Res, Res, Post, Post, Post]);
    }

    #[test]
    fn noise_alone_invents_no_regime() {
        let th = RegimeThresholds::default();
        let f: Vec<_> = (0..30)
            .map(|i| {
                feat(
                    3.0 + 0.3 * i as f64,
                    0.001 + 0.03 * (i == 12) as u8 as f64,
                    0.15,
                    0.9,
                )
            })
            .collect();
        let (l, no_stf, _) = label_cycles(&f, &th, 0.2);
        assert!(no_stf);
        assert!(l.iter().all(|&r| r == Pre));
    }
}
