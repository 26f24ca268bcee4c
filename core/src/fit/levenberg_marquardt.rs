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
    let n = obj.len();
    let p = obj.dim();
    let mut u = u0.to_vec();
    let mut r = vec![0.0; n];
    let mut trial = vec![0.0; n];
    let Some(mut rss) = obj.residuals_user(&obj.to_user(&u), &mut r) else {
        return Refined {
            u,
            iterations: 0,
            convergence: Convergence::Failed {
                reason: "the start of the refinement cannot be evaluated".into(),
            },
        };
    };
    let mut jac = DMatrix::<f64>::zeros(n, p);
    let mut steps = vec![fd_step; p];
    // An exact Jacobian where the problem gives one; else differences whose steps grow above
    // the residuals' noise, measured once (lazily: an exact Jacobian needs no noise).
    let mut floor: Option<StepFloor> = None;
    let mut lambda = 1e-3;
    let mut nu = 2.0;
    for iter in 1..=max_iters {
        let exact = obj
            .jacobian_internal(&u, &mut jac)
            .unwrap_or_else(|| vec![false; p]);
        let all_exact = exact.iter().all(|&e| e);
        if !all_exact {
            let floor = floor.get_or_insert_with(|| StepFloor {
                noise: residual_noise(&u, &r, &vec![NOISE_PROBE; p], &|point, out| {
                    obj.residuals_user(&obj.to_user(point), out).is_some()
                })
                .unwrap_or(0.0),
                max: vec![MAX_FD_STEP.max(fd_step); p],
            });
            forward_difference(
                &u,
                &r,
                &mut steps,
                floor,
                &|_, _| false,
                &|point, out| obj.residuals_user(&obj.to_user(point), out).is_some(),
                &exact,
                &mut jac,
            );
        }
        jac.iter_mut()
            .filter(|v| !v.is_finite())
            .for_each(|v| *v = 0.0);
        let jt = jac.transpose();
        let a = &jt * &jac;
        let g = &jt * DVector::from_column_slice(&r);
        let rnorm = rss.sqrt();
        let cosine = (0..p)
            .filter(|&j| a[(j, j)] > 0.0)
            .map(|j| g[j].abs() / (a[(j, j)].sqrt() * rnorm))
            .fold(0.0_f64, f64::max);
        // The same over the parameters away from their bounds (where the map is not flat): a
        // parameter pressing on its bound has a large cosine that no step can use.
        let inner_cosine = (0..p)
            .filter(|&j| a[(j, j)] > 0.0 && !obj.transforms()[j].saturated(u[j]))
            .map(|j| g[j].abs() / (a[(j, j)].sqrt() * rnorm))
            .fold(0.0_f64, f64::max);
        if rnorm == 0.0 || cosine < tol.sqrt() * 1e-2 {
            return Refined {
                u,
                iterations: iter,
                convergence: Convergence::Converged {
                    reason: format!("residuals orthogonal to the Jacobian (cosine {cosine:.1e})"),
                },
            };
        }
        let dmax = (0..p).map(|j| a[(j, j)]).fold(0.0_f64, f64::max);
        let floor = (1e-12 * dmax).max(f64::MIN_POSITIVE);
        loop {
            let mut m = a.clone();
            for j in 0..p {
                m[(j, j)] += lambda * a[(j, j)].max(floor);
            }
            let step = m.cholesky().map(|c| {
                let delta = c.solve(&(-&g));
                // A step of at most MAX_STEP scales: a long one would run into the flat,
                // saturated part of a bound transform and stall there.
                let longest = delta.amax();
                if longest > MAX_STEP {
                    delta * (MAX_STEP / longest)
                } else {
                    delta
                }
            });
            let accepted = step.and_then(|delta| {
                let cand: Vec<f64> = u.iter().zip(delta.iter()).map(|(a, b)| a + b).collect();
                let new_rss = obj.residuals_user(&obj.to_user(&cand), &mut trial)?;
                let predicted = -2.0 * g.dot(&delta) - delta.dot(&(&a * &delta));
                let rho = (rss - new_rss) / predicted;
                (new_rss < rss && rho > 0.0).then_some((cand, new_rss, rho, delta.amax()))
            });
            match accepted {
                Some((cand, new_rss, rho, step_size)) => {
                    let drop = (rss - new_rss) / rss;
                    u = cand;
                    rss = new_rss;
                    std::mem::swap(&mut r, &mut trial);
                    lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                    nu = 2.0;
                    if stop_at_bound.is_some_and(|pinned| pinned(&u)) {
                        return Refined {
                            u,
                            iterations: iter,
                            convergence: Convergence::Converged {
                                reason: "stopped on a parameter's bound".into(),
                            },
                        };
                    }
                    if drop < tol || step_size < 1e-12 {
                        return Refined {
                            u,
                            iterations: iter,
                            convergence: small_change(drop, tol, all_exact.then_some(inner_cosine)),
                        };
                    }
                    break;
                }
                None => {
                    lambda *= nu;
                    nu *= 2.0;
                    if lambda > LAMBDA_MAX {
                        return Refined {
                            u,
                            iterations: iter,
                            convergence: Convergence::Converged {
                                reason: "no step lowers the cost any further".into(),
                            },
                        };
                    }
                }
            }
        }
    }
    Refined {
        u,
        iterations: max_iters,
        convergence: Convergence::MaxIterations,
    }
}
