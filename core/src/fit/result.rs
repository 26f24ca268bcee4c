//! What a fit reports: values with standard errors (robust to correlated residuals) and
//! correlations, goodness of fit, information criteria, the work done, and whether it
//! converged.

use serde::Serialize;

use super::fit_param::BoundSide;

/// How a fit ended.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum Convergence {
    /// The last stage met its stopping rule.
    Converged {
        /// Which rule.
        reason: String,
    },
    /// The last stage ran out of iterations: the values may not be the optimum.
    MaxIterations,
    /// The last stage stopped making progress although its exact gradient says the cost can
    /// still fall: the values are not an optimum (a crawl along a curved valley).
    Stalled {
        /// Where and how.
        reason: String,
    },
    /// The optimiser failed.
    Failed {
        /// Why.
        reason: String,
    },
}

impl Convergence {
    /// Whether the fit converged.
    pub fn converged(&self) -> bool {
        matches!(self, Convergence::Converged { .. })
    }
}

/// The solver stage a fit is in, for progress reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SolverStage {
    /// Particle swarm.
    ParticleSwarm,
    /// Nelder–Mead.
    NelderMead,
    /// Levenberg–Marquardt.
    LevenbergMarquardt,
    /// The final Jacobian for the standard errors.
    Errors,
}

/// Progress of a running fit, passed to the observer at the start and after every iteration
/// of each solver stage, and when the standard errors' stage begins.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitProgress {
    /// The stage running.
    pub stage: SolverStage,
    /// Evaluations of the model so far (simulations, for trajectory fits).
    pub evaluations: u64,
    /// Lowest cost so far: mean squared residual (N² or m²).
    pub best_cost: f64,
}

/// A fitted parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FittedParam {
    /// Name.
    pub name: String,
    /// Best value.
    pub value: f64,
    /// Standard error (infinite or NaN if the data do not determine the parameter; 0 if
    /// fixed), robust to residuals correlated within a block ([`ErrorBlocks`]).
    pub std_error: f64,
    /// The classical standard error, `s²·(JᵀJ)⁻¹`, which takes every residual as
    /// independent: too small when they are correlated (kept for comparison).
    pub naive_std_error: f64,
    /// Held fixed.
    pub fixed: bool,
    /// The bound that holds this free parameter: it lies near the bound (within
    /// [`HELD_REACH`](super::HELD_REACH) of its box) and the data push it past: the
    /// Gauss–Newton step from the end would cross the bound. `None`: free to move either way.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub held_by: Option<BoundSide>,
    /// How far this free parameter's difference column stood above the residuals' noise
    /// (rms change over rms noise) at the longest step allowed, when that was less than
    /// [`NOISY_COLUMN`](super::NOISY_COLUMN): its standard error is then uncertain (a
    /// simulation's noise at its `rtol`). `None`: the column stood clear of the noise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noisy_column: Option<f64>,
}

impl FittedParam {
    /// A free parameter ended at `value` with standard error `std_error` (the classical one
    /// the same), held by no bound.
    pub fn free(name: &str, value: f64, std_error: f64) -> Self {
        FittedParam {
            name: name.into(),
            value,
            std_error,
            naive_std_error: std_error,
            fixed: false,
            held_by: None,
            noisy_column: None,
        }
    }

    /// A parameter held at `value` (its standard errors zero).
    pub fn held(name: &str, value: f64) -> Self {
        FittedParam {
            fixed: true,
            ..Self::free(name, value, 0.0)
        }
    }

    /// The value for a person to read: rounded to its standard error
    /// ([`crate::digits::rounded`]), a held value or one without an error to six
    /// significant digits.
    pub fn shown_value(&self) -> String {
        let error = if self.fixed { f64::NAN } else { self.std_error };
        crate::digits::rounded(self.value, error)
    }
}

/// The blocks of consecutive samples over which the standard errors' residuals were taken as
/// correlated: the cluster-robust covariance sums each block's scores before squaring them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct ErrorBlocks {
    /// Samples per block.
    pub length: usize,
    /// Number of blocks: the effective number of independent pieces of data.
    pub count: usize,
    /// Whether blocks of this length were found long enough to hold the residuals'
    /// correlation; if not, the residuals are correlated over about the whole record and
    /// the standard errors may still be too small.
    pub settled: bool,
}

/// The outcome of a fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FitResult {
    /// All parameters of the fit, free and fixed, in the order given.
    pub params: Vec<FittedParam>,
    /// Correlations of the free parameters, in their order in `params`.
    pub correlation: Vec<Vec<f64>>,
    /// The blocks behind the standard errors (`None` without free parameters).
    pub error_blocks: Option<ErrorBlocks>,
    /// Number of residuals (samples).
    pub n_points: usize,
    /// Number of free parameters.
    pub n_free: usize,
    /// Residual sum of squares (N² or m²).
    pub rss: f64,
    /// RMS residual (N, or m for trajectory fits).
    pub rms: f64,
    /// S(μ) = mean((x_exp − x_sim)²) in mm² (trajectory fits only).
    pub s_mm2: Option<f64>,
    /// Akaike information criterion, N·ln(RSS/N) + 2p.
    pub aic: f64,
    /// Bayesian information criterion, N·ln(RSS/N) + p·ln N.
    pub bic: f64,
    /// Evaluations of the model (simulations, for trajectory fits), all stages.
    pub evaluations: u64,
    /// Evaluations that failed (a simulation error, a model error, a non-finite residual)
    /// and were scored as a penalty.
    pub failures: u64,
    /// The last such failure, if any.
    pub last_failure: Option<String>,
    /// Iterations of all stages.
    pub iterations: u64,
    /// Wall time, s.
    pub wall_seconds: f64,
    /// How the fit ended.
    pub convergence: Convergence,
    /// One line per stage: what ran and how it ended.
    pub log: Vec<String>,
}

impl FitResult {
    /// The fitted parameter called `name`.
    pub fn param(&self, name: &str) -> Option<&FittedParam> {
        self.params.iter().find(|p| p.name == name)
    }

    /// The best value of `name`.
    pub fn value(&self, name: &str) -> Option<f64> {
        self.param(name).map(|p| p.value)
    }

    /// The standard error of `name`.
    pub fn std_error(&self, name: &str) -> Option<f64> {
        self.param(name).map(|p| p.std_error)
    }
}
