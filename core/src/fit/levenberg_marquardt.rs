//! A damped Gauss–Newton (Levenberg–Marquardt) refinement, written with nalgebra.
//!
//! Why not argmin's `GaussNewton`: it takes undamped steps, which diverge from a start that is
//! not already close (and our bound transforms flatten the residuals near a bound), it has no
//! way to treat a failed evaluation as "step rejected", and its finite-difference Jacobian
//! would be ours anyway. This is Nielsen's update of the damping λ with Marquardt's diagonal
//! scaling, in the transforms' internal coordinates:
//!
//! ```text
//! (JᵀJ + λ·diag(JᵀJ))·δ = −Jᵀr,   accept if the cost drops, ρ = actual / predicted drop
//! ```
//!
//! Steps are shortened to at most two scales of any parameter. The Jacobian is exact where the
//! problem gives one ([`super::objective::Residuals::jacobian`]: force fits of built-ins
//! without state); else its difference steps start at `fd_step` and grow above the residuals'
//! noise, measured once (see [`super::residual_jacobian`]): a column that is mostly integrator noise
//! gives a step that raises the cost at every damping, and the refinement stopped far from
//! the optimum.

use nalgebra::{DMatrix, DVector};

use super::objective::Objective;
use super::residual_jacobian::{forward_difference, residual_noise, StepFloor};
use super::result::Convergence;

/// What the refinement did.
pub struct Refined {
    /// Best internal coordinates.
    pub u: Vec<f64>,
    /// Iterations (Jacobians computed).
    pub iterations: u64,
    /// How it ended.
    pub convergence: Convergence,
}

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

/// How a refinement whose last step lowered the cost by the fraction `drop` (< `tol`) ends.
/// With an exact Jacobian, whose largest cosine with the residuals was `cosine` before the
/// step (over the parameters away from their bounds), a cosine above [`STALL_COSINE`] means
/// the linearisation promised a drop of at least cosine² (1 %) and the step got less than
/// `tol`: a crawl along a curved valley, not an optimum (the fit of `power_law +
/// jamming_on_off` from its defaults crawled to n_j = 1 at cosine 0.17 and an RMS 12 % above
/// the optimum this way), reported as [`Convergence::Stalled`] so that the chain goes on.
/// With differences the cosine carries their noise and is not judged.
fn small_change(drop: f64, tol: f64, cosine: Option<f64>) -> Convergence {
    match cosine {
        Some(c) if c > STALL_COSINE => Convergence::Stalled {
            reason: format!(
                "relative cost change {drop:.1e} < {tol:.1e} with the residuals at cosine \
                 {c:.1e} to the Jacobian"
            ),
        },
        _ => Convergence::Converged {
            reason: format!("relative cost change {drop:.1e} < {tol:.1e}"),
        },
    }
}

/// A test of internal coordinates that stops a refinement (see [`refine`]).
pub type BoundStop<'a> = Option<&'a dyn Fn(&[f64]) -> bool>;

/// Refine `u0` by Levenberg–Marquardt; stops after `max_iters` Jacobians, or as soon as an
/// accepted point satisfies `stop_at_bound` (a parameter on a bound, where its map is flat and
/// further iterations only creep: the caller decides what to do from there).
pub fn refine(
    obj: &Objective,
    u0: &[f64],
    max_iters: u64,
    tol: f64,
    fd_step: f64,
    stop_at_bound: BoundStop,
) -> Refined {
    let (n, p) = (obj.len(), obj.dim());
    let mut r = vec![0.0; n];
    let Some(rss) = obj.residuals_user(&obj.to_user(u0), &mut r) else {
        let reason = "the start of the refinement cannot be evaluated".into();
        return Refined {
            u: u0.to_vec(),
            iterations: 0,
            convergence: Convergence::Failed { reason },
        };
    };
    let mut lm = Lm {
        obj,
        u: u0.to_vec(),
        r,
        trial: vec![0.0; n],
        rss,
        lambda: 1e-3,
        nu: 2.0,
        jac: DMatrix::<f64>::zeros(n, p),
        steps: vec![fd_step; p],
        floor: None,
        fd_step,
    };
    for iter in 1..=max_iters {
        let all_exact = lm.jacobian();
        let jt = lm.jac.transpose();
        let a = &jt * &lm.jac;
        let g = &jt * DVector::from_column_slice(&lm.r);
        let (cosine, inner_cosine) = lm.cosines(&a, &g);
        let end = if lm.rss.sqrt() == 0.0 || cosine < tol.sqrt() * 1e-2 {
            Some(Convergence::Converged {
                reason: format!("residuals orthogonal to the Jacobian (cosine {cosine:.1e})"),
            })
        } else {
            lm.step(
                &a,
                &g,
                (tol, all_exact.then_some(inner_cosine)),
                stop_at_bound,
            )
        };
        if let Some(convergence) = end {
            return lm.refined(iter, convergence);
        }
    }
    lm.refined(max_iters, Convergence::MaxIterations)
}

/// A refinement under way: the point, its residuals and cost, the damping, the Jacobian and
/// its difference steps.
struct Lm<'a> {
    obj: &'a Objective<'a>,
    u: Vec<f64>,
    r: Vec<f64>,
    /// The residuals of the last trial point.
    trial: Vec<f64>,
    rss: f64,
    lambda: f64,
    nu: f64,
    jac: DMatrix<f64>,
    steps: Vec<f64>,
    /// The difference steps' floor above the residuals' noise, measured once (lazily: an
    /// exact Jacobian needs no noise).
    floor: Option<StepFloor>,
    fd_step: f64,
}

impl Lm<'_> {
    /// Where the refinement ended after `iterations`, and how.
    fn refined(self, iterations: u64, convergence: Convergence) -> Refined {
        Refined {
            u: self.u,
            iterations,
            convergence,
        }
    }

    /// The Jacobian at `u`: exact where the problem gives one, else differences whose steps
    /// grow above the residuals' noise; non-finite entries zeroed. Whether it is all exact.
    fn jacobian(&mut self) -> bool {
        let (obj, p) = (self.obj, self.u.len());
        let exact = obj
            .jacobian_internal(&self.u, &mut self.jac)
            .unwrap_or_else(|| vec![false; p]);
        let all_exact = exact.iter().all(|&e| e);
        if !all_exact {
            let (u, r, fd_step) = (&self.u, &self.r, self.fd_step);
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
            );
        }
        self.jac
            .iter_mut()
            .filter(|v| !v.is_finite())
            .for_each(|v| *v = 0.0);
        all_exact
    }

    /// The largest cosine between the residuals and a column of the Jacobian (`a` = JᵀJ,
    /// `g` = Jᵀr), over all parameters and over those away from their bounds (where the map
    /// is not flat: a parameter pressing on its bound has a large cosine that no step can
    /// use).
    fn cosines(&self, a: &DMatrix<f64>, g: &DVector<f64>) -> (f64, f64) {
        let rnorm = self.rss.sqrt();
        let transforms = self.obj.transforms();
        let cosine = |inner: bool| {
            (0..self.u.len())
                .filter(|&j| a[(j, j)] > 0.0 && !(inner && transforms[j].saturated(self.u[j])))
                .map(|j| g[j].abs() / (a[(j, j)].sqrt() * rnorm))
                .fold(0.0_f64, f64::max)
        };
        (cosine(false), cosine(true))
    }

    /// One iteration's step: the damping raised until a step lowers the cost, then lowered
    /// (Nielsen). How the refinement ends, if it does here: stopped on a bound, a small
    /// change (below `tol`; `inner_cosine` as [`small_change`] reads it), or no step lowering
    /// the cost at any damping.
    fn step(
        &mut self,
        a: &DMatrix<f64>,
        g: &DVector<f64>,
        (tol, inner_cosine): (f64, Option<f64>),
        stop_at_bound: BoundStop,
    ) -> Option<Convergence> {
        let dmax = (0..self.u.len()).map(|j| a[(j, j)]).fold(0.0_f64, f64::max);
        let floor = (1e-12 * dmax).max(f64::MIN_POSITIVE);
        loop {
            let Some((cand, new_rss, rho, step_size)) = self.tried(a, g, floor) else {
                self.lambda *= self.nu;
                self.nu *= 2.0;
                if self.lambda > LAMBDA_MAX {
                    let reason = "no step lowers the cost any further".into();
                    return Some(Convergence::Converged { reason });
                }
                continue;
            };
            let drop = (self.rss - new_rss) / self.rss;
            self.u = cand;
            self.rss = new_rss;
            std::mem::swap(&mut self.r, &mut self.trial);
            self.lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
            self.nu = 2.0;
            if stop_at_bound.is_some_and(|pinned| pinned(&self.u)) {
                let reason = "stopped on a parameter's bound".into();
                return Some(Convergence::Converged { reason });
            }
            if drop < tol || step_size < 1e-12 {
                return Some(small_change(drop, tol, inner_cosine));
            }
            return None;
        }
    }

    /// The step at the current damping (diagonal at least `floor`), if it lowers the cost
    /// with a positive gain ratio: the point, its cost, the ratio and the step's length.
    fn tried(
        &mut self,
        a: &DMatrix<f64>,
        g: &DVector<f64>,
        floor: f64,
    ) -> Option<(Vec<f64>, f64, f64, f64)> {
        let mut m = a.clone();
        for j in 0..self.u.len() {
            m[(j, j)] += self.lambda * a[(j, j)].max(floor);
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
        let cand: Vec<f64> = self
            .u
            .iter()
            .zip(delta.iter())
            .map(|(a, b)| a + b)
            .collect();
        let obj = self.obj;
        let new_rss = obj.residuals_user(&obj.to_user(&cand), &mut self.trial)?;
        let predicted = -2.0 * g.dot(&delta) - delta.dot(&(a * &delta));
        let rho = (self.rss - new_rss) / predicted;
        (new_rss < self.rss && rho > 0.0).then_some((cand, new_rss, rho, delta.amax()))
    }
}
