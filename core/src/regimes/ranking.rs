//! Ranking models by how well they reproduce each regime.
//!
//! The score of a model in a regime is its relative force RMS error there
//! ([`RegimeMetrics::relative_rms_error`]): the RMS of the force error over the regime's cycles
//! divided by the measured force RMS (floored at the on-threshold); lower is better, 0 is
//! perfect, 1 is as bad as predicting no force at all where there is one. The overall score is
//! the mean of the per-regime scores over the regimes the measurement has, each regime weighing
//! the same, so the small forces of post-resonance count as much as the large ones at
//! resonance (an RMS over the whole record would be decided by the resonance alone). A record
//! with no sweep (a damper on an actuator, a shaker: no rotor, so no regimes along a sweep)
//! is ranked overall by each model's error over the whole record instead
//! ([`OverallScore::WholeRecord`]), the order its verdict gives. Ties and NaN scores sort last
//! in a stable order.
//!
//! [`RegimeMetrics::relative_rms_error`]: super::RegimeMetrics::relative_rms_error

use serde::Serialize;

use super::metrics::{mean_or, Comparison, PerRegime};
use super::regime::Regime;

/// A model's score (lower is better).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Score {
    /// The model's name.
    pub model: String,
    /// Its score.
    pub score: f64,
}

/// What a model's overall score is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OverallScore {
    /// The mean of its per-regime scores, each regime weighing the same (a swept record).
    MeanOverRegimes,
    /// Its relative force RMS error over the whole record (a record with no sweep).
    WholeRecord,
}

/// Models sorted best first, overall and per regime.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Ranking {
    /// By the overall score ([`OverallScore`]).
    pub overall: Vec<Score>,
    /// By the score in each regime (`None`: the measurement has no such cycle).
    pub per_regime: PerRegime<Vec<Score>>,
}

impl Ranking {
    /// The best model overall.
    pub fn best_overall(&self) -> Option<&str> {
        self.overall.first().map(|s| s.model.as_str())
    }

    /// The best model in `regime`.
    pub fn best_in(&self, regime: Regime) -> Option<&str> {
        self.per_regime
            .get(regime)
            .and_then(|v| v.first())
            .map(|s| s.model.as_str())
    }
}

/// `v` best first (lowest score), NaN scores last.
pub(super) fn sorted(mut v: Vec<Score>) -> Vec<Score> {
    v.sort_by(|a, b| match (a.score.is_nan(), b.score.is_nan()) {
        (false, false) => a.score.total_cmp(&b.score),
        (x, y) => x.cmp(&y),
    });
    v
}

/// Rank models from their comparisons with the same measurement, overall by `over` (see the
/// [module doc](self)).
pub fn rank_models(results: &[(&str, &Comparison)], over: OverallScore) -> Ranking {
    let mut per_regime = PerRegime::default();
    for r in Regime::ALL {
        let scores: Vec<Score> = results
            .iter()
            .filter_map(|(name, c)| {
                c.per_regime.get(r).map(|m| Score {
                    model: name.to_string(),
                    score: m.relative_rms_error,
                })
            })
            .collect();
        per_regime.set(r, (!scores.is_empty()).then(|| sorted(scores)));
    }
    let overall = results
        .iter()
        .map(|(name, c)| Score {
            model: name.to_string(),
            score: match over {
                OverallScore::MeanOverRegimes => mean_or(
                    Regime::ALL
                        .iter()
                        .filter_map(|&r| c.per_regime.get(r).map(|m| m.relative_rms_error)),
                    f64::NAN,
                ),
                OverallScore::WholeRecord => c.overall.relative_rms_error,
            },
        })
        .collect();
    Ranking {
        overall: sorted(overall),
        per_regime,
    }
}

#[cfg(test)]
mod tests {
    use super::super::boundaries::Boundaries;
    use super::super::metrics::{BoundaryErrors, RegimeMetrics};
    use super::*;

    fn metrics(rel: f64) -> RegimeMetrics {
        RegimeMetrics {
            cycles: 10,
            measured_rms: 1.0,
            model_rms: 1.0,
            force_rms_error: rel,
            relative_rms_error: rel,
            measured_energy: 0.0,
            energy_error: 0.0,
            measured_duty: 0.0,
            model_duty: 0.0,
            duty_error: 0.0,
            peak_force_error: 0.0,
            label_agreement: 1.0,
            model_energy: 0.0,
            measured_c_eq: 0.0,
            model_c_eq: 0.0,
            c_eq_error: 0.0,
            measured_phase_x: 0.0,
            model_phase_x: 0.0,
            phase_x_error: 0.0,
            measured_phase_v: 0.0,
            model_phase_v: 0.0,
            phase_v_error: 0.0,
            measured_peak_force: 0.0,
            model_peak_force: 0.0,
        }
    }

    fn comparison(res: f64, post: f64) -> Comparison {
        Comparison {
            per_regime: PerRegime {
                pre_resonance: None,
                resonance: Some(metrics(res)),
                post_resonance: Some(metrics(post)),
            },
            overall: metrics(0.0),
            boundary_errors: BoundaryErrors::default(),
            model_labels: vec![],
            model_boundaries: Boundaries::default(),
            model_features: vec![],
            cycle_force_rms_error: vec![],
        }
    }

    #[test]
    fn best_per_regime_and_overall_by_the_mean_of_regimes() {
        // A wins resonance, B wins post-resonance and overall (mean 0.3 against 0.45).
        let a = comparison(0.1, 0.8);
        let b = comparison(0.2, 0.4);
        let c = comparison(f64::NAN, 0.9);
        let r = rank_models(
            &[("a", &a), ("b", &b), ("c", &c)],
            OverallScore::MeanOverRegimes,
        );
        assert_eq!(r.best_in(Regime::Resonance), Some("a"));
        assert_eq!(r.best_in(Regime::PostResonance), Some("b"));
        assert_eq!(r.best_in(Regime::PreResonance), None);
        assert_eq!(r.best_overall(), Some("b"));
        assert!((r.overall[0].score - 0.3).abs() < 1e-12);
        assert_eq!(r.overall.last().map(|s| s.model.as_str()), Some("c"));
        let res = r.per_regime.resonance.as_ref().unwrap();
        assert_eq!(res.last().map(|s| s.model.as_str()), Some("c"));
    }

    #[test]
    fn a_record_without_a_sweep_is_ranked_over_the_whole_record() {
        // B wins the mean over the regimes, A the whole record; the regimes' own rankings
        // are the same either way.
        let (mut a, mut b) = (comparison(0.1, 0.8), comparison(0.2, 0.4));
        a.overall = metrics(0.15);
        b.overall = metrics(0.25);
        let pairs = [("a", &a), ("b", &b)];
        let mean = rank_models(&pairs, OverallScore::MeanOverRegimes);
        let whole = rank_models(&pairs, OverallScore::WholeRecord);
        assert_eq!(mean.best_overall(), Some("b"));
        assert_eq!(whole.best_overall(), Some("a"));
        assert_eq!(whole.overall[0].score, 0.15);
        assert_eq!(mean.per_regime, whole.per_regime);
    }
}
