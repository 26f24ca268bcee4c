//! Ranking models on what the field reads from loops, as well as on the force error, each
//! ranking with the test behind it.
//!
//! For each [`LoopMetric`] a model gets a per-cycle error against the measured cycle (the
//! measured regimes' cycles, the model's force on the measured kinematics):
//!
//! | metric | per-cycle error | score in a regime |
//! |---|---|---|
//! | `force` | RMS of F_model − F_measured over the cycle, N | mean over its cycles ÷ mean measured RMS force there |
//! | `energy` | \|Δ∮F dx\|, J | mean ÷ mean \|measured ∮F dx\| there |
//! | `c_eq` | \|Δ equivalent viscous damping\|, N·s/m | mean ÷ mean \|measured c_eq\| there |
//! | `phase_x`, `phase_v` | \|Δ phase of the fundamental\| against x, v, wrapped to 180° | mean, degrees (cycles where both have a fundamental) |
//! | `duty` | \|Δ on-fraction\| | mean |
//! | `peak_force` | \|Δ peak \|F\|\|, N | mean ÷ mean measured peak there |
//!
//! Each cycle's measured scale is at least what a force at the on-threshold would give (that
//! RMS and peak; the energy π·F·X and c_eq F/(ω·X) of a damper of that peak), so a regime whose
//! measured force is only noise does not divide by ≈ 0. Lower is better. The overall score is the mean of the per-regime scores (each regime weighs
//! the same, as in [`super::ranking`]). The **test behind each ranking**: in each regime the
//! best model's per-cycle errors are paired, cycle by cycle, with the runner-up's; `z` is the
//! mean of the differences over its standard error (whole cycles are the units, as evidence
//! pairs blocks, never correlated samples). |z| < 2 says the two are not told apart by this
//! metric on this record. Cycles next to each other along a slow sweep still resemble each
//! other, so `z` is an upper bound on the evidence, not a p-value.

use serde::Serialize;

use super::classify::{Classification, Regime};
use super::metrics::{finite_mean, phase_error, Comparison, PerRegime};
use super::ranking::{sorted, Score};

/// A quantity read from the loops.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum LoopMetric {
    /// RMS force error per cycle.
    Force,
    /// Energy dissipated per cycle.
    Energy,
    /// Equivalent viscous damping.
    CEq,
    /// Phase of the fundamental against x.
    PhaseX,
    /// Phase of the fundamental against v.
    PhaseV,
    /// On-fraction of the cycle.
    Duty,
    /// Peak force.
    PeakForce,
}

impl LoopMetric {
    /// Every metric, in report order.
    pub const ALL: [LoopMetric; 7] = [
        LoopMetric::Force,
        LoopMetric::Energy,
        LoopMetric::CEq,
        LoopMetric::PhaseX,
        LoopMetric::PhaseV,
        LoopMetric::Duty,
        LoopMetric::PeakForce,
    ];

    /// The name in results.
    pub fn name(self) -> &'static str {
        match self {
            LoopMetric::Force => "force",
            LoopMetric::Energy => "energy",
            LoopMetric::CEq => "c_eq",
            LoopMetric::PhaseX => "phase_x",
            LoopMetric::PhaseV => "phase_v",
            LoopMetric::Duty => "duty",
            LoopMetric::PeakForce => "peak_force",
        }
    }

    /// What the score is, in words.
    pub fn criterion(self) -> &'static str {
        match self {
            LoopMetric::Force => "mean per-cycle RMS force error / mean measured RMS force",
            LoopMetric::Energy => "mean |Δ∮F dx| per cycle / mean |measured ∮F dx|",
            LoopMetric::CEq => "mean |Δc_eq| per cycle / mean |measured c_eq|",
            LoopMetric::PhaseX => "mean |Δphase of the force's fundamental against x|, degrees",
            LoopMetric::PhaseV => "mean |Δphase of the force's fundamental against v|, degrees",
            LoopMetric::Duty => "mean |Δon-fraction| per cycle",
            LoopMetric::PeakForce => "mean |Δpeak |F|| per cycle / mean measured peak",
        }
    }

    /// Error of cycle `i` (model against measured), and the measured value's scale there:
    /// at least what a force at the on-threshold `thr` would give (its RMS and peak, the
    /// energy and c_eq of a damper of that peak force), so a regime whose measured force is
    /// only noise does not divide by ≈ 0.
    fn cycle(self, i: usize, meas: &Classification, c: &Comparison) -> (f64, f64) {
        let (a, b) = (&meas.features[i], &c.model_features[i]);
        let thr = meas.on_threshold;
        let damper = |x: f64| if x.is_finite() { x } else { 0.0 };
        match self {
            LoopMetric::Force => (c.cycle_force_rms_error[i], a.f_rms.max(thr)),
            LoopMetric::Energy => (
                (b.energy - a.energy).abs(),
                a.energy.abs().max(std::f64::consts::PI * thr * a.amplitude),
            ),
            LoopMetric::CEq => (
                (b.c_eq - a.c_eq).abs(),
                a.c_eq.abs().max(damper(thr / (a.omega * a.amplitude))),
            ),
            LoopMetric::PhaseX => (phase_error(a.phase_x, b.phase_x), f64::NAN),
            LoopMetric::PhaseV => (phase_error(a.phase_v, b.phase_v), f64::NAN),
            LoopMetric::Duty => ((b.duty - a.duty).abs(), f64::NAN),
            LoopMetric::PeakForce => ((b.f_peak - a.f_peak).abs(), a.f_peak.max(thr)),
        }
    }

    /// Whether the score divides by the measured scale.
    fn relative(self) -> bool {
        !matches!(
            self,
            LoopMetric::PhaseX | LoopMetric::PhaseV | LoopMetric::Duty
        )
    }
}

/// The paired test of the best model against the runner-up over a regime's cycles.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PairedTest {
    /// The best model.
    pub best: String,
    /// The runner-up.
    pub runner_up: String,
    /// Cycles where both errors are defined.
    pub cycles: usize,
    /// Mean per-cycle error of the runner-up minus the best's.
    pub mean_difference: f64,
    /// That over its standard error (NaN with fewer than 2 cycles or no spread).
    pub z: f64,
}

/// Models ranked in one regime by one metric.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct RegimeRank {
    /// Scores, best first.
    pub scores: Vec<Score>,
    /// Best against runner-up (`None` with fewer than two models).
    pub test: Option<PairedTest>,
}

/// Models ranked by one metric.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MetricRanking {
    /// The metric.
    pub metric: LoopMetric,
    /// What the score is.
    pub criterion: &'static str,
    /// By the mean of the per-regime scores, best first.
    pub overall: Vec<Score>,
    /// Per measured regime.
    pub per_regime: PerRegime<RegimeRank>,
}

fn paired(best: &str, runner: &str, errors: &[(Vec<f64>, &str)]) -> Option<PairedTest> {
    let get = |name: &str| errors.iter().find(|e| e.1 == name).map(|e| &e.0);
    let (a, b) = (get(best)?, get(runner)?);
    let d: Vec<f64> = a
        .iter()
        .zip(b)
        .map(|(x, y)| y - x)
        .filter(|d| d.is_finite())
        .collect();
    let n = d.len();
    let mean = d.iter().sum::<f64>() / n.max(1) as f64;
    let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n.max(2) - 1) as f64;
    let se = (var / n.max(1) as f64).sqrt();
    Some(PairedTest {
        best: best.to_string(),
        runner_up: runner.to_string(),
        cycles: n,
        mean_difference: mean,
        z: if n >= 2 && se > 0.0 {
            mean / se
        } else {
            f64::NAN
        },
    })
}

fn rank_regime(
    metric: LoopMetric,
    idx: &[usize],
    meas: &Classification,
    results: &[(&str, &Comparison)],
) -> RegimeRank {
    let errors: Vec<(Vec<f64>, &str)> = results
        .iter()
        .map(|(name, c)| {
            (
                idx.iter().map(|&i| metric.cycle(i, meas, c).0).collect(),
                *name,
            )
        })
        .collect();
    let scale = if metric.relative() {
        results.first().map_or(f64::NAN, |(_, c)| {
            finite_mean(idx.iter().map(|&i| metric.cycle(i, meas, c).1))
        })
    } else {
        1.0
    };
    let scores = sorted(
        errors
            .iter()
            .map(|(e, name)| Score {
                model: name.to_string(),
                score: finite_mean(e.iter().copied()) / scale,
            })
            .collect(),
    );
    let test = match scores.as_slice() {
        [a, b, ..] => paired(&a.model, &b.model, &errors),
        _ => None,
    };
    RegimeRank { scores, test }
}

/// Rank models on every [`LoopMetric`], per measured regime and overall, each with the paired
/// test of the best against the runner-up (see the [module doc](self)).
pub fn rank_on_loops(meas: &Classification, results: &[(&str, &Comparison)]) -> Vec<MetricRanking> {
    LoopMetric::ALL
        .iter()
        .map(|&metric| {
            let mut per_regime = PerRegime::default();
            for r in Regime::ALL {
                let idx = meas.cycles_in(r);
                if !idx.is_empty() {
                    per_regime.set(r, Some(rank_regime(metric, &idx, meas, results)));
                }
            }
            // Each model's mean over the regimes where its score is finite.
            let overall = results
                .iter()
                .map(|(name, _)| {
                    let ranks = Regime::ALL.into_iter().filter_map(|r| per_regime.get(r));
                    let scores = ranks.map(|rank: &RegimeRank| {
                        let mine = rank.scores.iter().find(|s| s.model == *name);
                        mine.map_or(f64::NAN, |s| s.score)
                    });
                    Score {
                        model: name.to_string(),
                        score: finite_mean(scores),
                    }
                })
                .collect();
            MetricRanking {
                metric,
                criterion: metric.criterion(),
                overall: sorted(overall),
                per_regime,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::classify::classify;
    use super::super::cycles::cycles_from_phase;
    use super::super::metrics::compare;
    use super::super::thresholds::RegimeThresholds;
    use super::*;
    use crate::data::force_data::ForceData;
    use rand::rngs::StdRng;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    #[test]
    fn the_true_damper_ranks_first_on_every_loop_metric_with_its_test() {
        // ω = 6 rad/s, 200 Hz, 30 s, x = 10 mm·sin φ; measured F = 40·v + σ 0.02 N. Models: the
        // truth, a damper 30 % weaker, and a spring with the same peak force (no energy, phase
        // 0° against x instead of 90°).
        let t: Vec<f64> = (0..6000).map(|i| i as f64 / 200.0).collect();
        let phi: Vec<f64> = t.iter().map(|t| 6.0 * t).collect();
        let x: Vec<f64> = phi.iter().map(|p| 0.01 * p.sin()).collect();
        let v: Vec<f64> = phi.iter().map(|p| 0.06 * p.cos()).collect();
        let a: Vec<f64> = phi.iter().map(|p| -0.36 * p.sin()).collect();
        let mut rng = StdRng::seed_from_u64(4);
        let g = Normal::new(0.0, 0.02).unwrap();
        let truth: Vec<f64> = v.iter().map(|v| 40.0 * v).collect();
        let f: Vec<f64> = truth.iter().map(|f| f + g.sample(&mut rng)).collect();
        let sig = ForceData::new(&t, &x, &v, &a, &f);
        let th = RegimeThresholds::default();
        let meas = classify(&sig, cycles_from_phase(&t, &phi).unwrap(), &th).unwrap();
        let weak: Vec<f64> = truth.iter().map(|f| 0.7 * f).collect();
        let spring: Vec<f64> = x.iter().map(|x| 240.0 * x).collect();
        let cs: Vec<Comparison> = [&truth, &weak, &spring]
            .iter()
            .map(|m| compare(&meas, &sig, m, &th).unwrap())
            .collect();
        let named = [("truth", &cs[0]), ("weak", &cs[1]), ("spring", &cs[2])];
        let r = cs[0].per_regime.resonance.unwrap();
        assert!(
            (r.measured_c_eq / 40.0 - 1.0).abs() < 0.01,
            "c_eq {}",
            r.measured_c_eq
        );
        assert!((r.measured_phase_x - 90.0).abs() < 1.0 && r.measured_phase_v.abs() < 1.0);
        assert!((cs[1].per_regime.resonance.unwrap().model_c_eq / 28.0 - 1.0).abs() < 0.01);
        assert!(cs[2].per_regime.resonance.unwrap().model_phase_x.abs() < 1.0);
        for m in rank_on_loops(&meas, &named) {
            let res = m.per_regime.resonance.as_ref().unwrap();
            let test = res.test.as_ref().unwrap();
            let last = &res.scores[2].model;
            if matches!(
                m.metric,
                LoopMetric::Duty | LoopMetric::PhaseX | LoopMetric::PhaseV
            ) {
                // A weaker damper has the damper's phase and on-fraction: the two tie (to
                // rounding) and the test says so; the spring is last on phase.
                assert!(
                    test.mean_difference.abs() < 1e-9,
                    "{:?}: {test:?}",
                    m.metric
                );
                if m.metric != LoopMetric::Duty {
                    assert_eq!(last, "spring", "{:?}", m.metric);
                    assert!(res.scores[2].score > 80.0, "{:?}", res.scores);
                }
            } else if m.metric == LoopMetric::PeakForce {
                // The spring was built with the damper's peak: the test does not tell them
                // apart, and the weaker damper is last.
                assert_eq!(res.scores[0].model, "truth");
                assert!(test.runner_up == "spring" && test.z.abs() < 3.0, "{test:?}");
                assert_eq!(last, "weak");
            } else {
                assert_eq!(m.overall[0].model, "truth", "{:?}", m.metric);
                assert_eq!(res.scores[0].model, "truth", "{:?}", m.metric);
                assert!(test.z > 10.0, "{:?}: {test:?}", m.metric);
            }
        }
    }
}
