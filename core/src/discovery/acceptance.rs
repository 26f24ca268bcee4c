//! The rule that decides whether the data demand a candidate, and which one.
//!
//! With σ the noise floor and N_h the number of held-out samples, the margin is
//! `m = min_gain_sigma · σ / √N_h` (the standard error of an RMS of N_h samples of white noise
//! is σ/√(2N_h), so the default of 3 is above 4 standard errors). A candidate is
//! **significant** when
//!
//! 1. its fit ran, and its held-out RMS is below the current model's by more than `m`, and
//! 2. its BIC on the training samples is below the current model's by more than
//!    `min_bic_drop` (default 10).
//!
//! Among significant candidates, those whose held-out RMS is within `m` of the lowest explain
//! the data equally well; of them the one with the lowest BIC (fewest parameters for the same
//! fit) is accepted and the others are reported as ties. Nothing significant ends the search.

use super::score::CandidateScore;
use super::settings::DiscoverySettings;

/// The margin a held-out gain must exceed, N.
pub fn margin(settings: &DiscoverySettings, noise_floor: f64, n_holdout: usize) -> f64 {
    settings.min_gain_sigma * noise_floor / (n_holdout.max(1) as f64).sqrt()
}

/// Whether `score` passes the test against the current model.
pub fn is_significant(score: &CandidateScore, margin: f64, settings: &DiscoverySettings) -> bool {
    score.failure.is_none()
        && score.holdout_gain.is_finite()
        && score.holdout_gain > margin
        && score.delta_bic < -settings.min_bic_drop
}

/// The accepted candidate (its index in `scores`) and the indices of its ties, from scores
/// whose `significant` flag is set; `None` if none is significant.
pub fn choose(scores: &[CandidateScore], margin: f64) -> Option<(usize, Vec<usize>)> {
    let best = scores
        .iter()
        .filter(|s| s.significant)
        .map(|s| s.holdout_rms)
        .fold(f64::INFINITY, f64::min);
    let tied: Vec<usize> = (0..scores.len())
        .filter(|&i| scores[i].significant && scores[i].holdout_rms <= best + margin)
        .collect();
    let &winner = tied
        .iter()
        .min_by(|&&a, &&b| scores[a].bic.total_cmp(&scores[b].bic))?;
    Some((winner, tied.into_iter().filter(|&i| i != winner).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn score(name: &str, holdout_rms: f64, gain: f64, bic: f64, delta_bic: f64) -> CandidateScore {
        CandidateScore {
            name: name.into(),
            holdout_rms,
            train_rms: holdout_rms,
            aic: bic,
            bic,
            delta_aic: delta_bic,
            delta_bic,
            holdout_gain: gain,
            explained_fraction: 0.0,
            params: vec![],
            significant: false,
            failure: None,
        }
    }

    #[test]
    fn both_tests_must_pass_and_ties_go_to_the_lower_bic() {
        let s = DiscoverySettings::default();
        let m = margin(&s, 0.02, 3600);
        assert!((m - 0.001).abs() < 1e-12);
        let mut scores = vec![
            score("a", 0.0200, 0.030, -500.0, -300.0),
            score("b", 0.0205, 0.0295, -520.0, -320.0),
            score("c", 0.0300, 0.020, -400.0, -200.0),
            score("d", 0.0195, 0.0305, -100.0, -5.0), // BIC test fails
            score("e", 0.0495, 0.0005, -600.0, -50.0), // gain within the margin
        ];
        for sc in &mut scores {
            sc.significant = is_significant(sc, m, &s);
        }
        let flags: Vec<bool> = scores.iter().map(|s| s.significant).collect();
        assert_eq!(flags, [true, true, true, false, false]);
        let (winner, ties) = choose(&scores, m).unwrap();
        assert_eq!(scores[winner].name, "b");
        assert_eq!(ties, [0]);
        scores.iter_mut().for_each(|s| s.significant = false);
        assert!(choose(&scores, m).is_none());
    }

    #[test]
    fn a_failed_fit_is_never_significant() {
        let s = DiscoverySettings::default();
        let mut sc = score("a", 0.01, 1.0, -1e3, -1e3);
        sc.failure = Some("diverged".into());
        assert!(!is_significant(&sc, 0.0, &s));
    }
}
