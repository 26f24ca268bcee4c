//! The source study's behavioural definitions of its regimes, as boundaries along a sweep.
//!
//! Each cycle's force behaves one of three ways ([`Behaviour`]), read from its features with the
//! thresholds of [`RegimeThresholds`]:
//!
//! - **negligible**: the peak of the lightly smoothed force ([`CycleFeatures::f_peak_smooth`])
//!   is at most max(`negligible_force` (0.2 N), `negligible_k`·σ) — the study's pre-resonance,
//!   "F_STF remains close to zero (≤ 0.2 N)";
//! - **on**: not negligible, and on for at least `resonance_duty` (½) of the cycle — a damper,
//!   the study's resonance;
//! - **on–off**: not negligible, and zero (|F| at or below the on-threshold) for more than
//!   1 − `resonance_duty` of the cycle, between its pulses — the study's post-resonance.
//!
//! The cycles are taken in sweep order (ω rising, or falling for a down-sweep), and each
//! behaviour is smoothed by a median filter over `smoothing_cycles` cycles so single noisy cycles
//! do not move a boundary. Then:
//!
//! 1. **pre → resonance** ([`BoundaryRule::ForceOnset`]) at the first cycle whose smoothed force
//!    is not negligible;
//! 2. **resonance → post**, searched after the first smoothed *on* cycle that follows: at the
//!    first cycle after it that is no longer on — [`BoundaryRule::OnOff`] when the cycles there
//!    are mostly on–off, [`BoundaryRule::ForceGone`] when the force has fallen back to
//!    negligible. A force that is on–off from its onset and never on for most of a cycle (impact
//!    spikes, no damping regime) puts this boundary at the onset too
//!    ([`BoundaryRule::OnOffFromOnset`]): the resonance has no cycles. A force that stays on to
//!    the end of the record has no post-resonance.
//!
//! Cycles before the first boundary are pre-resonance, between the two resonance, after the
//! second post-resonance. A boundary's ω is the mean ω of the two cycles on either side; its
//! uncertainty is half the ω span of the zone where the unsmoothed behaviours mix the two sides,
//! looked for within `smoothing_cycles` (at least 3) cycles of the change, and at least the two
//! cycles of the change itself (as in [`super::boundaries`]).

use super::boundaries::{boundary_at, Boundaries, Boundary, BoundaryRule};
use super::features::CycleFeatures;
use super::median::median_filter;
use super::regime::Regime;
use super::thresholds::RegimeThresholds;

/// What a cycle's force does; see the [module doc](self).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Behaviour {
    /// Peak at or below the negligible level.
    Negligible,
    /// On for at least `resonance_duty` of the cycle.
    On,
    /// Zero for more than 1 − `resonance_duty` of the cycle.
    OnOff,
}

/// The behaviour of a cycle with `features`, given the negligible level (N).
pub fn behaviour(f: &CycleFeatures, th: &RegimeThresholds, negligible_level: f64) -> Behaviour {
    if f.f_peak_smooth <= negligible_level {
        Behaviour::Negligible
    } else if f.duty >= th.resonance_duty {
        Behaviour::On
    } else {
        Behaviour::OnOff
    }
}

/// Labels (unsmoothed, smoothed) and boundaries of cycles by the study's definitions.
pub struct Placed {
    /// Each cycle's label from its own behaviour and the side of the boundaries it lies on.
    pub raw: Vec<Regime>,
    /// The labels the boundaries give.
    pub labels: Vec<Regime>,
    /// The boundaries.
    pub boundaries: Boundaries,
}

/// Positions (in sweep order) of the two changes and the rule of the second.
fn changes(beh: &[Behaviour], window: usize) -> (Option<usize>, Option<(usize, BoundaryRule)>) {
    let forced: Vec<bool> = beh.iter().map(|&b| b != Behaviour::Negligible).collect();
    let on: Vec<bool> = beh.iter().map(|&b| b == Behaviour::On).collect();
    let (forced_s, on_s) = (median_filter(&forced, window), median_filter(&on, window));
    let Some(b1) = forced_s.iter().position(|&f| f) else {
        return (None, None);
    };
    let n = beh.len();
    let Some(first_on) = (b1..n).find(|&i| on_s[i]) else {
        return (Some(b1), Some((b1, BoundaryRule::OnOffFromOnset)));
    };
    let Some(b2) = (first_on..n).find(|&i| !on_s[i]) else {
        return (Some(b1), None);
    };
    let tail = &beh[b2..(b2 + window.max(1)).min(n)];
    let gone = tail.iter().filter(|&&b| b == Behaviour::Negligible).count();
    let rule = if 2 * gone > tail.len() {
        BoundaryRule::ForceGone
    } else {
        BoundaryRule::OnOff
    };
    (Some(b1), Some((b2, rule)))
}

/// Place the boundaries of cycles with `features` by the study's definitions (see the
/// [module doc](self)), given the negligible level (N).
pub fn place(features: &[CycleFeatures], th: &RegimeThresholds, negligible_level: f64) -> Placed {
    let n = features.len();
    let down = n > 1 && features[n - 1].omega < features[0].omega;
    let order: Vec<usize> = if down {
        (0..n).rev().collect()
    } else {
        (0..n).collect()
    };
    let beh: Vec<Behaviour> = order
        .iter()
        .map(|&i| behaviour(&features[i], th, negligible_level))
        .collect();
    let omega: Vec<f64> = order.iter().map(|&i| features[i].omega).collect();
    let w = th.smoothing_cycles;
    let (c1, c2) = changes(&beh, w);
    let (p1, p2) = (c1.unwrap_or(n), c2.map_or(n, |c| c.0));
    let b1 = c1.filter(|&j| j > 0);
    let b2 = c2.filter(|&(j, _)| j > 0);
    let forced: Vec<bool> = beh.iter().map(|&b| b != Behaviour::Negligible).collect();
    let not_on: Vec<bool> = beh.iter().map(|&b| b != Behaviour::On).collect();
    // The boundary between sweep positions j − 1 and j; its `cycle` is the index of the cycle
    // at position j.
    let at = |j: usize, rule, side: &[bool]| Boundary {
        cycle: order[j],
        ..boundary_at(&omega, j, w, rule, |i| side[i], |i| !side[i])
    };
    let boundaries = Boundaries {
        pre_resonance: b1.map(|j| at(j, BoundaryRule::ForceOnset, &forced)),
        resonance_post: b2.map(|(j, rule)| {
            let on_off_from_onset = rule == BoundaryRule::OnOffFromOnset;
            at(j, rule, if on_off_from_onset { &forced } else { &not_on })
        }),
    };
    let mut labels = vec![Regime::PreResonance; n];
    let mut raw = vec![Regime::PreResonance; n];
    for (pos, &i) in order.iter().enumerate() {
        labels[i] = if pos < p1 {
            Regime::PreResonance
        } else if pos < p2 {
            Regime::Resonance
        } else {
            Regime::PostResonance
        };
        raw[i] = match (beh[pos], labels[i]) {
            (Behaviour::Negligible, Regime::PreResonance) => Regime::PreResonance,
            (Behaviour::Negligible, _) | (Behaviour::OnOff, Regime::PostResonance) => {
                Regime::PostResonance
            }
            _ => Regime::Resonance,
        };
    }
    Placed {
        raw,
        labels,
        boundaries,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Regime::{PostResonance as Post, PreResonance as Pre, Resonance as Res};

    /// Cycles on ω 3, 3.1, … with the given (smoothed peak, duty).
    fn sweep(cycles: &[(f64, f64)]) -> Vec<CycleFeatures> {
        cycles
            .iter()
            .enumerate()
            .map(|(i, &(peak, duty))| CycleFeatures {
                t_mid: i as f64,
                omega: 3.0 + 0.1 * i as f64,
                amplitude: 0.01,
                f_peak: peak,
                f_rms: peak / 2.0,
                duty,
                energy: 0.0,
                energy_ratio: 0.0,
                corr_x: 0.0,
                corr_v: 0.0,
                corr_a: 0.0,
                f_peak_smooth: peak,
                c_eq: 0.0,
                phase_x: f64::NAN,
                phase_v: f64::NAN,
            })
            .collect()
    }

    const NEG: (f64, f64) = (0.1, 0.0);
    const ON: (f64, f64) = (1.0, 0.8);
    const SPIKES: (f64, f64) = (1.0, 0.2);

    fn run(cycles: &[(f64, f64)]) -> Placed {
        place(&sweep(cycles), &RegimeThresholds::default(), 0.2)
    }

    #[test]
    fn onset_then_on_off_with_a_noisy_cycle_near_each_change() {
        // A lone on cycle before the onset's run and a lone on cycle among the first spikes: the
        // median over 5 cycles places each change after them, and the raw mix spans both cycles
        // of the change.
        let mut c = vec![NEG; 6];
        c.extend([
            ON, NEG, ON, ON, ON, ON, SPIKES, ON, SPIKES, SPIKES, SPIKES, SPIKES,
        ]);
        let p = run(&c);
        let b1 = p.boundaries.pre_resonance.unwrap();
        assert_eq!((b1.cycle, b1.rule), (7, BoundaryRule::ForceOnset));
        assert!((b1.omega - 3.65).abs() < 1e-9);
        assert!((b1.uncertainty - 0.05).abs() < 1e-9, "{b1:?}");
        let b2 = p.boundaries.resonance_post.unwrap();
        assert_eq!((b2.cycle, b2.rule), (13, BoundaryRule::OnOff));
        assert!((b2.omega - 4.25).abs() < 1e-9);
        assert!((b2.uncertainty - 0.05).abs() < 1e-9, "{b2:?}");
        assert_eq!(p.labels[6], Pre);
        assert_eq!(p.labels[7], Res);
        assert_eq!(p.labels[12], Res);
        assert_eq!(p.labels[13], Post);
        // The raw label of a lone on cycle among spikes is resonance.
        assert_eq!(p.raw[13], Res);
        assert_eq!(p.raw[14], Post);
    }

    #[test]
    fn pulses_before_the_damper_stay_in_the_resonance_and_a_force_that_goes_is_post() {
        let mut c = vec![NEG; 5];
        c.extend([SPIKES; 4]);
        c.extend([ON; 6]);
        c.extend([NEG; 5]);
        let p = run(&c);
        assert_eq!(p.boundaries.pre_resonance.unwrap().cycle, 5);
        let b2 = p.boundaries.resonance_post.unwrap();
        assert_eq!((b2.cycle, b2.rule), (15, BoundaryRule::ForceGone));
        assert!(p.labels[5..15].iter().all(|&l| l == Res));
    }

    #[test]
    fn spikes_from_the_onset_a_force_that_stays_on_and_a_down_sweep() {
        let mut c = vec![NEG; 5];
        c.extend([SPIKES; 8]);
        let p = run(&c);
        let (b1, b2) = (
            p.boundaries.pre_resonance.unwrap(),
            p.boundaries.resonance_post.unwrap(),
        );
        assert_eq!(b1.omega, b2.omega);
        assert_eq!(b2.rule, BoundaryRule::OnOffFromOnset);
        assert_eq!(p.count_res(), 0);
        let mut c = vec![NEG; 5];
        c.extend([ON; 8]);
        assert!(run(&c).boundaries.resonance_post.is_none());
        // The same sweep run downwards: ω falls along the record, the onset is read from its end.
        let mut f = sweep(&c);
        f.reverse();
        let p = place(&f, &RegimeThresholds::default(), 0.2);
        let b1 = p.boundaries.pre_resonance.unwrap();
        assert!((b1.omega - 3.45).abs() < 1e-9);
        assert_eq!(b1.cycle, 7);
        assert_eq!(p.labels[7], Res);
        assert_eq!(p.labels[8], Pre);
    }

    impl Placed {
        fn count_res(&self) -> usize {
            self.labels.iter().filter(|&&l| l == Res).count()
        }
    }
}
