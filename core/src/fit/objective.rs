//! The objective every optimiser sees: residuals of free parameters, with failures turned into
//! penalties, evaluations counted and progress reported.
//!
//! A fit problem implements [`Residuals`]: given the user values of the free parameters it
//! streams its residuals to a sink (no residual vector is allocated for a plain cost). The
//! [`Objective`] maps internal coordinates through the bound transforms, scores the mean
//! squared residual, and counts every evaluation and every failure in its [`Tally`], which
//! the fit's observer ([`super::observer::FitObserver`]) reads for the progress display.
//! It keeps the residuals of the fit's start and latest accepted point
//! ([`super::kept_points`]) and answers a second asking at them without evaluating again.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

use argmin::core::{CostFunction, Error as ArgminError};
use nalgebra::DMatrix;

use super::kept_points::{Kept, KeptPoints};
use super::transform::BoundTransform;

/// A least-squares problem: residuals as a function of the free parameters' user values.
pub trait Residuals: Sync {
    /// Number of residuals.
    fn len(&self) -> usize;

    /// Whether there are no residuals.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Stream the residuals at free values `x` to `sink(i, r_i)`, in any order, each once;
    /// an error (a failed simulation, a model error) as text.
    fn residuals(&self, x: &[f64], sink: &mut dyn FnMut(usize, f64)) -> Result<(), String>;

    /// The residuals at free values `x` written to `out` (residual i to `out[i]`), and their
    /// sum of squares added up in the order [`Residuals::residuals`] streams them. The default
    /// streams them; a problem may write them directly, with the same values and the same
    /// sum to the bit (a call per residual through a `dyn` sink was 3 % of a discovery).
    fn residuals_into(&self, x: &[f64], out: &mut [f64]) -> Result<f64, String> {
        let mut rss = 0.0;
        self.residuals(x, &mut written_and_summed(out, &mut rss))?;
        Ok(rss)
    }

    /// The exact Jacobian `∂r_i/∂x_j` at free values `x`, written to `jac` (`len` × free),
    /// when the problem can give it; `None` (the default): the fitter differences the
    /// residuals instead.
    fn jacobian(&self, _x: &[f64], _jac: &mut DMatrix<f64>) -> Option<Result<(), String>> {
        None
    }

    /// The residuals at free values `x` computed more accurately than [`Residuals::residuals`]
    /// (a simulation integrated to a tighter tolerance: see
    /// [`super::residual_jacobian::error_settings`]), for the Jacobian behind the standard
    /// errors; streamed as `residuals` streams them. `None` (the default): the fit's own
    /// residuals are accurate enough.
    fn precise_residuals(
        &self,
        _x: &[f64],
        _sink: &mut dyn FnMut(usize, f64),
    ) -> Option<Result<(), String>> {
        None
    }

    /// Told ahead that the residuals are about to be asked at each of the free values
    /// `points` (a Jacobian's difference columns, in parallel): a problem may prepare what
    /// they share. Nothing it does may change what [`Residuals::residuals`] returns. The
    /// default does nothing.
    fn prefetch(&self, _points: &[Vec<f64>]) {}

    /// Samples over which the residuals are known to be correlated, whatever their own
    /// autocorrelation shows (a derivative filter's window, when the model reads its output):
    /// the blocks of the robust standard errors are at least twice this long. 1 (the
    /// default): nothing known beyond the residuals.
    fn correlation_span(&self) -> usize {
        1
    }
}

/// ln of the cost that stands for a failed evaluation in the optimisers (cost 1e300).
pub const PENALTY_LN_COST: f64 = 690.775_527_898_213_7;

pub(super) fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A residual sink that writes residual `i` to `out[i]` (none past its end) and adds its
/// square to `rss`, in the order the residuals come.
pub(super) fn written_and_summed<'o>(
    out: &'o mut [f64],
    rss: &'o mut f64,
) -> impl FnMut(usize, f64) + 'o {
    move |i, r| {
        *rss += r * r;
        if let Some(slot) = out.get_mut(i) {
            *slot = r;
        }
    }
}

/// Whether two value vectors are the same bit for bit: the test by which a fit's kept
/// residuals and a sum's kept contributions are found again.
pub(super) fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// The counts of a fit's evaluations, shared (behind an `Arc`) by its [`Objective`] and the
/// observer that shows them.
#[derive(Debug)]
pub struct Tally {
    evaluations: AtomicU64,
    failures: AtomicU64,
    last_failure: Mutex<Option<String>>,
    best: Mutex<f64>,
}

impl Tally {
    /// Evaluations so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations.load(Ordering::Relaxed)
    }

    /// Lowest mean squared residual of any evaluation so far (infinite before the first).
    pub fn best(&self) -> f64 {
        *lock(&self.best)
    }
}

/// The objective of a fit in internal coordinates.
pub struct Objective<'a> {
    problem: &'a dyn Residuals,
    transforms: Vec<BoundTransform>,
    tally: Arc<Tally>,
    kept: KeptPoints,
}

impl<'a> Objective<'a> {
    /// The objective of `problem` with one transform per free parameter.
    pub fn new(problem: &'a dyn Residuals, transforms: Vec<BoundTransform>) -> Self {
        Objective {
            problem,
            transforms,
            tally: Arc::new(Tally {
                evaluations: AtomicU64::new(0),
                failures: AtomicU64::new(0),
                last_failure: Mutex::new(None),
                best: Mutex::new(f64::INFINITY),
            }),
            kept: KeptPoints::default(),
        }
    }

    /// The counts of evaluations, to share with an observer.
    pub fn tally(&self) -> Arc<Tally> {
        Arc::clone(&self.tally)
    }

    /// Number of free parameters.
    pub fn dim(&self) -> usize {
        self.transforms.len()
    }

    /// Number of residuals.
    pub fn len(&self) -> usize {
        self.problem.len()
    }

    /// The problem's [`Residuals::correlation_span`].
    pub fn correlation_span(&self) -> usize {
        self.problem.correlation_span()
    }

    /// The transforms of the free parameters.
    pub fn transforms(&self) -> &[BoundTransform] {
        &self.transforms
    }

    /// Evaluations so far.
    pub fn evaluations(&self) -> u64 {
        self.tally.evaluations()
    }

    /// Failed evaluations so far.
    pub fn failures(&self) -> u64 {
        self.tally.failures.load(Ordering::Relaxed)
    }

    /// The last failure's message.
    pub fn last_failure(&self) -> Option<String> {
        lock(&self.tally.last_failure).clone()
    }

    /// User values of the free parameters at internal coordinates `u`.
    pub fn to_user(&self, u: &[f64]) -> Vec<f64> {
        self.transforms
            .iter()
            .zip(u)
            .map(|(t, &u)| t.to_user(u))
            .collect()
    }

    /// [`Residuals::prefetch`] at the internal coordinates `points`.
    pub fn prefetch_internal(&self, points: &[Vec<f64>]) {
        let user: Vec<Vec<f64>> = points.iter().map(|u| self.to_user(u)).collect();
        self.problem.prefetch(&user);
    }

    /// [`Residuals::prefetch`] at the user values `points`.
    pub fn prefetch_user(&self, points: &[Vec<f64>]) {
        self.problem.prefetch(points);
    }

    /// Evaluate at user values `x`, streaming residuals to `sink`; `None` on failure (counted
    /// and remembered). Returns the residual sum of squares. At a kept point ([`Kept`]) the
    /// kept residuals are streamed instead, and no evaluation is counted.
    pub fn eval_user(&self, x: &[f64], sink: &mut dyn FnMut(usize, f64)) -> Option<f64> {
        if let Some(rss) = self.kept.recall(x, sink) {
            return Some(rss);
        }
        self.counted(|| {
            let mut rss = 0.0;
            let outcome = self.problem.residuals(x, &mut |i, r| {
                rss += r * r;
                sink(i, r);
            });
            outcome.map(|()| rss)
        })
    }

    /// Residuals at user values `x` written to `out`; the residual sum of squares. As
    /// [`Objective::eval_user`], through [`Residuals::residuals_into`].
    pub fn residuals_user(&self, x: &[f64], out: &mut [f64]) -> Option<f64> {
        let write = &mut |i: usize, r: f64| {
            if let Some(slot) = out.get_mut(i) {
                *slot = r;
            }
        };
        if let Some(rss) = self.kept.recall(x, write) {
            return Some(rss);
        }
        self.counted(|| self.problem.residuals_into(x, out))
    }

    /// One evaluation (`evaluate`: the residual sum of squares, or the failure) counted, a
    /// failure remembered, the lowest mean square kept; the sum of squares, `None` on failure.
    fn counted(&self, evaluate: impl FnOnce() -> Result<f64, String>) -> Option<f64> {
        let tally = &*self.tally;
        tally.evaluations.fetch_add(1, Ordering::Relaxed);
        let (outcome, rss) = match evaluate() {
            Ok(rss) => (Ok(()), rss),
            Err(e) => (Err(e), f64::NAN),
        };
        if self.failed(outcome, rss) {
            return None;
        }
        let mean = rss / self.len().max(1) as f64;
        let mut best = lock(&tally.best);
        if mean < *best {
            *best = mean;
        }
        Some(rss)
    }

    /// Keep the residuals `residuals` (sum of squares `rss`) at user values `x` as the fit's
    /// point `which`, to answer the next asking at `x` with.
    pub fn keep(&self, which: Kept, x: Vec<f64>, rss: f64, residuals: Vec<f64>) {
        self.kept.keep(which, x, rss, residuals);
    }

    /// Evaluate at user values `x` and keep the residuals as the fit's point `which`; the
    /// residual sum of squares, `None` on failure.
    pub fn evaluate_kept(&self, which: Kept, x: &[f64]) -> Option<f64> {
        let mut residuals = vec![0.0; self.len()];
        let rss = self.residuals_user(x, &mut residuals)?;
        self.keep(which, x.to_vec(), rss, residuals);
        Some(rss)
    }

    /// The problem's precise residuals ([`Residuals::precise_residuals`]) at user values `x`
    /// written to `out`: `None` when the problem has none, else their sum of squares (`None`
    /// on failure, counted and remembered).
    pub fn precise_residuals_user(&self, x: &[f64], out: &mut [f64]) -> Option<Option<f64>> {
        let mut rss = 0.0;
        let outcome = self.problem.precise_residuals(x, &mut |i, r| {
            rss += r * r;
            if let Some(slot) = out.get_mut(i) {
                *slot = r;
            }
        })?;
        self.tally.evaluations.fetch_add(1, Ordering::Relaxed);
        if self.failed(outcome, rss) {
            return Some(None);
        }
        Some(Some(rss))
    }

    /// Whether an evaluation's `outcome` (with residual sum of squares `rss`) failed: an
    /// error or a residual that is not finite, counted and remembered.
    fn failed(&self, outcome: Result<(), String>, rss: f64) -> bool {
        let failure = match outcome {
            Err(e) => Some(e),
            Ok(()) if !rss.is_finite() => Some("a residual is not finite".to_string()),
            Ok(()) => None,
        };
        let Some(reason) = failure else {
            return false;
        };
        self.tally.failures.fetch_add(1, Ordering::Relaxed);
        *lock(&self.tally.last_failure) = Some(reason);
        true
    }

    /// The exact columns of the Jacobian at user values `x`, written into `jac`: which
    /// columns are exact (finite throughout; the others are to be differenced), or `None`
    /// when the problem gives none or it failed. Counted as an evaluation.
    pub fn jacobian_user(&self, x: &[f64], jac: &mut DMatrix<f64>) -> Option<Vec<bool>> {
        let outcome = self.problem.jacobian(x, jac)?;
        self.tally.evaluations.fetch_add(1, Ordering::Relaxed);
        if let Err(e) = outcome {
            *lock(&self.tally.last_failure) = Some(e);
            return None;
        }
        let n = jac.nrows().max(1);
        let exact: Vec<bool> = jac
            .as_slice()
            .chunks_exact(n)
            .map(|c| c.iter().all(|v| v.is_finite()))
            .collect();
        exact.iter().any(|&e| e).then_some(exact)
    }

    /// The exact columns of the Jacobian in internal coordinates `u` (the user Jacobian
    /// times each transform's slope), as [`Objective::jacobian_user`].
    pub fn jacobian_internal(&self, u: &[f64], jac: &mut DMatrix<f64>) -> Option<Vec<bool>> {
        let exact = self.jacobian_user(&self.to_user(u), jac)?;
        let n = jac.nrows().max(1);
        let columns = jac.as_mut_slice().chunks_exact_mut(n);
        for (j, ((t, &uj), column)) in self.transforms.iter().zip(u).zip(columns).enumerate() {
            if exact[j] {
                let slope = t.slope(uj);
                column.iter_mut().for_each(|c| *c *= slope);
            }
        }
        Some(exact)
    }

    /// Mean squared residual at internal coordinates `u`; `None` on failure.
    pub fn cost(&self, u: &[f64]) -> Option<f64> {
        let x = self.to_user(u);
        self.eval_user(&x, &mut |_, _| {})
            .map(|rss| rss / self.len().max(1) as f64)
    }
}

/// The objective as argmin sees it: ln of the mean squared residual, so that Nelder–Mead's
/// tolerance on the spread of the simplex's costs is relative; a failure scores
/// [`PENALTY_LN_COST`].
pub struct LnCost<'o, 'a>(pub &'o Objective<'a>);

impl CostFunction for LnCost<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, u: &Self::Param) -> Result<f64, ArgminError> {
        Ok(match self.0.cost(u) {
            Some(c) => c.max(1e-300).ln().min(PENALTY_LN_COST),
            None => PENALTY_LN_COST,
        })
    }
}
