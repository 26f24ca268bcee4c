//! When a fit's result is not to be trusted as it stands, and what to try: one set of rules,
//! applied by [`fit_warnings`] to a [`FitResult`], the parameters' bounds and the noise floor,
//! for every kind of fit.
//!
//! | rule | fires when |
//! |---|---|
//! | [`FitWarning::NotConverged`] | the fit ran out of iterations or failed |
//! | [`FitWarning::AboveNoiseFloor`] | RMS residual > [`RESIDUAL_OVER_FLOOR`] × the noise floor |
//! | [`FitWarning::OnBound`] | a free parameter ends within [`NEAR_BOUND`] of its typical size (or of the box, if narrower) from a bound |
//! | [`FitWarning::Undetermined`] | a free parameter's standard error exceeds its \|value\|, or is not finite |
//! | [`FitWarning::Correlated`] | two free parameters correlate beyond [`CORRELATION_LIMIT`] in magnitude |
//! | [`FitWarning::NoisyError`] | a free parameter's difference column stood less than [`crate::fit::NOISY_COLUMN`] times above the residuals' noise |
//!
//! Each warning's [`Display`](std::fmt::Display) is one sentence that says what is wrong and
//! what to try, its numbers written by [`crate::digits`] as the reports and the terminal write
//! them; serialized, it is an object with a `kind` and the data
//! ([`FitWarning::stated`] adds the `message`).

use serde::Serialize;
use thiserror::Error;

use super::fit_param::{BoundSide, FitParam};
use super::noise_floor::{NoiseFloor, Quantity, ShownIn};
use super::result::{Convergence, FitResult};
use crate::digits::{significant, value_and_error};

/// Parameters whose value is near zero by nature (offsets, the initial state): their error
/// is not compared with their value.
const ABOUT_ZERO: [&str; 4] = [
    super::FORCE_OFFSET,
    super::DISPLACEMENT_OFFSET,
    super::INITIAL_STATE[0],
    super::INITIAL_STATE[1],
];

/// A fit whose RMS residual exceeds this multiple of the noise floor misses an effect.
pub const RESIDUAL_OVER_FLOOR: f64 = 1.5;
/// A free parameter this close to a bound — as a fraction of its typical size
/// ([`FitParam::effective_scale`]), or of the box's width if that is smaller — ends on it.
pub const NEAR_BOUND: f64 = 1e-3;
/// Two free parameters whose correlation exceeds this in magnitude are not told apart.
pub const CORRELATION_LIMIT: f64 = 0.99;

/// A reason not to trust a fit's result as it stands.
#[derive(Clone, Debug, PartialEq, Serialize, Error)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FitWarning {
    /// The fit did not converge: the values may not be the optimum.
    #[error("{}", not_converged(.convergence))]
    NotConverged {
        /// How the fit ended.
        convergence: Convergence,
    },
    /// The RMS residual is well above the noise floor: the model misses an effect.
    #[error(
        "the residual is {ratio:.1}× the noise floor (RMS {} against {}): the model \
         misses an effect — try `stf-lab discover`",
        .shown.show(*.rms),
        .shown.show(*.floor)
    )]
    AboveNoiseFloor {
        /// What the residuals measure.
        quantity: Quantity,
        /// The unit the sentence shows them in: the noise floor's, the record's own.
        #[serde(skip)]
        shown: ShownIn,
        /// RMS residual (N or m).
        rms: f64,
        /// Noise floor σ (N or m).
        floor: f64,
        /// `rms / floor`.
        ratio: f64,
    },
    /// A free parameter ended on one of its bounds: the data push it there or beyond.
    #[error(
        "{param} ended on its {} bound ({} at {}): the data push it there or beyond — \
         widen the bound of {param} or fix it",
        .side.name(),
        significant(*.value, 6),
        significant(*.bound, 6)
    )]
    OnBound {
        /// Parameter.
        param: String,
        /// Its fitted value.
        value: f64,
        /// The bound.
        bound: f64,
        /// Which bound.
        side: BoundSide,
    },
    /// A free parameter's standard error exceeds its |value| (or is not finite).
    #[error("{}", undetermined(.param, *.value, *.std_error))]
    Undetermined {
        /// Parameter.
        param: String,
        /// Its fitted value.
        value: f64,
        /// Its standard error (null in JSON if not finite).
        std_error: f64,
    },
    /// Two free parameters correlate so strongly that the data do not tell them apart.
    #[error(
        "{first} and {second} correlate at {correlation:.3}: the data do not tell them \
         apart — fix one or fit a record with a wider velocity range"
    )]
    Correlated {
        /// One parameter.
        first: String,
        /// The other.
        second: String,
        /// Their correlation.
        correlation: f64,
    },
    /// A free parameter's standard error rests on a difference column that hardly stands
    /// above the residuals' own noise (a simulation's, at its tolerance): it is uncertain.
    #[error(
        "the standard error of {param} is uncertain: its effect on the residuals stands only \
         {rise:.1}× above the simulation's own noise — tighten `[integrator] rtol` (e.g. \
         1e-10) and fit again"
    )]
    NoisyError {
        /// Parameter.
        param: String,
        /// Its column's rms change over the residuals' rms noise.
        rise: f64,
    },
}

/// A warning with its sentence, as written to `fit.json`: `kind`, `message` and the data.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StatedWarning<'a> {
    /// The sentence ([`FitWarning`]'s `Display`).
    pub message: String,
    /// The warning's kind and data.
    #[serde(flatten)]
    pub warning: &'a FitWarning,
}

impl FitWarning {
    /// The snake-case name of the rule (the `kind` of the JSON).
    pub fn kind(&self) -> &'static str {
        match self {
            FitWarning::NotConverged { .. } => "not_converged",
            FitWarning::AboveNoiseFloor { .. } => "above_noise_floor",
            FitWarning::OnBound { .. } => "on_bound",
            FitWarning::Undetermined { .. } => "undetermined",
            FitWarning::Correlated { .. } => "correlated",
            FitWarning::NoisyError { .. } => "noisy_error",
        }
    }

    /// The warning with its sentence, for serializing.
    pub fn stated(&self) -> StatedWarning<'_> {
        StatedWarning {
            message: self.to_string(),
            warning: self,
        }
    }
}

/// The sentence of [`FitWarning::NotConverged`]: what the end of the fit says, and what to try.
fn not_converged(convergence: &Convergence) -> String {
    match convergence {
        Convergence::Failed { reason } => format!(
            "the fit failed ({reason}): the values are not an optimum — check the start \
             values and bounds, or try another `fit.solver`"
        ),
        Convergence::Stalled { reason } => format!(
            "the fit stalled ({reason}): the values are not an optimum — start nearer \
             the optimum or try another `fit.solver`"
        ),
        _ => "the fit ran out of iterations: the values may not be the optimum — raise \
              `fit.max_iters` or start nearer the optimum"
            .into(),
    }
}

/// The sentence of [`FitWarning::Undetermined`], with the error if it is finite (the value
/// rounded to it, as the results table shows them).
fn undetermined(param: &str, value: f64, std_error: f64) -> String {
    if std_error.is_finite() {
        let (value, error) = value_and_error(value, std_error);
        format!(
            "{param} = {value} has a standard error of {error}, larger than itself: the \
             data do not determine {param} — fix it or drop its term"
        )
    } else {
        format!(
            "{param} has no finite standard error: the data do not determine \
             {param} — fix it or drop its term"
        )
    }
}

/// Every warning about `result`: `params` are the fit's parameters as given (for their bounds
/// and typical sizes, matched by name), `floor` the record's noise floor (none: the residual is
/// not judged). Most serious first: convergence, residual, bounds, standard errors,
/// correlations.
pub fn fit_warnings(
    result: &FitResult,
    params: &[FitParam],
    floor: Option<&NoiseFloor>,
) -> Vec<FitWarning> {
    let mut out = Vec::new();
    if !result.convergence.converged() {
        out.push(FitWarning::NotConverged {
            convergence: result.convergence.clone(),
        });
    }
    if let Some(floor) = floor.filter(|f| f.is_usable()) {
        let ratio = result.rms / floor.sigma;
        if ratio > RESIDUAL_OVER_FLOOR || ratio.is_nan() {
            out.push(FitWarning::AboveNoiseFloor {
                quantity: floor.quantity,
                shown: floor.shown,
                rms: result.rms,
                floor: floor.sigma,
                ratio,
            });
        }
    }
    let free: Vec<_> = result.params.iter().filter(|p| !p.fixed).collect();
    for p in &free {
        if let Some(q) = params.iter().find(|q| q.name == p.name) {
            out.extend(on_bound(q, p.value, p.held_by));
        }
    }
    for p in &free {
        // An offset or an initial state is near zero by nature: only an unbounded error
        // says it is not determined.
        let about_zero = ABOUT_ZERO.contains(&p.name.as_str());
        if (p.std_error > p.value.abs() && !about_zero) || !p.std_error.is_finite() {
            out.push(FitWarning::Undetermined {
                param: p.name.clone(),
                value: p.value,
                std_error: p.std_error,
            });
        }
    }
    for p in &free {
        if let Some(rise) = p.noisy_column {
            out.push(FitWarning::NoisyError {
                param: p.name.clone(),
                rise,
            });
        }
    }
    for (i, row) in result.correlation.iter().enumerate() {
        for (j, &c) in row.iter().enumerate().skip(i + 1) {
            if c.abs() > CORRELATION_LIMIT && c.is_finite() {
                let nuisance = |k: usize| {
                    free.get(k)
                        .is_some_and(|p| ABOUT_ZERO.contains(&p.name.as_str()))
                };
                // Two nuisances trading off (x0 against v0 while the trolley sticks) leave
                // the physics parameters alone.
                if nuisance(i) && nuisance(j) {
                    continue;
                }
                if let (Some(a), Some(b)) = (free.get(i), free.get(j)) {
                    out.push(FitWarning::Correlated {
                        first: a.name.clone(),
                        second: b.name.clone(),
                        correlation: c,
                    });
                }
            }
        }
    }
    out
}

/// Whether `value` of parameter `q` lies on one of its bounds (see [`NEAR_BOUND`]) or is
/// `held` by one (the data push it past a bound it stopped short of: [`crate::fit::HELD_REACH`]).
fn on_bound(q: &FitParam, value: f64, held: Option<BoundSide>) -> Option<FitWarning> {
    let width = q.max - q.min;
    let size = q.effective_scale();
    let reach = NEAR_BOUND * if width < size { width } else { size };
    let side = if q.min.is_finite() && value - q.min <= reach {
        (BoundSide::Lower, q.min)
    } else if q.max.is_finite() && q.max - value <= reach {
        (BoundSide::Upper, q.max)
    } else if let Some(side) = held {
        (
            side,
            if side == BoundSide::Lower {
                q.min
            } else {
                q.max
            },
        )
    } else {
        return None;
    };
    Some(FitWarning::OnBound {
        param: q.name.clone(),
        value,
        bound: side.1,
        side: side.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::FittedParam;

    /// A converged two-parameter fit with RMS 0.02, K = 4 ± 0.05, n = 1.5 ± 0.006,
    /// correlation `c`.
    fn result(c: f64) -> FitResult {
        FitResult {
            params: vec![
                FittedParam::free("K", 4.0, 0.05),
                FittedParam::free("n", 1.5, 0.006),
            ],
            correlation: vec![vec![1.0, c], vec![c, 1.0]],
            n_points: 1000,
            n_free: 2,
            rss: 0.4,
            rms: 0.02,
            s_mm2: None,
            aic: 0.0,
            bic: 0.0,
            evaluations: 10,
            failures: 0,
            last_failure: None,
            iterations: 5,
            wall_seconds: 0.0,
            convergence: Convergence::Converged {
                reason: "test".into(),
            },
            log: Vec::new(),
            error_blocks: None,
        }
    }

    fn bounds() -> Vec<FitParam> {
        vec![
            FitParam::new("K", 2.0).bounds(0.0, 1e4),
            FitParam::new("n", 1.2).bounds(1.0, 4.0),
        ]
    }

    fn kinds(w: &[FitWarning]) -> Vec<&'static str> {
        w.iter().map(FitWarning::kind).collect()
    }

    #[test]
    fn a_sound_fit_draws_no_warning() {
        let floor = NoiseFloor::force(0.02, 0.001);
        assert!(fit_warnings(&result(0.98), &bounds(), Some(&floor)).is_empty());
    }

    #[test]
    fn a_residual_well_above_the_floor_is_flagged_with_its_ratio() {
        let floor = NoiseFloor::force(0.012, 0.0);
        let w = fit_warnings(&result(0.0), &bounds(), Some(&floor));
        assert_eq!(kinds(&w), ["above_noise_floor"]);
        let FitWarning::AboveNoiseFloor { ratio, .. } = w[0] else {
            unreachable!()
        };
        assert!((ratio - 0.02 / 0.012).abs() < 1e-12);
        let text = w[0].to_string();
        assert!(
            text.contains("1.7× the noise floor") && text.contains("stf-lab discover"),
            "{text}"
        );
        // Up to 1.5× the floor is noise; an unusable floor judges nothing.
        let floor = NoiseFloor::force(0.014, 0.0);
        assert!(fit_warnings(&result(0.0), &bounds(), Some(&floor)).is_empty());
        let none = NoiseFloor::displacement(0.0);
        assert!(fit_warnings(&result(0.0), &bounds(), Some(&none)).is_empty());
        // Trajectory residuals read in mm.
        let floor = NoiseFloor::displacement(0.005);
        let w = fit_warnings(&result(0.0), &bounds(), Some(&floor));
        assert!(w[0]
            .to_string()
            .contains("RMS 20.0000 mm against 5.0000 mm"));
        // A record's own unit, given with the floor: a force in kN, a voltage in mV.
        let mut large = result(0.0);
        large.rms = 2.0e4;
        let kilo = NoiseFloor::force(1.2e4, 0.0).shown_in(ShownIn::new("kN", 1e-3));
        let w = fit_warnings(&large, &bounds(), Some(&kilo));
        let text = w[0].to_string();
        assert!(text.contains("RMS 20.0000 kN against 12.0000 kN"), "{text}");
        let volts = NoiseFloor::displacement(0.005).shown_in(ShownIn::new("mV", 1e3));
        let w = fit_warnings(&result(0.0), &bounds(), Some(&volts));
        let text = w[0].to_string();
        assert!(text.contains("RMS 20.0000 mV against 5.0000 mV"), "{text}");
    }

    #[test]
    fn a_parameter_on_a_bound_is_flagged_and_one_near_it_is_not() {
        let mut r = result(0.0);
        r.params[1].value = 1.0 + 1e-4;
        let w = fit_warnings(&r, &bounds(), None);
        assert_eq!(
            w,
            [FitWarning::OnBound {
                param: "n".into(),
                value: 1.0001,
                bound: 1.0,
                side: BoundSide::Lower
            }]
        );
        assert!(
            w[0].to_string()
                .starts_with("n ended on its lower bound (1.0001 at 1): the data push it"),
            "{}",
            w[0]
        );
        assert!(w[0].to_string().contains("widen the bound of n or fix it"));
        // 1 % of its size from the bound is inside.
        r.params[1].value = 1.012;
        assert!(fit_warnings(&r, &bounds(), None).is_empty());
        // The upper bound; a box narrower than the size sets the reach.
        r.params[1].value = 4.0;
        let w = fit_warnings(&r, &bounds(), None);
        assert!(matches!(
            w[..],
            [FitWarning::OnBound {
                side: BoundSide::Upper,
                ..
            }]
        ));
        let narrow = [FitParam::new("n", 1.2).bounds(1.0, 1.5)];
        r.params[1].value = 1.0009;
        assert!(fit_warnings(&r, &narrow, None).is_empty());
        r.params[1].value = 1.0004;
        assert_eq!(kinds(&fit_warnings(&r, &narrow, None)), ["on_bound"]);
        // A fixed parameter on its bound is the user's choice.
        r.params[1].fixed = true;
        assert!(fit_warnings(&r, &narrow, None).is_empty());
    }

    #[test]
    fn a_standard_error_above_the_value_or_not_finite_is_flagged() {
        let mut r = result(0.0);
        r.params[0].std_error = 5.2;
        r.params[1].std_error = f64::INFINITY;
        let w = fit_warnings(&r, &bounds(), None);
        assert_eq!(kinds(&w), ["undetermined", "undetermined"]);
        assert!(
            w[0].to_string()
                .starts_with("K = 4 has a standard error of 5, larger than itself"),
            "{}",
            w[0]
        );
        let small = FitWarning::Undetermined {
            param: "m_a".into(),
            value: 1.5184e-4,
            std_error: 5.60e-4,
        };
        assert!(
            small
                .to_string()
                .starts_with("m_a = 2e-4 has a standard error of 6e-4, larger than itself"),
            "{small}"
        );
        assert!(w[1].to_string().contains("no finite standard error"));
        r.params[0].std_error = f64::NAN;
        r.params[1].std_error = 1.5;
        assert_eq!(kinds(&fit_warnings(&r, &bounds(), None)), ["undetermined"]);
    }

    #[test]
    fn a_correlation_beyond_the_limit_names_both_parameters() {
        let w = fit_warnings(&result(-0.998), &bounds(), None);
        assert_eq!(
            w,
            [FitWarning::Correlated {
                first: "K".into(),
                second: "n".into(),
                correlation: -0.998
            }]
        );
        assert!(w[0]
            .to_string()
            .starts_with("K and n correlate at -0.998: the data do not tell them apart"));
        // Not determined (NaN) is the standard error's rule, not this one.
        assert!(fit_warnings(&result(f64::NAN), &bounds(), None).is_empty());
    }

    #[test]
    fn a_fit_that_did_not_converge_says_so_first() {
        let mut r = result(0.0);
        r.convergence = Convergence::MaxIterations;
        let floor = NoiseFloor::force(0.01, 0.0);
        let w = fit_warnings(&r, &bounds(), Some(&floor));
        assert_eq!(kinds(&w), ["not_converged", "above_noise_floor"]);
        assert!(w[0].to_string().contains("raise `fit.max_iters`"));
        r.convergence = Convergence::Failed {
            reason: "no solver improved on the start".into(),
        };
        let w = fit_warnings(&r, &bounds(), None);
        assert!(w[0].to_string().contains("fit failed (no solver improved"));
    }

    #[test]
    fn the_json_has_a_kind_a_message_and_the_data() {
        let w = FitWarning::Undetermined {
            param: "m_a".into(),
            value: 1e-4,
            std_error: f64::INFINITY,
        };
        let v = serde_json::to_value(w.stated()).unwrap();
        assert_eq!(v["kind"], "undetermined");
        assert_eq!(v["param"], "m_a");
        assert!(v["std_error"].is_null());
        assert_eq!(v["message"], w.to_string());
        let v = serde_json::to_value(
            FitWarning::NotConverged {
                convergence: Convergence::MaxIterations,
            }
            .stated(),
        )
        .unwrap();
        assert_eq!(v["convergence"]["status"], "max_iterations");
    }
}
