//! Where the regimes change along a sweep, in rad/s, with an uncertainty.
//!
//! Each [`Boundary`] carries the [`BoundaryRule`] that placed it: the source study's behavioural
//! definitions ([`super::rules`]: the force stops being negligible; the force becomes on–off or
//! falls back to negligible) by default, or the amplitude criterion when
//! `RegimeThresholds::amplitude_rule` is set. The rest of this page describes how a change of
//! smoothed labels becomes a boundary ([`find_boundaries`], used by the amplitude criterion; the
//! definitions place theirs the same way from their own per-cycle behaviour).
//!
//! A boundary lies between two neighbouring cycles whose smoothed labels are Pre and Resonance
//! (for `pre_resonance`) or Resonance and Post (for `resonance_post`), in either order, so
//! down-sweeps work too; the first such pair counts. Its ω is the mean of the two cycles' ω.
//! Its uncertainty is half the ω span of the zone where the raw (unsmoothed) labels mix the two
//! regimes, looked for within `window` cycles of the change: from the first raw cycle of the new
//! regime to the last raw cycle of the old one, and at least the two cycles of the change
//! itself (so a clean change has ½·|Δω| of one cycle).

use serde::Serialize;

use super::regime::Regime;

/// Which rule placed a boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BoundaryRule {
    /// Pre → resonance where the force stops being negligible: its peak passes
    /// max(`negligible_force`, `negligible_k`·σ) and stays above it.
    ForceOnset,
    /// Resonance → post where the force, after being on for most of the cycle, becomes
    /// on–off: zero (at or below the on-threshold) for more than 1 − `resonance_duty` of the
    /// cycle, in intervals between its pulses.
    OnOff,
    /// Resonance → post where the force, after being on for most of the cycle, falls back to
    /// negligible.
    ForceGone,
    /// Resonance → post at the force's onset itself: the force is on–off from its first
    /// non-negligible cycle and never on for most of a cycle (impact spikes with no damping
    /// regime); the resonance has no cycles.
    OnOffFromOnset,
    /// The amplitude criterion (an option, `amplitude_rule`): resonance cycles also need
    /// `resonance_amplitude` of the record's largest amplitude.
    Amplitude,
}

impl BoundaryRule {
    /// A sentence saying what placed the boundary, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            BoundaryRule::ForceOnset => {
                "the force stops being negligible (its peak passes the negligible level)"
            }
            BoundaryRule::OnOff => {
                "the force becomes on–off (zero for at least the stated share of the cycle)"
            }
            BoundaryRule::ForceGone => "the force falls back to negligible after the resonance",
            BoundaryRule::OnOffFromOnset => {
                "the force is on–off from its onset: no cycle has it on for most of the cycle"
            }
            BoundaryRule::Amplitude => {
                "the amplitude criterion (a fraction of the record's largest amplitude)"
            }
        }
    }
}

/// One change of regime.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Boundary {
    /// ω at the change, rad/s.
    pub omega: f64,
    /// Half-width of the uncertainty, rad/s.
    pub uncertainty: f64,
    /// Index of the first cycle after the change.
    pub cycle: usize,
    /// The rule that placed it.
    pub rule: BoundaryRule,
}

/// The changes of regime of a record (`None` where there is no such change).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Boundaries {
    /// Between pre-resonance and resonance.
    pub pre_resonance: Option<Boundary>,
    /// Between resonance and post-resonance.
    pub resonance_post: Option<Boundary>,
}

/// The boundaries of smoothed labels `smoothed`, with raw labels `raw` and cycle speeds `omega`
/// (rad/s), all of the same length; see the [module doc](self).
pub fn find_boundaries(
    omega: &[f64],
    raw: &[Regime],
    smoothed: &[Regime],
    window: usize,
) -> Boundaries {
    let n = omega.len().min(raw.len()).min(smoothed.len());
    let find = |a: Regime, b: Regime| -> Option<Boundary> {
        let j = (1..n).find(|&j| {
            let (p, q) = (smoothed[j - 1], smoothed[j]);
            (p == a && q == b) || (p == b && q == a)
        })?;
        let (old, new) = (smoothed[j - 1], smoothed[j]);
        Some(boundary_at(
            &omega[..n],
            j,
            window,
            BoundaryRule::Amplitude,
            |i| raw[i] == new,
            |i| raw[i] == old,
        ))
    };
    Boundaries {
        pre_resonance: find(Regime::PreResonance, Regime::Resonance),
        resonance_post: find(Regime::Resonance, Regime::PostResonance),
    }
}

/// The boundary between cycles `j − 1` and `j` (j ≥ 1), placed by `rule`: its ω is the mean
/// of the two cycles' ω; its uncertainty half the ω span from the first cycle on the new side
/// (`is_new`) to the last on the old side (`is_old`), looked for within `window` (at least 3)
/// cycles of the change, and at least the two cycles of the change itself.
pub(super) fn boundary_at(
    omega: &[f64],
    j: usize,
    window: usize,
    rule: BoundaryRule,
    is_new: impl Fn(usize) -> bool,
    is_old: impl Fn(usize) -> bool,
) -> Boundary {
    let n = omega.len();
    let w = window.max(3);
    let (lo_n, hi_n) = (j.saturating_sub(w), (j + w).min(n));
    let first_new = (lo_n..hi_n).find(|&i| is_new(i)).unwrap_or(j);
    let last_old = (lo_n..hi_n).rev().find(|&i| is_old(i)).unwrap_or(j - 1);
    let (lo, hi) = (first_new.min(j - 1), last_old.max(j));
    let (a, b) = omega[lo..=hi]
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &w| {
            (a.min(w), b.max(w))
        });
    Boundary {
        omega: 0.5 * (omega[j - 1] + omega[j]),
        uncertainty: 0.5 * (b - a),
        cycle: j,
        rule,
    }
}

#[cfg(test)]
mod tests {
    use super::super::median::median_filter;
    use super::*;
    use Regime::{PostResonance as Post, PreResonance as Pre, Resonance as Res};

    #[test]
    fn clean_changes_sit_between_their_cycles() {
        let omega: Vec<f64> = (0..10).map(|i| 3.0 + 0.5 * i as f64).collect();
        let l = [Pre, Pre, Pre, Res, Res, Res, Res, Post, Post, Post];
        let b = find_boundaries(&omega, &l, &l, 3);
        let pr = b.pre_resonance.unwrap();
        assert_eq!(pr.cycle, 3);
        assert!((pr.omega - 4.25).abs() < 1e-12);
        assert!((pr.uncertainty - 0.25).abs() < 1e-12);
        let rp = b.resonance_post.unwrap();
        assert!((rp.omega - 6.25).abs() < 1e-12);
    }

    #[test]
    fn a_mixed_zone_widens_the_uncertainty() {
        // Known change points 4.0 and 9.0 rad/s on a grid of 0.1 rad/s, with raw labels flipping
        // in the three cycles on either side of the first change.
        let omega: Vec<f64> = (0..100).map(|i| 2.05 + 0.1 * i as f64).collect();
        let mut raw: Vec<Regime> = omega
            .iter()
            .map(|&w| {
                if w < 4.0 {
                    Pre
                } else if w < 9.0 {
                    Res
                } else {
                    Post
                }
            })
            .collect();
        raw[18] = Res; // ω 3.85
        raw[21] = Pre; // ω 4.15
        let smooth = median_filter(&raw, 5);
        let b = find_boundaries(&omega, &raw, &smooth, 5);
        let pr = b.pre_resonance.unwrap();
        assert!((pr.omega - 4.0).abs() < 1e-9, "{pr:?}");
        assert!(
            (pr.uncertainty - 0.15).abs() < 1e-9,
            "from 3.85 to 4.15: {pr:?}"
        );
        let rp = b.resonance_post.unwrap();
        assert!((rp.omega - 9.0).abs() < 1e-9);
        assert!((rp.uncertainty - 0.05).abs() < 1e-9);
    }

    #[test]
    fn down_sweeps_and_missing_regimes() {
        let omega = [9.0, 8.0, 7.0, 6.0, 5.0];
        let l = [Post, Post, Res, Res, Pre];
        let b = find_boundaries(&omega, &l, &l, 3);
        assert!((b.resonance_post.unwrap().omega - 7.5).abs() < 1e-12);
        assert!((b.pre_resonance.unwrap().omega - 5.5).abs() < 1e-12);
        let none = find_boundaries(&omega, &[Pre; 5], &[Pre; 5], 3);
        assert_eq!(none, Boundaries::default());
    }
}
