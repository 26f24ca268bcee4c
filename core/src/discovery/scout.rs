//! The scout of a long record: a few short pieces of it, spread evenly over its length, each
//! simulated from the measured state at its start.
//!
//! A trajectory fit simulates the whole record at every evaluation, and a candidate's trial
//! (its starts, their short fits, then up to [`super::trajectory_level`]'s iteration limit) costs
//! hundreds of evaluations. On a long record the search for a candidate's values runs on the
//! scout instead — an eighth of the samples and at most a few thousand, so each evaluation
//! costs an eighth or less — and
//! the trial on the whole record continues from where the scout ended, a few
//! Levenberg–Marquardt iterations from its optimum. The scout only chooses which candidates
//! are tried on the whole record and where their fits start: every score, held-out residual
//! and verdict is still the whole record's.
//!
//! A piece starts from the measured state: x and v of a cubic fitted by least squares to
//! the measured x over a quarter cycle either side of its first sample. Not from the current
//! model's simulated state: where the current model lacks an effect that state is off by the
//! very gap sought (3 mm on a trolley that misses a cubic spring), and a candidate that damps
//! the start's transient away faster (any extra damping) would then look best. The first
//! quarter of each piece, where the start's error dies away, is simulated but not fitted.
//! Pieces spread over the record see every part of a sweep, and the piece nearest the cycle
//! of largest swing is centred on it: a few pieces spread evenly can all miss a sweep's
//! resonance, where a stiffening or an amplitude-dependent force shows most (a cubic spring
//! hidden on the paper's sweep lowered the evenly spread scout's mean square by 2e-8 mm²,
//! less than a wall impact fitted to its pieces' small swings, and was never tried on the
//! whole record). The pieces are simulated in parallel: the candidates run in parallel too,
//! but a step's last candidate, or the base's scout, would otherwise leave a core idle.
//!
//! A candidate's search screens its starts and ranks them at the record's tolerance, but
//! their short fits ([`super::trajectory_starts`]) integrate the pieces at [`SCOUT_RTOL`]
//! ([`Scout::searching`]): a short fit only moves a start towards its basin. The scout fit
//! that follows, the candidates' ranking by it and the base's own scout all run at the
//! record's tolerance: near a resonance whose branch a stiffening moves, a fit whose
//! difference steps are sized for a loose tolerance does not find the branch (see
//! [`SCOUT_RTOL`]).

use std::sync::Arc;

use rayon::prelude::*;

use super::trajectory_subset_fit::{Rig, Track};
use crate::physics::force_model::ForceModel;
use crate::regimes::Cycle;

/// Fewest samples for a record to be scouted (see [`Scout::new`]).
pub const SCOUT_FROM: usize = 12_000;

/// Pieces of a scout, at most.
const PIECES: usize = 8;

/// The scout's share of the record: its pieces hold about one sample in this many.
const SHARE: usize = 8;

/// Samples of a scout, at most, unless [`MIN_PIECES`] pieces of [`PIECE_CYCLES`] cycles need
/// more. A search needs cycles enough to tell a handful of parameters apart, not a share of a
/// record: on Silverbox (9 samples a cycle) a scout of 2 300 samples found the same cubic
/// stiffness as the whole record, and a scout that grows with the record makes the search
/// cost grow with it (at one sample in 8, 12 500 samples of a 100 000-sample record).
const MOST: usize = 6_000;

/// Fewest cycles a piece spans.
const PIECE_CYCLES: usize = 6;

/// Fewest pieces for a scout to stand for the record.
const MIN_PIECES: usize = 3;

/// Relative tolerance, at the tightest, of a candidate's short fits from its starts on the
/// scout (a user's looser `rtol` is kept; see [`Scout::searching`]). Measured on the
/// benchmarks (one run each, load about 2): trajectory `added_mass` hidden 17.3 s CPU against
/// 19.0 s with every search at the record's tolerance, the Silverbox layout 272 s against
/// 326 s, the same verdicts and gaps. With the scout fit at 1e-5 as well the Silverbox layout
/// took 178 s of CPU at idle, but on the paper's sweep with a weak cubic spring hidden
/// (`tests/discover_rotor_trajectory.rs`, its ignored case) the cubic spring's scout fit
/// missed the resonance's other branch (it lowered the scout's mean square by 3.4e-7 mm²
/// against 1.5e-3 mm² at 1e-7) and discovery named `wall_impact`.
pub const SCOUT_RTOL: f64 = 1e-5;

/// Short pieces of a record, each a rig of its own, that stand in for it while a candidate's
/// values are searched for.
pub(super) struct Scout<'a> {
    /// The pieces, each simulated from the measured state at its start.
    pub pieces: Vec<Rig<'a>>,
    /// Positions, in the pieces' joined residual, of the samples that train: training samples
    /// of the record past each piece's first quarter.
    pub train: Vec<usize>,
    /// Samples of the record the pieces hold.
    pub samples: usize,
}

impl<'a> Scout<'a> {
    /// The scout of `rig`'s record, or `None` when the record is too short for pieces of
    /// [`PIECE_CYCLES`] of `cycles` to make a scout of at least [`MIN_PIECES`] at one sample
    /// in [`SHARE`]. It holds one sample in [`SHARE`], at most [`MOST`] unless its fewest
    /// pieces need more. `train` are the record's training samples (increasing).
    pub fn new(rig: &Rig<'a>, cycles: &[Cycle], train: &[usize]) -> Option<Self> {
        let n = rig.t.len();
        let mut lengths: Vec<usize> = cycles.iter().map(|c| c.end - c.start).collect();
        lengths.sort_unstable();
        let cycle = lengths.get(lengths.len() / 2).copied().unwrap_or(n);
        let total = MOST.max(MIN_PIECES * PIECE_CYCLES * cycle).min(n / SHARE);
        let length = (total / PIECES).max(PIECE_CYCLES * cycle);
        let count = (total / length.max(1)).min(PIECES);
        if count < MIN_PIECES || rig.x.len() != n {
            return None;
        }
        let half = (cycle / 4).max(2);
        let mut is_train = vec![false; n];
        for &i in train {
            if let Some(slot) = is_train.get_mut(i) {
                *slot = true;
            }
        }
        let mut pieces = Vec::with_capacity(count);
        let mut positions = Vec::new();
        let mut joined = 0;
        for centre in centres(n, count, widest_swing(rig.x, cycles)) {
            let start = centre
                .saturating_sub(length / 2)
                .min(n.saturating_sub(length));
            let end = (start + length).min(n);
            let burn = (end - start) / 4;
            positions.extend(
                (start + burn..end)
                    .filter(|&i| is_train[i])
                    .map(|i| joined + i - start),
            );
            joined += end - start;
            pieces.push(Rig {
                initial: Some(measured_state(rig.t, rig.x, start, half)?),
                fixed_start: true,
                t: &rig.t[start..end],
                x: &rig.x[start..end],
                ..rig.clone()
            });
        }
        Some(Scout {
            pieces,
            train: positions,
            samples: joined,
        })
    }
}

impl<'a> Scout<'a> {
    /// This scout with its pieces integrated to relative tolerance `rtol`.
    pub fn at(&self, rtol: f64) -> Scout<'a> {
        let pieces = self
            .pieces
            .iter()
            .map(|p| {
                let mut piece = p.clone();
                piece.sim.rtol = rtol;
                piece
            })
            .collect();
        Scout {
            pieces,
            train: self.train.clone(),
            samples: self.samples,
        }
    }

    /// The scout a candidate's short fits from its starts run on: its pieces integrated to
    /// [`SCOUT_RTOL`], or the record's own tolerance where that is looser.
    pub fn searching(&self) -> Scout<'a> {
        self.at(self.rtol().max(SCOUT_RTOL))
    }
}

impl Track for Scout<'_> {
    /// The pieces' residuals joined in order (the pieces simulated in parallel; the first
    /// piece's error in order, if any).
    fn residual(&self, model: &Arc<dyn ForceModel>, values: &[f64]) -> Result<Vec<f64>, String> {
        let runs: Vec<Result<Vec<f64>, String>> = self
            .pieces
            .par_iter()
            .map(|piece| piece.residual(model, values))
            .collect();
        let mut out = Vec::with_capacity(self.samples);
        for run in runs {
            out.extend(run?);
        }
        Ok(out)
    }
    fn rtol(&self) -> f64 {
        self.pieces.first().map_or(1e-6, |p| p.sim.rtol)
    }
    fn fixes_start(&self) -> bool {
        true
    }
}

/// The centres of `count` pieces spread evenly over `n` samples, the one nearest `peak` (if
/// any) moved onto it. Pieces are at most an eighth of their spacing long, so the moved one
/// never overlaps its neighbours.
fn centres(n: usize, count: usize, peak: Option<usize>) -> Vec<usize> {
    let mut out: Vec<usize> = (0..count).map(|k| (2 * k + 1) * n / (2 * count)).collect();
    if let Some(peak) = peak {
        if let Some(nearest) = out.iter_mut().min_by_key(|c| c.abs_diff(peak)) {
            *nearest = peak;
        }
    }
    out
}

/// The middle sample of the cycle whose measured x swings widest (peak to peak), if any.
fn widest_swing(x: &[f64], cycles: &[Cycle]) -> Option<usize> {
    let swing = |c: &Cycle| {
        let part = x.get(c.start..c.end.min(x.len()))?;
        let (lo, hi) = part
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        (hi > lo).then_some(hi - lo)
    };
    cycles
        .iter()
        .filter_map(|c| Some((swing(c)?, (c.start + c.end) / 2)))
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, mid)| mid)
}

/// x and v at sample `i` of a cubic fitted by least squares to the measured `x` over `half`
/// samples either side (fewer at the record's ends); `None` if that fit is singular. A cubic,
/// not a quadratic: over a quarter cycle either side a quadratic's slope of a sine is 23 %
/// low, a cubic's within 2 %.
fn measured_state(t: &[f64], x: &[f64], i: usize, half: usize) -> Option<(f64, f64)> {
    let lo = i.saturating_sub(half);
    let hi = (i + half + 1).min(x.len());
    // Normal equations of x ≈ a + b·τ + c·τ² + d·τ³, τ = (t − t_i)/h (scaled for conditioning).
    let h = (t[hi - 1] - t[lo]).abs().max(f64::MIN_POSITIVE);
    let mut m = nalgebra::Matrix4::<f64>::zeros();
    let mut r = nalgebra::Vector4::<f64>::zeros();
    for j in lo..hi {
        let tau = (t[j] - t[i]) / h;
        let basis = nalgebra::Vector4::new(1.0, tau, tau * tau, tau * tau * tau);
        m += basis * basis.transpose();
        r += basis * x[j];
    }
    let coef = m.lu().solve(&r)?;
    let (x0, v0) = (coef[0], coef[1] / h);
    (x0.is_finite() && v0.is_finite()).then_some((x0, v0))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rig over `n` samples of a sine of `per` samples a cycle, and its cycles.
    fn sine_rig(n: usize, per: usize, t: &mut Vec<f64>, x: &mut Vec<f64>) -> Vec<Cycle> {
        *t = (0..n).map(|i| i as f64 / per as f64).collect();
        *x = t
            .iter()
            .map(|&t| (std::f64::consts::TAU * t).sin())
            .collect();
        (0..n / per)
            .map(|k| Cycle {
                start: k * per,
                end: (k + 1) * per,
                t_mid: k as f64 + 0.5,
                omega: std::f64::consts::TAU,
            })
            .collect()
    }

    fn rig<'a>(t: &'a [f64], x: &'a [f64]) -> Rig<'a> {
        let u = crate::numerics::interpolate::Linear::new(t.to_vec(), vec![0.0; t.len()]);
        Rig {
            system: crate::physics::oscillator_params::OscillatorParams::FORCED,
            excitation: Arc::new(crate::physics::excitation::Excitation::Force(u)),
            oscillator: vec![],
            initial: None,
            sim: crate::numerics::integrate::Settings::default(),
            fit_offset: false,
            fixed_start: false,
            t,
            x,
        }
    }

    /// One sample in 8 up to `MOST`; past that the scout stops growing with the record, and
    /// a record of long cycles still gets its fewest pieces of `PIECE_CYCLES` cycles.
    #[test]
    fn the_scout_holds_an_eighth_of_a_record_up_to_a_few_thousand_samples() {
        let (mut t, mut x) = (Vec::new(), Vec::new());
        for (n, per, samples, pieces) in [
            (20_000, 9, 2_496, 8),
            (100_000, 9, 6_000, 8),
            (1_000_000, 9, 6_000, 8),
            (1_000_000, 1_000, 18_000, 3),
        ] {
            let cycles = sine_rig(n, per, &mut t, &mut x);
            let train: Vec<usize> = (0..n).collect();
            let scout = Scout::new(&rig(&t, &x), &cycles, &train).unwrap();
            assert_eq!(
                (scout.samples, scout.pieces.len()),
                (samples, pieces),
                "{n} samples, {per} a cycle"
            );
            assert!(scout.train.iter().all(|&i| i < scout.samples));
        }
        let cycles = sine_rig(100_000, 5_000, &mut t, &mut x);
        let train: Vec<usize> = (0..100_000).collect();
        assert!(Scout::new(&rig(&t, &x), &cycles, &train).is_none());
    }

    /// A sine whose swing peaks at 0.4 of the record (a sweep's resonance), between the evenly
    /// spread pieces' centres (1/6, 3/6, 5/6): one piece is centred on the peak, the others
    /// stay where they were.
    #[test]
    fn a_piece_is_centred_on_the_widest_swing() {
        let (mut t, mut x) = (Vec::new(), Vec::new());
        let n = 200_000;
        let cycles = sine_rig(n, 1_000, &mut t, &mut x);
        let peak = 0.4 * n as f64;
        for (xi, i) in x.iter_mut().zip(0..) {
            let d = (i as f64 - peak) / 15_000.0;
            *xi *= 1.0 + 4.0 * (-d * d).exp();
        }
        let train: Vec<usize> = (0..n).collect();
        let scout = Scout::new(&rig(&t, &x), &cycles, &train).unwrap();
        let middles: Vec<f64> = scout
            .pieces
            .iter()
            .map(|p| 0.5 * (p.t[0] + p.t[p.t.len() - 1]) * 1_000.0 / n as f64)
            .collect();
        assert_eq!(middles.len(), 3);
        assert!((middles[0] - 1.0 / 6.0).abs() < 0.01, "{middles:?}");
        assert!((middles[1] - 0.4).abs() < 0.01, "{middles:?}");
        assert!((middles[2] - 5.0 / 6.0).abs() < 0.01, "{middles:?}");
        assert_eq!(widest_swing(&x, &[]), None);
    }

    #[test]
    fn the_measured_state_is_the_local_cubic_s_value_and_slope() {
        let t: Vec<f64> = (0..40).map(|i| i as f64 * 0.01).collect();
        let x: Vec<f64> = t.iter().map(|&t| 0.3 + 2.0 * t - 4.0 * t * t).collect();
        let (x0, v0) = measured_state(&t, &x, 20, 5).unwrap();
        assert!((x0 - x[20]).abs() < 1e-12);
        assert!((v0 - (2.0 - 8.0 * t[20])).abs() < 1e-9);
        let (_, v_end) = measured_state(&t, &x, 0, 5).unwrap();
        assert!((v_end - 2.0).abs() < 1e-9);
    }

    /// A sine at 9 and at 1000 samples a period, a quarter period either side: the slope
    /// within 2 % of the amplitude's rate.
    #[test]
    fn the_measured_slope_of_a_sine_holds_at_few_and_many_samples_a_period() {
        for per in [9usize, 1000] {
            let w = std::f64::consts::TAU;
            let t: Vec<f64> = (0..5 * per).map(|i| i as f64 / per as f64).collect();
            let x: Vec<f64> = t.iter().map(|&t| (w * t + 0.4).sin()).collect();
            for i in [2 * per, 2 * per + per / 3] {
                let (_, v) = measured_state(&t, &x, i, (per / 4).max(2)).unwrap();
                let truth = w * (w * t[i] + 0.4).cos();
                assert!(
                    (v - truth).abs() < 0.02 * w,
                    "{per} a period: {v} vs {truth}"
                );
            }
        }
    }
}
