//! Each solver stage of a fit as one run of argmin's `Executor`: Levenberg–Marquardt (our
//! [`LevenbergMarquardt`] solver), Nelder–Mead and the particle swarm (argmin's own), each
//! watched by the fit's observer ([`super::observer`]).
//!
//! How a stage ended is argmin's [`TerminationReason`]; [`convergence`] reads it into the
//! fit's [`Convergence`] — what `fit.json` reports — with the solver's words for the rule that
//! ended it. The chain of stages (which stage follows which) is the driver's
//! ([`super::driver`]).

use argmin::core::{Executor, State, TerminationReason};
use argmin::solver::neldermead::NelderMead;
use argmin::solver::particleswarm::ParticleSwarm;
use rand::rngs::StdRng;
use rand::SeedableRng;

use super::error::FitError;
use super::levenberg_marquardt::{BoundStop, LeastSquares, LevenbergMarquardt, STALLED};
use super::lm_state::LmState;
use super::objective::{LnCost, Objective};
use super::observer::{run_observed, SimplexState, SwarmState, Watch};
use super::result::{Convergence, SolverStage};
use super::solver::FitSettings;

/// Where a stage ended, after how many iterations, and how.
pub(super) struct StageEnd {
    /// Internal coordinates of its best point.
    pub u: Vec<f64>,
    /// Its iterations.
    pub iterations: u64,
    /// How it ended.
    pub convergence: Convergence,
}

/// A fit's convergence from argmin's `reason` for the end of a stage of `solver`, the rule
/// that ended it said in `words`: converged, out of iterations, stalled ([`STALLED`]), or
/// failed (any other exit, in its own words).
fn convergence(
    solver: &str,
    reason: Option<&TerminationReason>,
    words: impl FnOnce() -> String,
) -> Convergence {
    match reason {
        Some(TerminationReason::SolverConverged) => Convergence::Converged { reason: words() },
        Some(TerminationReason::MaxItersReached) => Convergence::MaxIterations,
        Some(TerminationReason::SolverExit(why)) if why == STALLED => {
            Convergence::Stalled { reason: words() }
        }
        Some(TerminationReason::SolverExit(why)) => Convergence::Failed {
            reason: why.clone(),
        },
        other => Convergence::Failed {
            reason: format!("{solver} stopped: {other:?}"),
        },
    }
}

/// Levenberg–Marquardt from `start` to the settings' `tol`, for at most `max_iters`
/// iterations, stopping where `stop_at_bound` holds.
pub(super) fn levenberg_marquardt(
    obj: &Objective,
    start: &[f64],
    settings: &FitSettings,
    stop_at_bound: BoundStop,
    watch: &Watch,
) -> Result<StageEnd, FitError> {
    let problem = LeastSquares { obj, stop_at_bound };
    let solver = LevenbergMarquardt::new(settings.tol, settings.fd_step);
    let executor = Executor::new(problem, solver)
        .configure(|s: LmState| s.param(start.to_vec()).max_iters(settings.max_iters))
        .timer(false);
    let mut state = run_observed(executor, watch.observer(SolverStage::LevenbergMarquardt))?;
    let convergence = convergence(
        "Levenberg–Marquardt",
        state.get_termination_reason(),
        || state.rule().unwrap_or_default().to_string(),
    );
    Ok(StageEnd {
        iterations: state.get_iter(),
        u: std::mem::take(&mut state.u),
        convergence,
    })
}

/// Nelder–Mead from `start` (a simplex of edge `simplex_step` scales) to the simplex
/// tolerance `tol`.
pub(super) fn nelder_mead(
    obj: &Objective,
    start: &[f64],
    tol: f64,
    settings: &FitSettings,
    watch: &Watch,
) -> Result<StageEnd, FitError> {
    let p = start.len();
    let mut simplex = vec![start.to_vec()];
    for j in 0..p {
        let mut v = start.to_vec();
        v[j] += settings.simplex_step;
        simplex.push(v);
    }
    let solver = NelderMead::new(simplex)
        .with_sd_tolerance(tol)
        .map_err(|e| FitError::Solver(e.to_string()))?;
    let executor = Executor::new(LnCost(obj), solver)
        .configure(|s: SimplexState| s.max_iters(settings.max_iters))
        .timer(false);
    let state = run_observed(executor, watch.observer(SolverStage::NelderMead))?;
    let convergence = convergence("Nelder–Mead", state.get_termination_reason(), || {
        format!("spread of ln(cost) over the simplex < {tol:.1e}")
    });
    Ok(StageEnd {
        u: state
            .get_best_param()
            .cloned()
            .unwrap_or_else(|| start.to_vec()),
        iterations: state.get_iter(),
        convergence,
    })
}

/// Where the swarm ended.
pub(super) struct SwarmEnd {
    /// Its best point (internal coordinates) and ln cost, if it has one.
    pub best: Option<(Vec<f64>, f64)>,
    /// Its iterations.
    pub iterations: u64,
}

/// The particle swarm over the whole box.
pub(super) fn particle_swarm(
    obj: &Objective,
    settings: &FitSettings,
    watch: &Watch,
) -> Result<SwarmEnd, FitError> {
    let (lo, hi): (Vec<f64>, Vec<f64>) = obj.transforms().iter().map(|t| t.search_box()).unzip();
    let solver = ParticleSwarm::new((lo, hi), settings.particles)
        .with_rng_generator(StdRng::seed_from_u64(settings.seed));
    let executor = Executor::new(LnCost(obj), solver)
        .configure(|s: SwarmState| s.max_iters(settings.max_iters))
        .timer(false);
    let state = run_observed(executor, watch.observer(SolverStage::ParticleSwarm))?;
    let best = state
        .get_best_param()
        .map(|b| (b.position.clone(), state.get_best_cost()));
    Ok(SwarmEnd {
        best,
        iterations: state.get_iter(),
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::fit::levenberg_marquardt::START_FAILS;
    use crate::fit::objective::Residuals;
    use crate::fit::transform::BoundTransform;

    /// r_i = y_i − k·x_i, failing where k > `fails_above`.
    struct Line {
        fails_above: f64,
    }

    impl Residuals for Line {
        fn len(&self) -> usize {
            50
        }
        fn residuals(&self, k: &[f64], sink: &mut dyn FnMut(usize, f64)) -> Result<(), String> {
            if k[0] > self.fails_above {
                return Err("too steep".into());
            }
            for i in 0..50 {
                let x = i as f64 * 0.1;
                let y = 3.0 * x + 0.01 * ((i * 7919 % 13) as f64 - 6.0);
                sink(i, y - k[0] * x);
            }
            Ok(())
        }
    }

    fn refined(line: &Line, start: f64, max_iters: u64) -> StageEnd {
        let obj = Objective::new(line, vec![BoundTransform::new(start, 0.0, 10.0, 1.0)]);
        let watch = Watch::new(obj.tally(), None, None, (&["k"], obj.transforms().to_vec()));
        let settings = FitSettings::default().max_iters(max_iters);
        levenberg_marquardt(&obj, &[0.0], &settings, None, &watch).unwrap()
    }

    #[test]
    fn argmin_s_reasons_become_the_fit_s_convergence() {
        let words = || "the rule".to_string();
        let c = |reason| convergence("LM", Some(&reason), words);
        assert!(c(TerminationReason::SolverConverged).converged());
        assert_eq!(
            c(TerminationReason::MaxItersReached),
            Convergence::MaxIterations
        );
        assert_eq!(
            c(TerminationReason::SolverExit(STALLED.into())),
            Convergence::Stalled {
                reason: "the rule".into()
            }
        );
        assert_eq!(
            c(TerminationReason::SolverExit("no start".into())),
            Convergence::Failed {
                reason: "no start".into()
            }
        );
        assert_eq!(
            convergence("LM", None, words),
            Convergence::Failed {
                reason: "LM stopped: None".into()
            }
        );
    }

    #[test]
    fn the_executor_counts_the_refinement_s_iterations_and_stops_it() {
        let line = Line {
            fails_above: f64::INFINITY,
        };
        let end = refined(&line, 1.0, 1);
        assert_eq!(
            (end.iterations, end.convergence),
            (1, Convergence::MaxIterations)
        );
        let end = refined(&line, 1.0, 100);
        assert!(end.convergence.converged(), "{:?}", end.convergence);
        assert!(end.iterations > 1 && end.iterations < 100);
        // Trial points that fail are rejected steps; a start that fails ends the stage.
        let end = refined(&Line { fails_above: 3.5 }, 1.0, 100);
        assert!(end.convergence.converged(), "{:?}", end.convergence);
        let end = refined(&Line { fails_above: 0.5 }, 1.0, 100);
        assert_eq!(
            (end.iterations, end.convergence),
            (
                0,
                Convergence::Failed {
                    reason: START_FAILS.into()
                }
            )
        );
    }
}
