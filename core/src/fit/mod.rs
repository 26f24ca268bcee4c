//! Calibration: fitting STF models and the oscillator itself to measurements.
//!
//! Two kinds of fit share one engine:
//!
//! - [`ForceFit`]: force level — an STF model's force `m_a·a + f(t, x, v, z) + f_off` against a
//!   measured F_STF, along measured kinematics ([`ForceData`](crate::data::force_data::ForceData)).
//! - [`TrajectoryFit`]: trajectory level, as in the source study — simulate the oscillator
//!   (with or without an STF model) and minimise `S(μ) = mean((x_exp − x_sim − x_off)²)`.
//!
//! Parameters ([`FitParam`]) have start values, bounds (honoured by a change of variables,
//! [`BoundTransform`], never by clipping) and a fixed/free switch. The default solver
//! ([`Solver::Auto`]) runs a Levenberg–Marquardt refinement and falls back on Nelder–Mead
//! (argmin) followed by another refinement if it does not converge; [`Solver::NelderMead`] is
//! the source study's method; [`Solver::ParticleSwarm`] (argmin) searches the whole box first. Every fit ends
//! with standard errors from a finite-difference Jacobian in the user's parameter space —
//! cluster-robust over blocks of consecutive samples as long as the residuals' correlation
//! ([`ErrorBlocks`]; the classical `s²·(JᵀJ)⁻¹`, too small for correlated residuals, is kept
//! beside them) — correlations, RMS, AIC and BIC, and says whether it converged
//! ([`FitResult`]). [`fit_warnings`] says, by the same rules for every kind of fit, when a
//! result is not to be trusted as it stands ([`FitWarning`]): it did not converge, its
//! residual is well above the record's [`NoiseFloor`], a parameter ended on a bound, is not
//! determined, or cannot be told apart from another. A failure inside the fit (a simulation
//! that diverges, a model
//! that errs) scores a penalty and is counted, never a crash. Fits are deterministic (the
//! swarm is seeded). An observer closure receives [`FitProgress`] after every evaluation.
//! A fitted model is scored on another record ([`Validation`]) by [`ForceFit::validate`] and
//! [`TrajectoryFit::validate`].

mod covariance;
mod driver;
mod error;
mod fit_param;
mod force_fit;
mod joint_trajectory;
mod levenberg_marquardt;
mod noise_floor;
mod objective;
mod residual_jacobian;
mod result;
mod same_term;
mod solver;
mod trajectory_fit;
mod transform;
mod validation;
mod warning;

pub use error::FitError;
pub use fit_param::{full_values, FitParam};
pub use force_fit::{ForceFit, FORCE_OFFSET};
pub use joint_trajectory::fit_trajectory_residuals;
pub use noise_floor::{NoiseFloor, Quantity};
pub use objective::Residuals;
pub use result::{Convergence, ErrorBlocks, FitProgress, FitResult, FittedParam, SolverStage};
pub use same_term::check_same_terms;
pub use solver::{FitSettings, Solver};
pub use trajectory_fit::{
    initial_state_params, TrajectoryData, TrajectoryFit, DISPLACEMENT_OFFSET, INITIAL_STATE,
};
pub use transform::BoundTransform;
pub use validation::Validation;
pub use warning::{
    fit_warnings, BoundSide, FitWarning, StatedWarning, CORRELATION_LIMIT, NEAR_BOUND,
    RESIDUAL_OVER_FLOOR,
};

/// Fit any least-squares problem: `params` lists every parameter (free and fixed, in order);
/// `problem` receives the user values of the free ones. For problems that are neither
/// [`ForceFit`] nor [`TrajectoryFit`].
pub fn fit_residuals(
    problem: &dyn Residuals,
    params: &[FitParam],
    settings: &FitSettings,
    observer: Option<&(dyn Fn(FitProgress) + Sync)>,
) -> Result<FitResult, FitError> {
    driver::run(problem, params, settings, observer, false)
}
