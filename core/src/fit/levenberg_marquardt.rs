//! A damped Gauss–Newton (Levenberg–Marquardt) refinement as an argmin [`Solver`].
//!
//! What is argmin's: the iteration itself — argmin's `Executor` starts the solver
//! ([`Solver::init`]), calls one [`Solver::next_iter`] per Jacobian, counts the iterations,
//! stops at `max_iters` (`TerminationReason::MaxItersReached`), shows every iteration to the
//! fit's observer ([`super::observer::FitObserver`]: the progress display, the trace) and
//! says how the run ended (`TerminationReason`, from which the fit's
//! [`Convergence`](super::result::Convergence) is read in [`super::stages`]).
//!
//! What is ours, and why:
//! - the update. argmin's `GaussNewton` takes undamped steps, which diverge from a start that
//!   is not already close (and our bound transforms flatten the residuals near a bound). This
//!   is Nielsen's update of the damping λ with Marquardt's diagonal scaling, in the
//!   transforms' internal coordinates:
//!
//!   ```text
//!   (JᵀJ + λ·diag(JᵀJ))·δ = −Jᵀr,   accept if the cost drops, ρ = actual / predicted drop
//!   ```
//!
//!   Steps are shortened to at most two scales of any parameter.
//! - failed evaluations. argmin's `Operator` and `Jacobian` return a `Result` whose error ends
//!   the run; here a trial point whose simulation fails is a rejected step (λ grows), so the
//!   solver evaluates through the fit's [`Objective`] ([`LeastSquares`]), which counts a failure
//!   and answers `None`.
//! - the Jacobian. It is exact where the problem gives one
//!   ([`super::objective::Residuals::jacobian`]: force fits of built-ins without state); else
//!   its difference steps start at `fd_step` and grow above the residuals' noise, measured once
//!   (see [`super::residual_jacobian`]): a column that is mostly integrator noise gives a step
//!   that raises the cost at every damping, and the refinement stopped far from the optimum.
//!   The steps and the noise are the solver's memory between iterations.
//! - the stopping rules and the state. A small relative change of the cost, residuals
//!   orthogonal to the Jacobian, no step at any damping, a parameter pinned on its bound, and
//!   the stall rule ([`small_change`]) end a run with argmin's `SolverConverged` or, for a
//!   stall, its `SolverExit` with [`STALLED`], their numbers in words in the state
//!   ([`LmState`]: argmin's `IterState` has no room for the residuals, the damping or the
//!   words).

use argmin::core::{Error as ArgminError, Problem, Solver, TerminationReason, KV};
use nalgebra::{DMatrix, DVector, Dyn, MatrixView};

use super::kept_points::Kept;
use super::lm_state::LmState;
use super::objective::Objective;
use super::residual_jacobian::{forward_difference, residual_noise, StepFloor};
use super::transform::BoundTransform;

/// Longest step in internal coordinates (units of the parameters' scales).
const MAX_STEP: f64 = 2.0;

/// Longest finite-difference step, in scales, that a column may grow to when the residuals
/// are noisy (see [`super::residual_jacobian`]).
pub const MAX_FD_STEP: f64 = 0.1;

/// Probe of the residuals' noise, in scales: far below any step, far above rounding.
pub const NOISE_PROBE: f64 = 1e-6;

/// Largest damping before the refinement decides no step can lower the cost.
const LAMBDA_MAX: f64 = 1e16;

/// Largest cosine between the residuals and a column of an exact Jacobian (of a parameter
/// away from its bounds) at which a step that lowers the cost by less than `tol` ends the
/// refinement as converged; above it the refinement has stalled (see [`small_change`]).
/// Below it, cosines of 4e-3–2e-2 are common at such stops among nearly interchangeable
/// effects (a power law beside a gated one), and a simplex from there found nothing better
/// that changed a discovery verdict, at 35 % more work.
const STALL_COSINE: f64 = 0.1;

/// argmin's `SolverExit` reason of a refinement that stalled ([`small_change`]).
pub const STALLED: &str = "stalled";

/// argmin's `SolverExit` reason of a refinement whose start cannot be evaluated.
pub const START_FAILS: &str = "the start of the refinement cannot be evaluated";

/// How a refinement ends by one of its own rules: argmin's reason, and the rule in words.
type End = (TerminationReason, String);

/// How a refinement whose last step lowered the cost by the fraction `drop` (< `tol`) ends.
/// With an exact Jacobian, whose largest cosine with the residuals was `cosine` before the
/// step (over the parameters away from their bounds), a cosine above [`STALL_COSINE`] means
/// the linearisation promised a drop of at least cosine² (1 %) and the step got less than
/// `tol`: a crawl along a curved valley, not an optimum (the fit of `power_law +
/// jamming_on_off` from its defaults crawled to n_j = 1 at cosine 0.17 and an RMS 12 % above
/// the optimum this way), reported as a stall ([`STALLED`]) so that the chain goes on.
/// With differences the cosine carries their noise and is not judged.
fn small_change(drop: f64, tol: f64, cosine: Option<f64>) -> End {
    match cosine {
        Some(c) if c > STALL_COSINE => (
            TerminationReason::SolverExit(STALLED.into()),
            format!(
                "relative cost change {drop:.1e} < {tol:.1e} with the residuals at cosine \
                 {c:.1e} to the Jacobian"
            ),
        ),
        _ => (
            TerminationReason::SolverConverged,
            format!("relative cost change {drop:.1e} < {tol:.1e}"),
        ),
    }
}

/// A test of internal coordinates that stops a refinement (see [`LeastSquares`]).
pub type BoundStop<'a> = Option<&'a dyn Fn(&[f64]) -> bool>;

/// The problem a refinement solves, as argmin's `Executor` holds it: the fit's objective, and
/// a test that stops the refinement as soon as an accepted point satisfies it (a parameter on
/// a bound, where its map is flat and further iterations only creep: the caller decides what
/// to do from there).
pub struct LeastSquares<'o, 'a> {
    /// The residuals, evaluated in internal coordinates.
    pub obj: &'o Objective<'a>,
    /// Stop on a bound (trajectory fits), or not.
    pub stop_at_bound: BoundStop<'o>,
}

/// The problem inside argmin's `Problem`.
fn least_squares<'p, 'o, 'a>(
    problem: &'p Problem<LeastSquares<'o, 'a>>,
) -> Result<&'p LeastSquares<'o, 'a>, ArgminError> {
    problem
        .problem
        .as_ref()
        .ok_or_else(|| ArgminError::msg("the refinement was given no problem"))
}

/// The Levenberg–Marquardt solver: its settings and its memory between iterations (the
/// Jacobian, its difference steps and their floor above the residuals' noise).
pub struct LevenbergMarquardt {
    /// A step that lowers the cost by less than this fraction ends the refinement.
    tol: f64,
    /// First finite-difference step, in scales.
    fd_step: f64,
    /// The residuals of the last trial point.
    trial: Vec<f64>,
    jac: DMatrix<f64>,
    steps: Vec<f64>,
    /// The parameters whose columns the last Jacobian differenced (the others were exact).
    differenced: Vec<usize>,
    /// The difference steps' floor above the residuals' noise, measured once (lazily: an
    /// exact Jacobian needs no noise).
    floor: Option<StepFloor>,
}

impl LevenbergMarquardt {
    /// A refinement that stops when an accepted step lowers the cost by less than the
    /// fraction `tol` (or the residuals are orthogonal to the Jacobian to `√tol·1e-2`), its
    /// difference steps starting at `fd_step` scales.
    pub fn new(tol: f64, fd_step: f64) -> Self {
        LevenbergMarquardt {
            tol,
            fd_step,
            trial: Vec::new(),
            jac: DMatrix::zeros(0, 0),
            steps: Vec::new(),
            differenced: Vec::new(),
            floor: None,
        }
    }
}

impl Solver<LeastSquares<'_, '_>, LmState> for LevenbergMarquardt {
    fn name(&self) -> &str {
        "Levenberg–Marquardt"
    }

    /// Evaluate the start; a start that fails ends the run ([`START_FAILS`]).
    fn init(
        &mut self,
        problem: &mut Problem<LeastSquares<'_, '_>>,
        mut state: LmState,
    ) -> Result<(LmState, Option<KV>), ArgminError> {
        let obj = least_squares(problem)?.obj;
        let (n, p) = (obj.len(), obj.dim());
        state.residuals = vec![0.0; n];
        self.trial = vec![0.0; n];
        self.jac = DMatrix::zeros(n, p);
        self.steps = vec![self.fd_step; p];
        self.floor = None;
        let start = obj.residuals_user(&obj.to_user(&state.u), &mut state.residuals);
        Ok(match start {
            Some(rss) => {
                state.rss = rss;
                (state, None)
            }
            None => {
                let reason = TerminationReason::SolverExit(START_FAILS.into());
                (state.ended(reason, START_FAILS.into()), None)
            }
        })
    }

    /// One Jacobian, then one accepted step (the damping raised until a step lowers the
    /// cost), or the end.
    fn next_iter(
        &mut self,
        problem: &mut Problem<LeastSquares<'_, '_>>,
        mut state: LmState,
    ) -> Result<(LmState, Option<KV>), ArgminError> {
        let ls = least_squares(problem)?;
        let all_exact = self.jacobian(ls.obj, &state.u, &state.residuals);
        let (a, g) = normal_equations(&self.jac, &state.residuals);
        let (cosine, inner_cosine) = cosines(ls.obj.transforms(), &state, &a, &g);
        let end = if state.rss.sqrt() == 0.0 || cosine < self.tol.sqrt() * 1e-2 {
            Some((
                TerminationReason::SolverConverged,
                format!("residuals orthogonal to the Jacobian (cosine {cosine:.1e})"),
            ))
        } else {
            self.step(ls, &mut state, (&a, &g), all_exact.then_some(inner_cosine))
        };
        Ok(match end {
            Some((reason, words)) => (state.ended(reason, words), None),
            None => (state, None),
        })
    }
}

/// JᵀJ and Jᵀr, each entry the very number nalgebra gives from a transposed copy of J
/// (`&J.transpose() * &J`, `&J.transpose() * DVector::from(r)`) without copying a record-long
/// matrix and vector each iteration. nalgebra multiplies matrices of more than
/// [`SMALL_DIM`] rows and columns with matrixmultiply, which reads any strides: there it is
/// given Jᵀ as a view of J's own storage. Smaller ones it multiplies column by column
/// (`gemv`), each entry a sum in row order from the first product: [`ordered_dots`] takes
/// those sums in the same order (nalgebra's `gemv` on a row-strided view reads out of
/// bounds, so the view is not given to it).
fn normal_equations(jac: &DMatrix<f64>, r: &[f64]) -> (DMatrix<f64>, DVector<f64>) {
    let (n, p) = jac.shape();
    let columns: Vec<&[f64]> = jac.as_slice().chunks_exact(n.max(1)).take(p).collect();
    if p > SMALL_DIM && n > SMALL_DIM {
        let jt = MatrixView::from_slice_with_strides_generic(
            jac.as_slice(),
            Dyn(p),
            Dyn(n),
            Dyn(n),
            Dyn(1),
        );
        return (jt * jac, DVector::from_vec(ordered_dots(&columns, r)));
    }
    match p {
        1 => small_normal::<1>(&columns, r),
        2 => small_normal::<2>(&columns, r),
        3 => small_normal::<3>(&columns, r),
        4 => small_normal::<4>(&columns, r),
        5 => small_normal::<5>(&columns, r),
        _ => {
            // Few rows, many columns: each column of JᵀJ as nalgebra's `gemv` sums it.
            let mut a = DMatrix::zeros(p, p);
            for (j, column) in columns.iter().enumerate() {
                a.column_mut(j)
                    .copy_from_slice(&ordered_dots(&columns, column));
            }
            (a, DVector::from_vec(ordered_dots(&columns, r)))
        }
    }
}

/// JᵀJ and Jᵀr of the `P` columns `columns`, each entry summed in row order from the first
/// product as nalgebra's `gemv` sums it, all in one pass over the rows (JᵀJ's upper
/// triangle, mirrored: a product is the same either way round).
fn small_normal<const P: usize>(columns: &[&[f64]], r: &[f64]) -> (DMatrix<f64>, DVector<f64>) {
    let n = r.len();
    let (mut a, mut g) = ([[0.0; P]; P], [0.0; P]);
    if n > 0 && columns.len() == P && columns.iter().all(|c| c.len() >= n) {
        let cols: [&[f64]; P] = std::array::from_fn(|i| &columns[i][..n]);
        for i in 0..P {
            g[i] = cols[i][0] * r[0];
            for j in i..P {
                a[i][j] = cols[i][0] * cols[j][0];
            }
        }
        for k in 1..n {
            let x: [f64; P] = std::array::from_fn(|i| cols[i][k]);
            for i in 0..P {
                g[i] += x[i] * r[k];
                for j in i..P {
                    a[i][j] += x[i] * x[j];
                }
            }
        }
    }
    let a = DMatrix::from_fn(P, P, |i, j| if i <= j { a[i][j] } else { a[j][i] });
    (a, DVector::from_row_slice(&g))
}

/// nalgebra's bound (in rows and columns) above which it multiplies with matrixmultiply.
const SMALL_DIM: usize = 5;

/// Σ_k c[k]·v[k] for each column c of `columns`, summed in k order from the first product
/// (0 for no rows), up to five columns in one pass over the rows.
fn ordered_dots(columns: &[&[f64]], v: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(columns.len());
    for group in columns.chunks(5) {
        match group.len() {
            1 => out.extend(dots::<1>(group, v)),
            2 => out.extend(dots::<2>(group, v)),
            3 => out.extend(dots::<3>(group, v)),
            4 => out.extend(dots::<4>(group, v)),
            _ => out.extend(dots::<5>(group, v)),
        }
    }
    out
}

/// [`ordered_dots`] of exactly `N` columns, their sums side by side in registers.
fn dots<const N: usize>(columns: &[&[f64]], v: &[f64]) -> [f64; N] {
    let n = v.len();
    let mut acc = [0.0; N];
    if n == 0 || columns.len() != N || columns.iter().any(|c| c.len() < n) {
        return acc;
    }
    let cols: [&[f64]; N] = std::array::from_fn(|i| &columns[i][..n]);
    for i in 0..N {
        acc[i] = cols[i][0] * v[0];
    }
    for k in 1..n {
        for i in 0..N {
            acc[i] += cols[i][k] * v[k];
        }
    }
    acc
}

/// The largest cosine between the residuals and a column of the Jacobian (`a` = JᵀJ,
/// `g` = Jᵀr), over all parameters and over those away from their bounds (where the map is
/// not flat: a parameter pressing on its bound has a large cosine that no step can use).
fn cosines(
    transforms: &[BoundTransform],
    state: &LmState,
    a: &DMatrix<f64>,
    g: &DVector<f64>,
) -> (f64, f64) {
    let rnorm = state.rss.sqrt();
    let u = &state.u;
    let cosine = |inner: bool| {
        (0..u.len())
            .filter(|&j| a[(j, j)] > 0.0 && !(inner && transforms[j].saturated(u[j])))
            .map(|j| g[j].abs() / (a[(j, j)].sqrt() * rnorm))
            .fold(0.0_f64, f64::max)
    };
    (cosine(false), cosine(true))
}

impl LevenbergMarquardt {
    /// The Jacobian at `u` (residuals `r`): exact where the problem gives one, else
    /// differences whose steps grow above the residuals' noise; non-finite entries zeroed.
    /// Whether it is all exact.
    fn jacobian(&mut self, obj: &Objective, u: &[f64], r: &[f64]) -> bool {
        let p = u.len();
        let exact = obj
            .jacobian_internal(u, &mut self.jac)
            .unwrap_or_else(|| vec![false; p]);
        let all_exact = exact.iter().all(|&e| e);
        self.differenced = (0..p).filter(|&j| !exact[j]).collect();
        if !all_exact {
            if self.floor.is_none() {
                self.prefetch_first(obj, u);
            }
            let fd_step = self.fd_step;
            let floor = self.floor.get_or_insert_with(|| StepFloor {
                noise: residual_noise(u, r, &vec![NOISE_PROBE; p], &|point, out| {
                    obj.residuals_user(&obj.to_user(point), out).is_some()
                })
                .unwrap_or(0.0),
                max: vec![MAX_FD_STEP.max(fd_step); p],
            });
            forward_difference(
                u,
                r,
                &mut self.steps,
                floor,
                &|_, _| false,
                &|point, out| obj.residuals_user(&obj.to_user(point), out).is_some(),
                &exact,
                &mut self.jac,
                &|points| obj.prefetch_internal(points),
            );
        }
        for v in self.jac.as_mut_slice() {
            if !v.is_finite() {
                *v = 0.0;
            }
        }
        all_exact
    }

    /// One iteration's step: the damping raised until a step lowers the cost, then lowered
    /// (Nielsen). How the refinement ends, if it does here: stopped on a bound, a small
    /// change (below `tol`; `inner_cosine` as [`small_change`] reads it), or no step lowering
    /// the cost at any damping.
    fn step(
        &mut self,
        ls: &LeastSquares,
        state: &mut LmState,
        (a, g): (&DMatrix<f64>, &DVector<f64>),
        inner_cosine: Option<f64>,
    ) -> Option<End> {
        let dmax = (0..state.u.len())
            .map(|j| a[(j, j)])
            .fold(0.0_f64, f64::max);
        let floor = (1e-12 * dmax).max(f64::MIN_POSITIVE);
        let (cand, new_rss, rho, step_size) = loop {
            if let Some(accepted) = self.tried(ls.obj, state, (a, g), floor) {
                break accepted;
            }
            state.lambda *= state.nu;
            state.nu *= 2.0;
            if state.lambda > LAMBDA_MAX {
                let words = "no step lowers the cost any further".into();
                return Some((TerminationReason::SolverConverged, words));
            }
        };
        let drop = (state.rss - new_rss) / state.rss;
        state.u = cand;
        state.rss = new_rss;
        std::mem::swap(&mut state.residuals, &mut self.trial);
        // Kept: the fit compares its end with its start and takes its errors there.
        let x = ls.obj.to_user(&state.u);
        ls.obj
            .keep(Kept::Accepted, x, new_rss, state.residuals.clone());
        state.lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
        state.nu = 2.0;
        if ls.stop_at_bound.is_some_and(|pinned| pinned(&state.u)) {
            let words = "stopped on a parameter's bound".into();
            return Some((TerminationReason::SolverConverged, words));
        }
        (drop < self.tol || step_size < 1e-12).then(|| small_change(drop, self.tol, inner_cosine))
    }

    /// The step at the current damping (diagonal at least `floor`), if it lowers the cost
    /// with a positive gain ratio: the point, its cost, the ratio and the step's length.
    fn tried(
        &mut self,
        obj: &Objective,
        state: &LmState,
        (a, g): (&DMatrix<f64>, &DVector<f64>),
        floor: f64,
    ) -> Option<(Vec<f64>, f64, f64, f64)> {
        let mut m = a.clone();
        for j in 0..state.u.len() {
            m[(j, j)] += state.lambda * a[(j, j)].max(floor);
        }
        let delta = m.cholesky()?.solve(&(-g));
        // A step of at most MAX_STEP scales: a long one would run into the flat, saturated
        // part of a bound transform and stall there.
        let longest = delta.amax();
        let delta = if longest > MAX_STEP {
            delta * (MAX_STEP / longest)
        } else {
            delta
        };
        let cand: Vec<f64> = state
            .u
            .iter()
            .zip(delta.iter())
            .map(|(a, b)| a + b)
            .collect();
        self.prefetch_trial(obj, &cand);
        let new_rss = obj.residuals_user(&obj.to_user(&cand), &mut self.trial)?;
        let predicted = -2.0 * g.dot(&delta) - delta.dot(&(a * &delta));
        let rho = (state.rss - new_rss) / predicted;
        (new_rss < state.rss && rho > 0.0).then_some((cand, new_rss, rho, delta.amax()))
    }

    /// Ahead of the first Jacobian at `u`: the two points of the noise probe
    /// ([`residual_noise`]) and the first points of the difference columns, handed to the
    /// problem at once, as [`LevenbergMarquardt::prefetch_trial`] hands the next ones.
    fn prefetch_first(&self, obj: &Objective, u: &[f64]) {
        let probe = |sign: f64| u.iter().map(|u| u + sign * NOISE_PROBE).collect();
        let points: Vec<Vec<f64>> = [probe(1.0), probe(-1.0)]
            .into_iter()
            .chain(self.columns_at(u))
            .collect();
        obj.prefetch_internal(&points);
    }

    /// The first point of each differenced column of a Jacobian at `u`: the parameter moved
    /// by its step, as [`forward_difference`] moves it.
    fn columns_at<'s>(&'s self, u: &'s [f64]) -> impl Iterator<Item = Vec<f64>> + 's {
        self.differenced.iter().map(move |&j| {
            let mut point = u.to_vec();
            point[j] = u[j] + self.steps[j].abs();
            point
        })
    }

    /// Ahead of evaluating the trial point `cand`: it and the first points of the difference
    /// columns the next Jacobian takes there if the step is accepted (the last Jacobian's
    /// differenced parameters, each moved by its step as [`forward_difference`] moves it),
    /// handed to the problem at once ([`Objective::prefetch_internal`]). A problem that
    /// integrates state prepares them side by side, where the trial alone would be
    /// integrated by itself and the columns after it; a rejected step wastes the columns.
    fn prefetch_trial(&self, obj: &Objective, cand: &[f64]) {
        if self.differenced.is_empty() {
            return;
        }
        let points: Vec<Vec<f64>> = std::iter::once(cand.to_vec())
            .chain(self.columns_at(cand))
            .collect();
        obj.prefetch_internal(&points);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// JᵀJ and Jᵀr from J's own storage are those of a transposed copy to the bit, with few
    /// parameters (nalgebra's own loops) and many (matrixmultiply).
    #[test]
    fn normal_equations_are_those_of_a_transposed_copy() {
        for (n, p) in [
            (1001, 1),
            (1001, 3),
            (1001, 5),
            (1001, 6),
            (1001, 12),
            (4, 7),
            (1, 2),
        ] {
            let jac = DMatrix::from_fn(n, p, |k, j| ((k * 7 + j * 13) as f64 * 0.37).sin() * 1e3);
            let r: Vec<f64> = (0..n).map(|k| (k as f64 * 0.11).cos()).collect();
            let (a, g) = normal_equations(&jac, &r);
            let jt = jac.transpose();
            let (a0, g0) = (&jt * &jac, &jt * DVector::from_column_slice(&r));
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(a.as_slice()),
                bits(a0.as_slice()),
                "JᵀJ, {p} parameters"
            );
            assert_eq!(
                bits(g.as_slice()),
                bits(g0.as_slice()),
                "Jᵀr, {p} parameters"
            );
        }
    }
}
