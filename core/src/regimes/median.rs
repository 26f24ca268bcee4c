//! The median filter that smooths per-cycle labels (regimes, on/off flags) before a boundary is
//! placed: a lone flipped cycle inside a run is taken back, a change that lasts stays.

/// Median filter of `labels` (regimes ordered Pre < Resonance < Post, booleans false < true)
/// over `window` cycles (odd); the window shrinks symmetrically at the ends.
pub fn median_filter<T: Copy + Ord>(labels: &[T], window: usize) -> Vec<T> {
    let n = labels.len();
    let h = window / 2;
    (0..n)
        .map(|i| {
            let hi = h.min(i).min(n - 1 - i);
            let mut w = labels[i - hi..=i + hi].to_vec();
            w.sort_unstable();
            w[w.len() / 2]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::regimes::Regime::{
        self, PostResonance as Post, PreResonance as Pre, Resonance as Res,
    };

    #[test]
    fn the_median_filter_removes_single_flips_and_keeps_changes() {
        let l = [
            Pre, Pre, Res, Pre, Pre, Res, Res, Post, Res, Res, Post, Post, Post,
        ];
        let m = median_filter(&l, 3);
        assert_eq!(
            m,
            vec![Pre, Pre, Pre, Pre, Pre, Res, Res, Res, Res, Res, Post, Post, Post]
        );
        assert_eq!(median_filter(&l, 1), l.to_vec());
        assert!(median_filter::<Regime>(&[], 5).is_empty());
    }
}
