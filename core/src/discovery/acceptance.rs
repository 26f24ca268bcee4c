//! The rule that decides whether the data demand a candidate, and which one.
//!
//! The evidence is a paired test on held-out **units** long enough to be independent: at
//! force level blocks of consecutive held-out samples at least twice the derivative filter's
//! window ([`super::blocks`]), at trajectory level whole held-out cycles. With `m₀ᵦ` the
//! current model's mean squared residual over unit b and `m₁ᵦ` the candidate's (each fitted on
//! the training cycles only), `dᵦ = ln(m₀ᵦ / m₁ᵦ)` and `z = mean(d) / (sd(d)/√N)`, at force
//! level read as a normal z through Student's t over N − 1 degrees of freedom ([`t_as_z`],
//! [`block_gain_z`]). At force level the test is over every block,
//! or over the blocks where the current model holds an excess over the noise floor
//! ([`excess_gain_z`]) when that gives the larger z: an effect near resonance shows in a few
//! cycles only. N — the blocks or cycles the test is over — is its **effective sample size**,
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
//!    units resolve (see [`super::choice`]): a real but small gain — a flexible candidate
//!    bending to follow the derivative filter's bias — is not the missing physics.
//!
//! Among significant candidates, the one with the lowest held-out RMS is the best; those the
//! best does not beat by the same paired test (`z ≤ min_gain_sigma`) explain the data equally
//! well. Of these ties, the simplest is accepted — the fewest parameters, then the lowest BIC
//! — and the others are reported: the held-out evidence does not pay for the extra
//! parameters, even when they lower the training BIC (a power law with n = 1.02 hidden on a
//! yield base: on-off jamming, with four parameters, had a BIC 27 below the viscous damper's
//! on the training cycles and the same held-out RMS). Nothing significant ends the search.

use super::score::CandidateScore;
use super::settings::DiscoverySettings;

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

/// The z of the mean of paired differences `d`: mean over its standard error. +∞ for a
/// consistent gain without spread, 0 for fewer than two pairs or no difference.
pub fn mean_z(d: &[f64]) -> f64 {
    let n = d.len();
    if n < 2 {
        return 0.0;
    }
    let mean = d.iter().sum::<f64>() / n as f64;
    let var = d.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64;
    let se = (var / n as f64).sqrt();
    if se > 0.0 {
        mean / se
    } else if mean > 0.0 {
        f64::INFINITY
    } else {
        0.0
    }
}

/// The force-level paired test of per-block RMS residuals `new` over `reference`: the
/// log-ratio of each block's mean square, `dᵦ = 2·ln(reference_b / new_b)`, its mean over its
/// standard error read through Student's t ([`t_as_z`]). The log makes blocks of small and
/// large misfit count alike: an effect that grows with amplitude removes most of each
/// block's misfit, a share that differs little between blocks, while the differences of
/// mean squares span orders of magnitude between resonance and the rest (a wall taking the
/// held-out RMS from 0.087 to 0.037 N scored z = 2.5 by differences over 46 blocks). +∞ for a
/// consistent gain without spread, 0 with fewer than two blocks or a non-finite ratio.
pub fn block_gain_z(reference: &[f64], new: &[f64]) -> f64 {
    let d: Vec<f64> = reference
        .iter()
        .zip(new)
        .map(|(a, b)| 2.0 * (a.max(f64::MIN_POSITIVE) / b.max(f64::MIN_POSITIVE)).ln())
        .collect();
    if d.iter().any(|v| !v.is_finite()) {
        return 0.0;
    }
    t_as_z(mean_z(&d), d.len())
}

/// A unit holds an excess over the noise floor σ when its mean squared residual is at least
/// this many times σ²: noise alone over a block of tens of samples does not give it.
pub const EXCESS_UNIT: f64 = 2.0;

/// The paired test `gain_z` of per-unit RMS residuals `new` over `reference`, and the units
/// it is over: the larger of the test over every unit and over the units where `reference`
/// holds an excess over the floor `sigma` ([`EXCESS_UNIT`]; at least two). An effect that
/// lives in a few cycles (a cubic spring or a wall near resonance) removes most of their
/// misfit and nothing elsewhere; over all units the spread of that mixture hides it, over the
/// units that hold the misfit it is consistent. Choosing the units by the reference alone
/// keeps the test fair: under "nothing is missing" a candidate fitted on the training cycles
/// gains on them no more than elsewhere. Taking the larger of two tests at most doubles the
/// chance of a z above the threshold by luck.
pub fn excess_gain_z(
    reference: &[f64],
    new: &[f64],
    gain_z: fn(&[f64], &[f64]) -> f64,
    sigma: f64,
) -> (f64, usize) {
    let all = (gain_z(reference, new), reference.len());
    let bar = EXCESS_UNIT * sigma * sigma;
    let (r, n): (Vec<f64>, Vec<f64>) = reference
        .iter()
        .zip(new)
        .filter(|(a, _)| *a * *a >= bar)
        .map(|(a, b)| (*a, *b))
        .unzip();
    if r.len() < 2 || r.len() == reference.len() {
        return all;
    }
    let above = (gain_z(&r, &n), r.len());
    if above.0 > all.0 {
        above
    } else {
        all
    }
}

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
/// ties by the level's paired test `tie_z` over the units); `None` if none is significant.
pub fn choose(
    scores: &[CandidateScore],
    holdout: &[&[f64]],
    tie_z: fn(&[f64], &[f64]) -> f64,
    settings: &DiscoverySettings,
) -> Option<(usize, Vec<usize>)> {
    let best = (0..scores.len())
        .filter(|&i| scores[i].significant)
        .min_by(|&a, &b| scores[a].holdout_rms.total_cmp(&scores[b].holdout_rms))?;
    let tied: Vec<usize> = (0..scores.len())
        .filter(|&i| {
            scores[i].significant
                && (i == best || tie_z(holdout[i], holdout[best]) <= settings.min_gain_sigma)
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
        let (winner, ties) = choose(&scores, &holdout, paired_z, &s).unwrap();
        assert_eq!(scores[winner].name, "b");
        assert_eq!(ties, [0]);
        scores.iter_mut().for_each(|s| s.significant = false);
        assert!(choose(&scores, &holdout, paired_z, &s).is_none());
    }

    #[test]
    fn of_ties_the_fewest_parameters_win_before_the_lower_bic() {
        let s = DiscoverySettings::default();
        let e = noise(500, 4);
        let param = |name: &str| crate::fit::FittedParam {
            name: name.into(),
            value: 1.0,
            std_error: 0.1,
            naive_std_error: 0.1,
            fixed: false,
        };
        // Same held-out residuals: a tie. The four-parameter one has the lower BIC.
        let mut four = score("four", 1.0, 20.0, -540.0, -340.0);
        four.params = ["a", "b", "c", "d"].map(param).to_vec();
        let mut one = score("one", 1.0, 20.0, -520.0, -320.0);
        one.params = vec![param("c")];
        let mut scores = vec![four, one];
        for sc in &mut scores {
            sc.significant = is_significant(sc, &s);
        }
        let (winner, ties) = choose(&scores, &[&e, &e], paired_z, &s).unwrap();
        assert_eq!(scores[winner].name, "one");
        assert_eq!(ties, [0]);
        // A clear held-out gain is not a tie: the better one wins whatever its size.
        let better: Vec<f64> = e.iter().map(|v| v * 0.8).collect();
        scores[0].holdout_rms = 0.8;
        let (winner, ties) = choose(&scores, &[&better, &e], paired_z, &s).unwrap();
        assert_eq!(scores[winner].name, "four");
        assert!(ties.is_empty());
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
    fn a_gain_in_the_units_that_hold_the_misfit_is_seen() {
        // Four units of misfit (RMS 5σ) fixed, twelve at the floor unchanged but for noise.
        let e = noise(16, 5);
        let reference: Vec<f64> = (0..16)
            .map(|i| if i % 4 == 0 { 5.0 } else { 1.0 + 0.05 * e[i] })
            .collect();
        let new: Vec<f64> = (0..16).map(|i| 1.0 + 0.05 * e[(i + 7) % 16]).collect();
        let over_all = block_gain_z(&reference, &new);
        let (z, n) = excess_gain_z(&reference, &new, block_gain_z, 1.0);
        assert!(over_all < 3.0 && z > 4.0, "{over_all} {z}");
        assert_eq!(n, 4);
        // At the floor everywhere: the test over all units.
        let other: Vec<f64> = (0..16).map(|i| 1.0 + 0.05 * e[(i + 3) % 16]).collect();
        let (z, n) = excess_gain_z(&new, &other, block_gain_z, 1.0);
        assert_eq!((z, n), (block_gain_z(&new, &other), 16));
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
}
