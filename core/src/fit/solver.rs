//! Which optimiser a fit uses, when it stops, and whether it keeps a trace of its iterations.

use std::path::PathBuf;

use derive_setters::Setters;
use serde::{Deserialize, Serialize};

use super::error::FitError;

/// The optimiser, or chain of optimisers, of a fit. Every chain ends with standard errors
/// from a finite-difference Jacobian at the best point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Solver {
    /// Levenberg–Marquardt from the start; if it does not converge, Nelder–Mead (to
    /// `presearch_tol`) then Levenberg–Marquardt again. (Nelder–Mead first was tried: on a
    /// free vibration with dry friction its large first moves left the basin that
    /// Levenberg–Marquardt, started 10 % off, finds directly.)
    #[default]
    Auto,
    /// Nelder–Mead alone (the source study's method), run to `simplex_tol`.
    NelderMead,
    /// Levenberg–Marquardt alone, from the start values.
    LevenbergMarquardt,
    /// Particle swarm over the whole bounded box (a global search), then Levenberg–Marquardt.
    ParticleSwarm,
}

impl Solver {
    /// All solvers, for listings and error messages.
    pub const ALL: [Solver; 4] = [
        Solver::Auto,
        Solver::NelderMead,
        Solver::LevenbergMarquardt,
        Solver::ParticleSwarm,
    ];
}

/// Settings of a fit, with named setters.
///
/// ```
/// use stf_core::fit::{FitSettings, Solver};
/// let s = FitSettings::default().solver(Solver::NelderMead).max_iters(200).seed(7);
/// assert_eq!(s.max_iters, 200);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Setters)]
pub struct FitSettings {
    /// The optimiser.
    pub solver: Solver,
    /// Most iterations of each stage.
    pub max_iters: u64,
    /// Levenberg–Marquardt stops when an accepted step lowers the cost by less than this
    /// fraction, or when the residuals are orthogonal to the Jacobian's columns to this
    /// level (cosine), or when no step lowers the cost.
    pub tol: f64,
    /// Nelder–Mead stops when the standard deviation of ln(cost) over the simplex falls below
    /// this (a relative spread of the costs). In [`Solver::Auto`]'s fallback the simplex stage
    /// stops at the larger of this and `presearch_tol`.
    pub simplex_tol: f64,
    /// Simplex tolerance of the Nelder–Mead stage in [`Solver::Auto`].
    pub presearch_tol: f64,
    /// Initial simplex edge, in units of each parameter's scale.
    pub simplex_step: f64,
    /// Finite-difference step of Jacobians, in units of each parameter's scale.
    pub fd_step: f64,
    /// Particles of the swarm.
    pub particles: usize,
    /// Seed of every random choice (the swarm).
    pub seed: u64,
    /// A file to which each fit appends every iteration's cost and parameters, stage by
    /// stage (see the fit's observer); none by default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[setters(strip_option)]
    pub trace: Option<PathBuf>,
    /// Whether the fit ends with its standard errors (a Jacobian at the end point and the
    /// covariance over blocks of residuals); on by default. A search that ranks many starts
    /// by their RMS leaves them out and completes the one it keeps
    /// ([`with_errors`](super::with_errors)): its parameters' errors are NaN until then.
    #[serde(skip, default = "errors_by_default")]
    pub errors: bool,
}

/// [`FitSettings::errors`] when read from a file: on.
fn errors_by_default() -> bool {
    true
}

impl Default for FitSettings {
    fn default() -> Self {
        FitSettings {
            solver: Solver::Auto,
            max_iters: 1000,
            tol: 1e-9,
            simplex_tol: 1e-8,
            presearch_tol: 1e-3,
            simplex_step: 0.1,
            fd_step: 1e-5,
            particles: 40,
            seed: 1,
            trace: None,
            errors: true,
        }
    }
}

impl FitSettings {
    /// These settings for a fit whose residuals come from a simulation integrated to
    /// relative tolerance `rtol`: the finite-difference step is at least `√rtol`, and the
    /// relative cost change that ends Levenberg–Marquardt at least `10·rtol`.
    ///
    /// The simulated x carries the integrator's relative error, which jumps as the adaptive
    /// steps change with the parameters; a forward difference over a step `h` divides that
    /// noise by `h`, and its total error is smallest near `h ≈ √noise`. With `fd_step` 1e-5
    /// and `rtol` 1e-7 the Jacobian would be mostly noise and Levenberg–Marquardt would stop
    /// far from the optimum. Likewise the cost itself is known only to a few `rtol`: the
    /// simulated x carries a global error of several `rtol` (2.7e-5 mm on a 40 mm swing, 7·rtol,
    /// on the paper's sweep), and along a long, curved valley of nearly interchangeable
    /// parameters the refinement can lower the cost by less than that for hundreds of
    /// iterations (2 115 simulations for one candidate of the bundled trajectory discovery
    /// with a limit of `rtol`, 1 139 with `10·rtol`, for 0.2 % of S).
    ///
    /// ```
    /// use stf_core::fit::FitSettings;
    /// let s = FitSettings::default().for_simulation(1e-6);
    /// assert_eq!((s.fd_step, s.tol), (1e-3, 10.0 * 1e-6));
    /// let s = FitSettings::default().for_simulation(1e-12);
    /// assert_eq!((s.fd_step, s.tol), (1e-5, 1e-9));
    /// ```
    pub fn for_simulation(mut self, rtol: f64) -> Self {
        self.fd_step = self.fd_step.max(rtol.sqrt());
        self.tol = self.tol.max(10.0 * rtol);
        self
    }

    /// Check the settings.
    pub fn check(&self) -> Result<(), FitError> {
        let pos = |v: f64| v > 0.0 && v.is_finite();
        let ok = self.max_iters > 0
            && pos(self.tol)
            && pos(self.simplex_tol)
            && pos(self.presearch_tol)
            && pos(self.simplex_step)
            && pos(self.fd_step)
            && self.fd_step < 0.5
            && self.particles >= 2;
        if ok {
            Ok(())
        } else {
            Err(FitError::BadSettings(format!(
                "need max_iters > 0, positive finite tolerances and steps, fd_step < 0.5, \
                 particles ≥ 2 (got {self:?})"
            )))
        }
    }
}
