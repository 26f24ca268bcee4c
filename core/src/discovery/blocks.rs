//! The units of the force-level paired test: blocks of consecutive held-out samples, each at
//! least as long as the residual's correlation, so that blocks, not samples, are independent.
//!
//! A force residual is correlated from sample to sample: v and a come from a sliding
//! polynomial filter, whose noise is correlated over its window, and a model that misses
//! something leaves a misfit that spans part of a cycle. A paired test over samples counts
//! one stretch of misfit many times and overstates the evidence (a 1 % fall of the held-out
//! RMS scored z = 20.9 over the samples of a 150 s record at 1 kHz, where the filter's window
//! is 121 samples). Pairing whole cycles instead (as at trajectory level) is right but weak
//! where an effect acts in a few cycles only (a cubic spring near resonance: 3–5 of 16).
//! Blocks sit between: their length ([`block_length`]) is twice the derivative filter's
//! window when it is known — filtered noise is uncorrelated beyond one window, so sums over
//! neighbouring blocks of two windows share at most a quarter of their filtered noise — and
//! otherwise twice the lag at which the current residual's autocorrelation first falls below
//! [`DECORRELATED`]. Each held-out cycle is cut into whole blocks, the remainder joined to its
//! last block; a cycle shorter than the length is one block. The number of blocks is the
//! test's effective sample size.

use super::holdout::{rms_in, runs, HoldoutSplit};

/// The autocorrelation below which residuals a lag apart count as uncorrelated.
pub const DECORRELATED: f64 = 0.1;

/// Blocks of held-out samples: ranges of positions in the held-out samples (`split.holdout`),
/// so a residual taken at the held-out samples is cut by them directly.
#[derive(Clone, Debug, PartialEq)]
pub struct Blocks {
    /// The target length, samples.
    pub length: usize,
    /// Each block's first position and one past its last.
    pub ranges: Vec<(usize, usize)>,
}

/// The length of the test's blocks, samples: twice the filter `window` when known, else twice
/// the first lag at which the autocorrelation of `residual` over the held-out cycles of
/// `split` falls below [`DECORRELATED`] (pairs within one cycle only); at least 1.
pub fn block_length(residual: &[f64], split: &HoldoutSplit, window: Option<usize>) -> usize {
    if let Some(w) = window {
        return (2 * w).max(1);
    }
    let cycles: Vec<(usize, usize)> = runs(&split.holdout).into_iter().map(|r| r.0).collect();
    let longest = cycles.iter().map(|c| c.1 - c.0).max().unwrap_or(0);
    let at = |i: usize| residual.get(i).copied().unwrap_or(0.0);
    let (sum, n) = cycles.iter().fold((0.0, 0usize), |(s, n), c| {
        ((c.0..c.1).map(at).sum::<f64>() + s, n + c.1 - c.0)
    });
    let mean = sum / n.max(1) as f64;
    let cov = |lag: usize| -> f64 {
        let (mut s, mut m) = (0.0, 0usize);
        for c in &cycles {
            for i in c.0..c.1.saturating_sub(lag) {
                s += (at(i) - mean) * (at(i + lag) - mean);
                m += 1;
            }
        }
        if m == 0 {
            0.0
        } else {
            s / m as f64
        }
    };
    let var = cov(0);
    if !(var > 0.0 && var.is_finite()) {
        return 1;
    }
    let lag = (1..longest / 2)
        .find(|&k| cov(k) / var < DECORRELATED)
        .unwrap_or(longest / 2);
    (2 * lag).max(1)
}

impl Blocks {
    /// The held-out cycles of `split` cut into blocks of `length` samples (see the module).
    pub fn new(split: &HoldoutSplit, length: usize) -> Self {
        let length = length.max(1);
        let mut ranges = Vec::new();
        for (_, (start, end)) in runs(&split.holdout) {
            let whole = ((end - start) / length).max(1);
            for b in 0..whole {
                let from = start + b * length;
                let to = if b + 1 == whole { end } else { from + length };
                ranges.push((from, to));
            }
        }
        Blocks { length, ranges }
    }

    /// The RMS of `r` (a residual at the held-out samples) over each block.
    pub fn rms(&self, r: &[f64]) -> Vec<f64> {
        self.ranges
            .iter()
            .map(|&(from, to)| rms_in(r, from, to))
            .collect()
    }

    /// The number of blocks: the effective sample size of the test.
    pub fn count(&self) -> usize {
        self.ranges.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn split(holdout: Vec<usize>) -> HoldoutSplit {
        HoldoutSplit {
            train: Vec::new(),
            holdout,
            holdout_cycles: 0,
        }
    }

    #[test]
    fn cycles_are_cut_into_whole_blocks_the_remainder_joined_to_the_last() {
        let s = split((10..35).chain(60..65).collect());
        let b = Blocks::new(&s, 10);
        assert_eq!(b.ranges, [(0, 10), (10, 25), (25, 30)]);
        assert_eq!(b.count(), 3);
        let r: Vec<f64> = (0..30).map(|i| if i < 10 { 2.0 } else { 1.0 }).collect();
        assert_eq!(b.rms(&r), [2.0, 1.0, 1.0]);
    }

    #[test]
    fn the_length_is_twice_the_window_or_twice_the_correlation() {
        let s = split((0..400).chain(800..1200).collect());
        assert_eq!(block_length(&[], &s, Some(19)), 38);
        // White noise: uncorrelated at lag 1.
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let white: Vec<f64> = (0..1200).map(|_| StandardNormal.sample(&mut rng)).collect();
        assert!(
            block_length(&white, &s, None) <= 4,
            "{}",
            block_length(&white, &s, None)
        );
        // A moving sum over 20 samples of it: correlated over 20 lags (1 − k/20 > 0.1 for
        // k < 18).
        let smooth: Vec<f64> = (0..1200)
            .map(|i: usize| white[i.saturating_sub(19)..=i].iter().sum())
            .collect();
        let l = block_length(&smooth, &s, None);
        assert!((30..=40).contains(&l), "{l}");
    }
}
