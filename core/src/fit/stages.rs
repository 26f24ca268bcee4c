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
