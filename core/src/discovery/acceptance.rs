//! The rule that decides whether the data demand a candidate, and which one.
//!
//! The evidence is a paired test on the held-out samples: with `r₀` the current model's
//! residuals there and `r₁` the candidate's (each fitted on the training cycles only),
//! `dᵢ = r₀ᵢ² − r₁ᵢ²`, and `z = mean(d) / (sd(d)/√N_h)`. Under "nothing is missing" the
//! candidate's extra parameters only fit training noise, which the held-out noise does not
//! share, so `z` is of order 1 or negative; a real effect makes it large. The pairing removes
//! the noise common to both models, so a gain far below σ/√N_h is still resolved when it is
//! consistent. A candidate is **significant** when
//!
//! 1. its fit ran, and its held-out gain has `z > min_gain_sigma` (default 3), and
//! 2. its BIC on the training samples is below the current model's by more than
//!    `min_bic_drop` (default 10, "very strong" on Kass and Raftery's scale).
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
/// 0 for no samples or no difference.
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

/// Whether `score` passes the test against the current model.
pub fn is_significant(score: &CandidateScore, settings: &DiscoverySettings) -> bool {
    score.failure.is_none()
        && score.gain_z > settings.min_gain_sigma
        && score.delta_bic < -settings.min_bic_drop
}

/// The accepted candidate (its index in `scores`: of the ties, the one with the fewest own
/// `params`, then the lowest BIC) and the indices of its ties, from scores
/// whose `significant` flag is set and their held-out units `holdout` (same order), compared
/// by the level's paired test `gain_z` ([`paired_z`] over samples, the log-ratio over cycles
/// at trajectory level); `None` if none is significant.
pub fn choose(
    scores: &[CandidateScore],
    holdout: &[&[f64]],
    gain_z: fn(&[f64], &[f64]) -> f64,
    settings: &DiscoverySettings,
) -> Option<(usize, Vec<usize>)> {
    let best = (0..scores.len())
        .filter(|&i| scores[i].significant)
        .min_by(|&a, &b| scores[a].holdout_rms.total_cmp(&scores[b].holdout_rms))?;
    let tied: Vec<usize> = (0..scores.len())
        .filter(|&i| {
            scores[i].significant
                && (i == best || gain_z(holdout[i], holdout[best]) <= settings.min_gain_sigma)
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
            explained_fraction: 0.0,
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
    fn a_failed_fit_is_never_significant() {
        let s = DiscoverySettings::default();
        let mut sc = score("a", 0.01, 100.0, -1e3, -1e3);
        sc.failure = Some("diverged".into());
        assert!(!is_significant(&sc, &s));
    }
}
