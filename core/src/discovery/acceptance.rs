//! The rule that decides whether the data demand a candidate, and which one.
//!
//! The evidence is a paired test on held-out **units** long enough to be independent: at
//! force level blocks of consecutive held-out samples at least twice the derivative filter's
//! window ([`super::blocks`]), at trajectory level whole held-out cycles. At force level the
//! test is [`block_gain_z`]: the held-out gain of squared residuals over its noise-only spread
//! estimated from block sums, read through Student's t ([`t_as_z`]); the spread of the blocks'
//! own gains would count a real gain that varies across the record as noise (an effect near
//! resonance gains in a few cycles only). At trajectory level `dᵦ = ln(m₀ᵦ / m₁ᵦ)`, `m` a
//! cycle's mean squared residual, and `z = mean(d) / (sd(d)/√N)` ([`mean_z`]). N — the blocks
//! or cycles the test is over — is its **effective sample size**,
//! stated with every score. Pairing samples instead counted one stretch of correlated misfit
//! many times: a 1 % fall of the held-out force RMS scored z = 20.9 over 37 500 samples. Under
//! "nothing is missing" the candidate's extra parameters only fit training noise, which the
//! held-out noise does not share, so `z` is of order 1 or negative; a real effect makes it
//! large. A candidate is **significant** when
//!
//! 1. its fit ran, and its held-out gain has `z > min_gain_sigma` (default 3), and
//! 2. its BIC on the training samples is below the current model's by more than
//!    `min_bic_drop` (default 10, "very strong" on Kass and Raftery's scale), and
//! 3. it removes at least `min_explained` (default 0.1) of the current model's held-out excess
//!    over the noise floor, `(MSE_current − MSE_candidate) / (MSE_current − σ²)`, σ the floor
//!    of the current model (force level: the sensor's noise with the kinematics' noise
//!    propagated through the model) and the excess counted as at least what the held-out
//!    units resolve (`choice::excess`): a real but small gain — a flexible candidate
//!    bending to follow the derivative filter's bias — is not the missing physics.
//!
//! Among significant candidates, the one with the lowest held-out RMS is the best; those it
//! beats only within the paired test's resolution — its held-out gain over them within one
//! standard error, `z ≤` [`TIE_SIGMA`] — explain the data equally well. (Not `z ≤
//! min_gain_sigma`: a gain of one to three standard errors is not proven at 3σ, but neither is
//! it a tie — `yield` 10 % below `cubic_stiffness` held out on a damper was called a tie and
//! the cubic spring taken as the simpler.) Of these ties, the simplest is accepted — the fewest parameters, then the lowest BIC
//! — and the others are reported: the held-out evidence does not pay for the extra
//! parameters, even when they lower the training BIC (a power law with n = 1.02 hidden on a
//! yield base: on-off jamming, with four parameters, had a BIC 27 below the viscous damper's
//! on the training cycles and the same held-out RMS). Nothing significant ends the search.

use super::blocks::Blocks;
use super::score::CandidateScore;
use super::settings::DiscoverySettings;

/// The most standard errors of the paired test by which the best candidate's held-out gain
/// over another may exceed zero for the two to be a tie: the test's resolution.
pub const TIE_SIGMA: f64 = 1.0;

/// The paired z of the gain of residuals `new` over `reference` (same samples): mean of
/// `reference² − new²` over its standard error. +∞ for a consistent gain without spread,
/// 0 for no samples or no difference. Only for independent units (blocks, cycles): samples of
/// a residual are not.
pub fn paired_z(reference: &[f64], new: &[f64]) -> f64 {
    let d: Vec<f64> = reference
        .iter()
        .zip(new)
        .map(|(a, b)| a * a - b * b)
        .collect();
    mean_z(&d)
}

/// The mean of `d` and its standard error (`None` for fewer than two values).
pub(super) fn mean_se(d: &[f64]) -> Option<(f64, f64)> {
    let n = d.len();
    if n < 2 {
        return None;
    }
    let mean = d.iter().sum::<f64>() / n as f64;
    let var = d.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64;
    Some((mean, (var / n as f64).sqrt()))
}

/// The z of the mean of paired differences `d`: mean over its standard error. +∞ for a
/// consistent gain without spread, 0 for fewer than two pairs or no difference.
pub fn mean_z(d: &[f64]) -> f64 {
    mean_se(d).map_or(0.0, |(mean, se)| z_of(mean, se))
}

/// `value` over its standard error `se`: +∞ for a positive value without spread, else 0
/// without spread.
fn z_of(value: f64, se: f64) -> f64 {
    if se > 0.0 {
        value / se
    } else if value > 0.0 {
        f64::INFINITY
    } else {
        0.0
    }
}

/// The force-level paired test of the held-out residuals `new` over `reference` (the same
/// held-out samples), with `blocks` as the independent units; the z and the number of blocks.
///
/// The gain is `G = Σᵢ (reference_i² − new_i²)`. With `δ = reference − new` — the difference
/// of the two models' forces, fixed by their training fits — each term is `2·δᵢ·newᵢ + δᵢ²`,
/// and the held-out noise `e` enters only through `2·δᵢ·eᵢ`. Its variance is estimated from
/// the block sums `Uᵦ = Σᵢ∈ᵦ 2·δᵢ·newᵢ` (blocks as long as the noise's correlation, so their
/// sums are independent): `z = G / √(Σᵦ Uᵦ²)`, read through Student's t over the blocks
/// ([`t_as_z`]). The candidate's residual stands for the noise: where it leaves a misfit the
/// estimate only grows, so the test errs towards "not significant". Unlike the spread of the
/// blocks' gains, this does not count the variation of a real gain across the record as noise
/// (an effect near resonance gains in a few cycles only: a wall taking the held-out RMS from
/// 0.087 to 0.037 N scored z = 2.5 by the spread of 46 blocks' mean-square differences).
pub fn block_gain_z(reference: &[f64], new: &[f64], blocks: &Blocks) -> (f64, usize) {
    let (mut gain, mut var) = (0.0, 0.0);
    for &(from, to) in &blocks.ranges {
        let mut u = 0.0;
        for k in from..to.min(reference.len()).min(new.len()) {
            let (a, b) = (reference[k], new[k]);
            gain += a * a - b * b;
            u += 2.0 * (a - b) * b;
        }
        var += u * u;
    }
    let n = blocks.count();
    let z = if gain.is_finite() && var.is_finite() {
        z_of(gain, var.sqrt())
    } else {
        0.0
    };
    (t_as_z(z, n), n)
}

/// A unit holds an excess over the noise floor σ when its mean squared residual is at least
/// this many times σ²: noise alone over a block of tens of samples does not give it (see
/// `choice::excess`).
pub const EXCESS_UNIT: f64 = 2.0;

/// The normal z of the same one-sided tail as Student's `t` over `n` pairs (n − 1 degrees of
/// freedom), by Wallace's approximation `√(ν·ln(1 + t²/ν))·(8ν + 1)/(8ν + 3)` (within 0.1 of
/// the exact z at ν = 2, t = 11.9: 2.62 against 2.70). A few units give a noisy spread: a t
/// of 12 over three is as likely by chance as a z of 2.7. `t` itself with fewer than two
/// pairs or when infinite.
pub fn t_as_z(t: f64, n: usize) -> f64 {
    if n < 2 || !t.is_finite() {
        return t;
    }
    let nu = (n - 1) as f64;
    t.signum() * (nu * (t * t / nu).ln_1p()).sqrt() * (8.0 * nu + 1.0) / (8.0 * nu + 3.0)
}

/// Whether `score` passes the held-out test and the BIC test against the current model,
/// whatever share of the excess it explains.
pub fn passes_tests(score: &CandidateScore, settings: &DiscoverySettings) -> bool {
    score.failure.is_none()
        && score.gain_z > settings.min_gain_sigma
        && score.delta_bic < -settings.min_bic_drop
}

/// Whether `score` passes both tests and explains at least `min_explained` of the current
/// model's held-out excess over the noise floor.
pub fn is_significant(score: &CandidateScore, settings: &DiscoverySettings) -> bool {
    passes_tests(score, settings) && score.explained_share >= settings.min_explained
}

/// The accepted candidate (its index in `scores`: of the ties, the one with the fewest own
/// `params`, then the lowest BIC) and the indices of its ties, from scores
/// whose `significant` flag is set and their per-unit RMS residuals `holdout` (same order;
/// ties by the level's paired test `tie_z` over the units, within [`TIE_SIGMA`]); `None` if
/// none is significant.
pub fn choose(
    scores: &[CandidateScore],
    holdout: &[&[f64]],
    tie_z: &dyn Fn(&[f64], &[f64]) -> f64,
) -> Option<(usize, Vec<usize>)> {
    let best = (0..scores.len())
        .filter(|&i| scores[i].significant)
        .min_by(|&a, &b| scores[a].holdout_rms.total_cmp(&scores[b].holdout_rms))?;
    let tied: Vec<usize> = (0..scores.len())
        .filter(|&i| {
            scores[i].significant && (i == best || tie_z(holdout[i], holdout[best]) <= TIE_SIGMA)
        })
        .collect();
    let &winner = tied.iter().min_by(|&&a, &&b| {
        scores[a]
            .params
            .len()
            .cmp(&scores[b].params.len())
            .then(scores[a].bic.total_cmp(&scores[b].bic))
    })?;
    Some((winner, tied.into_iter().filter(|&i| i != winner).collect()))
}

/// The paired z of the gain of per-cycle RMS residuals `new` over `reference`, on the log
/// scale: `dᵢ = 2·ln(reference_i / new_i)` (the log-ratio of cycle i's mean squared residual),
/// `z = mean(d) / (sd(d)/√N)`. A cycle is the unit: residuals within one are correlated. The
/// log makes cycles of small and large amplitude count alike: an effect that grows with
/// amplitude (a cubic spring) removes most of each cycle's misfit, a different share of
/// different sizes, and a difference of squares would vary so much across cycles that a few
/// held-out cycles could never show it. +∞ for a consistent gain without spread, 0 with fewer
/// than two cycles or no difference.
pub(super) fn cycle_gain_z(reference: &[f64], new: &[f64]) -> f64 {
    let d: Vec<f64> = reference
        .iter()
        .zip(new)
        .map(|(a, b)| 2.0 * (a.max(f64::MIN_POSITIVE) / b.max(f64::MIN_POSITIVE)).ln())
        .collect();
    if d.iter().any(|v| !v.is_finite()) {
        return 0.0;
    }
    mean_z(&d)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn score(
        name: &str,
        holdout_rms: f64,
        gain_z: f64,
        bic: f64,
        delta_bic: f64,
    ) -> CandidateScore {
        CandidateScore {
            name: name.into(),
            holdout_rms,
            train_rms: holdout_rms,
            aic: bic,
            bic,
            delta_aic: delta_bic,
            delta_bic,
            holdout_gain: 0.0,
            gain_z,
            effective_n: 0,
            explained_fraction: 0.0,
            explained_share: 1.0,
            params: vec![],
            significant: false,
            failure: None,
            evaluations: 0,
            wall_seconds: 0.0,
        }
    }

    /// Seeded Gaussian noise of σ = 1.
    fn noise(n: usize, seed: u64) -> Vec<f64> {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        (0..n).map(|_| StandardNormal.sample(&mut rng)).collect()
    }

    #[test]
    fn paired_z_sees_a_consistent_small_gain_and_not_a_shuffle() {
        let e = noise(1000, 1);
        // A gain of 1 % of the noise everywhere.
        let worse: Vec<f64> = e.iter().map(|v| v * 1.01).collect();
        assert!(paired_z(&worse, &e) > 10.0);
        assert!(paired_z(&e, &worse) < -10.0);
        assert_eq!(paired_z(&e, &e), 0.0);
        // Two unrelated noises of the same size: no evidence either way.
        let f = noise(1000, 2);
        assert!(paired_z(&e, &f).abs() < 3.0, "{}", paired_z(&e, &f));
        assert_eq!(paired_z(&[1.0], &[0.0]), 0.0);
    }

    #[test]
    fn both_tests_must_pass_and_ties_go_to_the_lower_bic() {
        let s = DiscoverySettings::default();
        let e = noise(500, 3);
        let scale = |k: f64| e.iter().map(|v| v * k).collect::<Vec<f64>>();
        let (ra, rb, rc, rd, re) = (scale(1.0), scale(1.0), scale(1.5), scale(0.9), scale(2.0));
        let mut scores = vec![
            score("a", 1.0, 20.0, -500.0, -300.0),
            score("b", 1.0, 20.0, -520.0, -320.0),
            score("c", 1.5, 10.0, -400.0, -200.0),
            score("d", 0.9, 25.0, -100.0, -5.0), // BIC test fails
            score("e", 2.0, 2.0, -600.0, -50.0), // held-out gain not significant
        ];
        for sc in &mut scores {
            sc.significant = is_significant(sc, &s);
        }
        let flags: Vec<bool> = scores.iter().map(|s| s.significant).collect();
        assert_eq!(flags, [true, true, true, false, false]);
        let holdout: Vec<&[f64]> = vec![&ra, &rb, &rc, &rd, &re];
        let (winner, ties) = choose(&scores, &holdout, &paired_z).unwrap();
        assert_eq!(scores[winner].name, "b");
        assert_eq!(ties, [0]);
        scores.iter_mut().for_each(|s| s.significant = false);
        assert!(choose(&scores, &holdout, &paired_z).is_none());
    }

    #[test]
    fn of_ties_the_fewest_parameters_win_before_the_lower_bic() {
        let s = DiscoverySettings::default();
        let e = noise(500, 4);
        let param = |name: &str| crate::fit::FittedParam::free(name, 1.0, 0.1);
        // Same held-out residuals: a tie. The four-parameter one has the lower BIC.
        let mut four = score("four", 1.0, 20.0, -540.0, -340.0);
        four.params = ["a", "b", "c", "d"].map(param).to_vec();
        let mut one = score("one", 1.0, 20.0, -520.0, -320.0);
        one.params = vec![param("c")];
        let mut scores = vec![four, one];
        for sc in &mut scores {
            sc.significant = is_significant(sc, &s);
        }
        let (winner, ties) = choose(&scores, &[&e, &e], &paired_z).unwrap();
        assert_eq!(scores[winner].name, "one");
        assert_eq!(ties, [0]);
        // A clear held-out gain is not a tie: the better one wins whatever its size.
        let better: Vec<f64> = e.iter().map(|v| v * 0.8).collect();
        scores[0].holdout_rms = 0.8;
        let (winner, ties) = choose(&scores, &[&better, &e], &paired_z).unwrap();
        assert_eq!(scores[winner].name, "four");
        assert!(ties.is_empty());
    }

    /// Held-out units where the best's squared residual is below another's by `gain` on
    /// average, scattered ±0.425 (20 units): z ≈ gain / 0.098.
    fn paired_units(gain: f64) -> (Vec<f64>, Vec<f64>) {
        let other = vec![1.0; 20];
        let best = (0..20)
            .map(|i| (1.0 - gain + if i % 2 == 0 { 0.425 } else { -0.425 }).sqrt())
            .collect();
        (other, best)
    }

    /// A tie only within the paired test's resolution: a best candidate 10 % lower held out
    /// (z ≈ 1.9: not proven at 3σ) wins; one 0.5 % lower (z ≈ 0.1) ties, and the simpler is
    /// taken.
    #[test]
    fn a_tie_is_a_gain_within_one_standard_error_and_a_clear_winner_is_not_a_tie() {
        for (gain, tie) in [(0.19, false), (0.01, true)] {
            let (other, best) = paired_units(gain);
            let z = paired_z(&other, &best);
            assert!(if tie { z < 0.5 } else { z > 1.5 && z < 3.0 }, "z {z}");
            let rms = |r: &[f64]| (r.iter().map(|v| v * v).sum::<f64>() / r.len() as f64).sqrt();
            let mut scores = vec![
                score("simple", rms(&other), 20.0, -520.0, -320.0),
                score("rich", rms(&best), 20.0, -540.0, -340.0),
            ];
            let param = |name: &str| crate::fit::FittedParam::free(name, 1.0, 0.1);
            scores[0].params = vec![param("a")];
            scores[1].params = vec![param("a"), param("b")];
            for sc in &mut scores {
                sc.significant = true;
            }
            let (winner, ties) = choose(&scores, &[&other, &best], &paired_z).unwrap();
            if tie {
                assert_eq!((scores[winner].name.as_str(), ties), ("simple", vec![1]));
            } else {
                assert_eq!((scores[winner].name.as_str(), ties), ("rich", vec![]));
            }
        }
    }

    #[test]
    fn a_real_gain_that_explains_too_little_is_not_significant() {
        let s = DiscoverySettings::default();
        let mut sc = score("a", 1.0, 20.0, -500.0, -300.0);
        sc.explained_share = 0.05;
        assert!(passes_tests(&sc, &s) && !is_significant(&sc, &s));
        sc.explained_share = 0.5;
        assert!(is_significant(&sc, &s));
    }

    #[test]
    fn the_block_test_sees_a_gain_in_a_few_blocks_and_not_a_refit_of_noise() {
        let e = noise(2000, 5);
        let split = crate::discovery::HoldoutSplit {
            train: Vec::new(),
            holdout: (0..2000).collect(),
            holdout_cycles: 1,
        };
        let blocks = Blocks::new(&split, 40);
        // A misfit of 3σ in 4 of 50 blocks, removed by the candidate.
        let reference: Vec<f64> = (0..2000)
            .map(|i| e[i] + if (i / 40) % 12 == 0 { 3.0 } else { 0.0 })
            .collect();
        let (z, n) = block_gain_z(&reference, &e, &blocks);
        assert_eq!(n, 50);
        assert!(z > 10.0, "{z}");
        // A candidate that fits a little noise: a small smooth force, no gain.
        let overfit: Vec<f64> = (0..2000)
            .map(|i| e[i] - 0.05 * (i as f64 / 300.0).sin())
            .collect();
        let (z, _) = block_gain_z(&e, &overfit, &blocks);
        assert!(z < 1.0, "{z}");
    }

    #[test]
    fn blocks_keep_z_of_order_one_where_samples_overstate_it() {
        // Noise correlated over 20 samples (a moving sum, as a derivative filter leaves) and
        // two models equally far from the truth, on either side: no gain in expectation.
        let split = crate::discovery::HoldoutSplit {
            train: Vec::new(),
            holdout: (0..2000).collect(),
            holdout_cycles: 1,
        };
        let blocks = Blocks::new(&split, 40);
        let g: Vec<f64> = (0..2000).map(|i| 0.05 * (i as f64 / 25.0).sin()).collect();
        let (mut by_blocks, mut by_samples) = (Vec::new(), Vec::new());
        for seed in 0..200 {
            let w = noise(2020, 100 + seed);
            let e: Vec<f64> = (0..2000)
                .map(|i| w[i..i + 20].iter().sum::<f64>() / 20f64.sqrt())
                .collect();
            let r0: Vec<f64> = e.iter().zip(&g).map(|(e, g)| e + g).collect();
            let r1: Vec<f64> = e.iter().zip(&g).map(|(e, g)| e - g).collect();
            by_blocks.push(block_gain_z(&r0, &r1, &blocks).0);
            by_samples.push(paired_z(&r0, &r1));
        }
        let sd = |z: &[f64]| (z.iter().map(|v| v * v).sum::<f64>() / z.len() as f64).sqrt();
        assert!((0.7..1.4).contains(&sd(&by_blocks)), "{}", sd(&by_blocks));
        assert!(sd(&by_samples) > 2.5, "{}", sd(&by_samples));
        let false_alarms = by_blocks.iter().filter(|&&z| z > 3.0).count();
        assert!(false_alarms <= 2, "{false_alarms} of 200");
    }

    #[test]
    fn a_t_over_few_pairs_is_a_smaller_z() {
        // Exact: P(t₂ > 11.9) = 0.0035, z 2.70; many pairs: t and z agree.
        assert!((t_as_z(11.9, 3) - 2.70).abs() < 0.1, "{}", t_as_z(11.9, 3));
        assert!((t_as_z(3.0, 1000) - 3.0).abs() < 0.02);
        assert_eq!(t_as_z(-2.0, 1000).signum(), -1.0);
    }

    #[test]
    fn a_failed_fit_is_never_significant() {
        let s = DiscoverySettings::default();
        let mut sc = score("a", 0.01, 100.0, -1e3, -1e3);
        sc.failure = Some("diverged".into());
        assert!(!is_significant(&sc, &s));
    }

    #[test]
    fn the_cycle_gain_counts_ratios_not_differences() {
        // Cycles of very different size, each halved: a perfectly consistent gain.
        assert_eq!(
            cycle_gain_z(&[1.0, 10.0, 0.1], &[0.5, 5.0, 0.05]),
            f64::INFINITY
        );
        // Better on some, worse on others: no evidence.
        let z = cycle_gain_z(&[1.0, 1.0, 1.0, 1.0], &[0.9, 1.1, 0.95, 1.05]);
        assert!(z.abs() < 1.0, "{z}");
        assert_eq!(cycle_gain_z(&[1.0], &[0.1]), 0.0);
    }
}
