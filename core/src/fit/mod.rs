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
//! followed by another refinement if it does not converge; [`Solver::NelderMead`] is
//! the source study's method; [`Solver::ParticleSwarm`] searches the whole box first. Every
//! stage is one run of argmin's `Executor`: Nelder–Mead and the swarm are argmin's solvers,
//! Levenberg–Marquardt is ours written as an argmin `Solver` (its own state, `LmState`; why,
//! in `levenberg_marquardt.rs`), and how a stage ended is argmin's termination reason, read
//! into [`Convergence`]. Every fit ends
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
//! swarm is seeded). An observer closure receives [`FitProgress`] after every iteration of
//! every stage, from the fit's argmin observer, which also writes a trace of the iterations
//! when [`FitSettings::trace`] names a file.
//! A fitted model is scored on another record ([`Validation`]) by [`ForceFit::validate`] and
//! [`TrajectoryFit::validate`].

mod covariance;
mod driver;
mod error;
mod filter_noise;
mod fit_param;
mod force_fit;
mod kept_points;
mod levenberg_marquardt;
mod lm_state;
mod noise_floor;
mod objective;
mod observer;
mod offset;
mod part_cache;
mod residual_jacobian;
mod result;
mod row_halves;
mod same_term;
mod solver;
mod stages;
mod trajectory_fit;
mod transform;
mod validation;
mod warning;

pub use driver::{with_errors, HELD_REACH, NOISY_COLUMN};
pub use error::FitError;
pub use filter_noise::{FilterNoise, REPLICATES};
pub use fit_param::{full_values, BoundSide, FitParam};
pub use force_fit::{ForceFit, FORCE_OFFSET};
pub use noise_floor::{NoiseFloor, Quantity, ShownIn};
pub use objective::Residuals;
pub use offset::{least_squares_offset, offset_param, offset_reach};
pub use residual_jacobian::{error_settings, ERROR_ATOL, ERROR_RTOL};
pub use result::{Convergence, ErrorBlocks, FitProgress, FitResult, FittedParam, SolverStage};
pub use same_term::check_same_terms;
pub use solver::{FitSettings, Solver};
pub use trajectory_fit::{
    initial_state_params, TrajectoryData, TrajectoryFit, DISPLACEMENT_OFFSET, INITIAL_STATE,
};
pub use transform::BoundTransform;
pub use validation::Validation;
pub use warning::{
    fit_warnings, FitWarning, StatedWarning, CORRELATION_LIMIT, NEAR_BOUND, RESIDUAL_OVER_FLOOR,
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
    driver::run(problem, params, settings, observer, Quantity::Force)
}

/// Fit `problem`, whose residuals are displacements in m, as a trajectory fit is fitted:
/// `params` lists every parameter (free and fixed, in order); `problem` receives the user
/// values of the free ones.
///
/// For a least-squares problem of simulated displacements that is not one
/// [`TrajectoryFit`] — several records' trajectories fitted together over shared
/// parameters (a campaign's global fit) — by the rules of a trajectory fit: the same driver,
/// its refinement stopping where a parameter reaches a bound and releasing it, `S` reported
/// in mm² ([`FitResult::s_mm2`]), standard errors from the same block-robust
/// covariance. The caller gives the settings a trajectory fit would use
/// ([`FitSettings::for_simulation`] at its integrator's `rtol`).
///
/// A residual evaluation that fails (a simulation that diverges at a trial point) is scored as
/// a penalty and counted, as in every fit: the step is rejected, the fit goes on.
pub fn fit_trajectory_residuals(
    problem: &dyn Residuals,
    params: &[FitParam],
    settings: &FitSettings,
    observer: Option<&(dyn Fn(FitProgress) + Sync)>,
) -> Result<FitResult, FitError> {
    driver::run(problem, params, settings, observer, Quantity::Displacement)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// r_i = y_i − a·sin(t_i), displacements of a few mm.
    struct Sine {
        t: Vec<f64>,
        y: Vec<f64>,
    }

    impl Residuals for Sine {
        fn len(&self) -> usize {
            self.t.len()
        }
        fn residuals(&self, a: &[f64], sink: &mut dyn FnMut(usize, f64)) -> Result<(), String> {
            for (i, (t, y)) in self.t.iter().zip(&self.y).enumerate() {
                sink(i, y - a[0] * t.sin());
            }
            Ok(())
        }
    }

    #[test]
    fn a_joint_displacement_problem_is_fitted_with_s_in_mm2() {
        let t: Vec<f64> = (0..300).map(|i| i as f64 * 0.05).collect();
        let y = t
            .iter()
            .enumerate()
            .map(|(i, t)| 3e-3 * t.sin() + 1e-5 * ((i * 7919 % 13) as f64 - 6.0))
            .collect();
        let problem = Sine { t, y };
        let params = [FitParam::new("a", 1e-3).bounds(0.0, 1e-2)];
        let fit =
            fit_trajectory_residuals(&problem, &params, &FitSettings::default(), None).unwrap();
        let a = fit.value("a").unwrap();
        assert!((a / 3e-3 - 1.0).abs() < 1e-3, "a = {a}");
        let s = fit.s_mm2.unwrap();
        assert!((s - fit.rss / fit.n_points as f64 * 1e6).abs() <= 1e-12 * s.max(1e-30));
        assert!(fit.convergence.converged());
    }
}
