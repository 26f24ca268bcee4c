//! Splitting a record into training and held-out samples by whole cycles.
//!
//! Every k-th whole cycle (the k-th, 2k-th, … counting from 1) is held out; all other
//! samples, including the partial cycles at both ends, train. Whole cycles keep the held-out
//! samples independent of the training ones at the scale of the motion: a model cannot score
//! well on them by interpolating between neighbouring samples.
//!
//! Beside the split: the RMS of a residual over a set of samples, over the whole record, and
//! over each run of consecutive held-out samples (each held-out cycle), used by both levels.

use super::error::DiscoveryError;
use crate::regimes::Cycle;

/// Sample indices that train the fits and those held out to score them: together, every
/// sample of the record.
#[derive(Clone, Debug, PartialEq)]
pub struct HoldoutSplit {
    /// Training samples, increasing.
    pub train: Vec<usize>,
    /// Held-out samples, increasing.
    pub holdout: Vec<usize>,
    /// Number of held-out cycles.
    pub holdout_cycles: usize,
}

impl HoldoutSplit {
    /// Hold out every `every`-th of `cycles` in a record of `n` samples.
    pub fn new(n: usize, cycles: &[Cycle], every: usize) -> Result<Self, DiscoveryError> {
        if every < 2 {
            return Err(DiscoveryError::BadSettings(format!(
                "holdout_every must be ≥ 2 (got {every})"
            )));
        }
        let mut held = vec![false; n];
        let mut holdout_cycles = 0;
        for (i, c) in cycles.iter().enumerate() {
            if c.end > n || c.start >= c.end {
                return Err(DiscoveryError::BadData(format!(
                    "cycle {i} spans samples {}..{} of a record of {n}",
                    c.start, c.end
                )));
            }
            if (i + 1) % every == 0 {
                held[c.start..c.end].fill(true);
                holdout_cycles += 1;
            }
        }
        if holdout_cycles == 0 {
            return Err(DiscoveryError::NoHoldout {
                cycles: cycles.len(),
                every,
            });
        }
        let (holdout, train): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| held[i]);
        Ok(HoldoutSplit {
            train,
            holdout,
            holdout_cycles,
        })
    }
}

/// The RMS of `r` over each held-out cycle: `holdout` holds whole cycles of increasing
/// samples, never two neighbouring cycles (one in `holdout_every` ≥ 2 is held out), so each
/// run of consecutive indices is one cycle.
pub(super) fn cycle_rms(r: &[f64], holdout: &[usize]) -> Vec<f64> {
    let cycles = runs(holdout).into_iter();
    cycles.map(|((from, to), _)| rms_in(r, from, to)).collect()
}

/// The runs of consecutive indices of `holdout` (increasing) — its held-out cycles — as
/// ranges of record indices and of positions in `holdout`.
pub(super) fn runs(holdout: &[usize]) -> Vec<((usize, usize), (usize, usize))> {
    let mut out: Vec<((usize, usize), (usize, usize))> = Vec::new();
    for (k, &i) in holdout.iter().enumerate() {
        match out.last_mut() {
            Some((index, at)) if index.1 == i => {
                index.1 = i + 1;
                at.1 = k + 1;
            }
            _ => out.push(((i, i + 1), (k, k + 1))),
        }
    }
    out
}

/// The RMS of `r` over the samples `from..to` (NaN where `r` has no sample).
pub(super) fn rms_in(r: &[f64], from: usize, to: usize) -> f64 {
    rms_of((from..to).map(|i| r.get(i).copied().unwrap_or(f64::NAN))).0
}

/// RMS of `r` over the samples `subset` (0 for an empty subset).
pub(crate) fn rms_over(r: &[f64], subset: &[usize]) -> f64 {
    rms_of(subset.iter().map(|&i| r[i])).0
}

/// RMS of all of `r` (0 when empty).
pub(crate) fn rms(r: &[f64]) -> f64 {
    rms_of(r.iter().copied()).0
}

/// The RMS of `values` and how many there are ((0, 0) when there are none).
pub(crate) fn rms_of(values: impl Iterator<Item = f64>) -> (f64, usize) {
    let (ss, n) = values.fold((0.0, 0usize), |(ss, n), v| (ss + v * v, n + 1));
    if n == 0 {
        (0.0, 0)
    } else {
        ((ss / n as f64).sqrt(), n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cycle(start: usize, end: usize) -> Cycle {
        Cycle {
            start,
            end,
            t_mid: 0.0,
            omega: 1.0,
        }
    }

    #[test]
    fn every_kth_whole_cycle_is_held_out() {
        let cycles: Vec<Cycle> = (0..8).map(|i| cycle(5 + 10 * i, 15 + 10 * i)).collect();
        let s = HoldoutSplit::new(100, &cycles, 4).unwrap();
        assert_eq!(s.holdout_cycles, 2);
        let expected: Vec<usize> = (35..45).chain(75..85).collect();
        assert_eq!(s.holdout, expected);
        assert_eq!(s.train.len() + s.holdout.len(), 100);
        assert!(s.train.contains(&0) && s.train.contains(&99));
    }

    #[test]
    fn too_few_cycles_or_bad_cycles_are_errors() {
        let cycles = [cycle(0, 10), cycle(10, 20)];
        assert!(HoldoutSplit::new(30, &cycles, 4).is_err());
        assert!(HoldoutSplit::new(15, &cycles, 2).is_err());
        assert!(HoldoutSplit::new(30, &cycles, 1).is_err());
    }

    #[test]
    fn held_out_cycles_are_the_runs_of_consecutive_samples() {
        let r = [3.0, 1.0, 1.0, 9.0, 9.0, 2.0, 2.0, 2.0, 4.0];
        let rms = cycle_rms(&r, &[1, 2, 5, 6, 7]);
        assert_eq!(rms, vec![1.0, 2.0]);
        assert_eq!(cycle_rms(&r, &[0, 8]), vec![3.0, 4.0]);
        assert!(cycle_rms(&r, &[]).is_empty());
    }
}
