//! The driver shared by every kind of fit: checked parameters in, [`FitResult`] out.
//!
//! It runs the stages of the chosen [`Solver`] on an [`Objective`] — each stage one run of
//! argmin's `Executor` ([`super::stages`]), watched by the fit's observer
//! ([`super::observer`]); the chain between them (which stage follows which, the start kept
//! if nothing beats it, a pinned parameter released) is ours — then computes the residuals
//! and a forward-difference Jacobian at the best point in the user's parameter space (so the
//! standard errors are those of the values reported, whatever the transforms; robust to
//! residuals correlated over blocks of samples, which are chosen from the residuals), and the
//! statistics of the result.

use std::sync::mpsc::Sender;
use std::time::Instant;

use nalgebra::DMatrix;

use super::covariance::{self, MIN_BLOCKS};
use super::error::FitError;
use super::fit_param::{BoundSide, FitParam};
use super::kept_points::Kept;
use super::levenberg_marquardt::{BoundStop, MAX_FD_STEP, NOISE_PROBE};
use super::noise_floor::Quantity;
use super::objective::{Objective, Residuals};
use super::observer::Watch;
use super::residual_jacobian::{forward_difference, residual_noise, StepFloor, ERROR_RTOL};
use super::result::{Convergence, ErrorBlocks, FitProgress, FitResult, FittedParam, SolverStage};
use super::solver::{FitSettings, Solver};
use super::stages::{self, StageEnd};

/// Fit the free members of `params` (all of them, in order) of `problem`, whose
/// [`Residuals::residuals`] receives the user values of the free parameters only.
/// `quantity`: what the residuals measure (displacements: a trajectory fit, S(μ) reported in
/// mm²). `observer` sees
/// the fit's progress after every iteration of every stage (see [`super::observer`]).
pub fn run(
    problem: &dyn Residuals,
    params: &[FitParam],
    settings: &FitSettings,
    observer: Option<&(dyn Fn(FitProgress) + Sync)>,
    quantity: Quantity,
) -> Result<FitResult, FitError> {
    Watch::forwarding(observer, |display| {
        run_watched(problem, params, settings, display, quantity)
    })
}

/// [`run`], its progress sent to `display`.
fn run_watched(
    problem: &dyn Residuals,
    params: &[FitParam],
    settings: &FitSettings,
    display: Option<Sender<FitProgress>>,
    quantity: Quantity,
) -> Result<FitResult, FitError> {
    let clock = Instant::now();
    let free = checked(problem, params, settings)?;
    let transforms: Vec<_> = free.iter().map(|p| p.transform()).collect();
    let obj = Objective::new(problem, transforms.clone());
    let names: Vec<&str> = free.iter().map(|p| p.name.as_str()).collect();
    let watch = Watch::new(
        obj.tally(),
        display,
        settings.trace.as_deref(),
        (&names, transforms),
    );
    let u0 = vec![0.0; obj.dim()];
    // Kept: the refinement begins here, and the end is compared with it.
    if obj.evaluate_kept(Kept::Start, &obj.to_user(&u0)).is_none() {
        return Err(FitError::StartFails(
            obj.last_failure().unwrap_or_else(|| "unknown".into()),
        ));
    }
    let mut chain = Chain {
        obj: &obj,
        free: &free,
        settings,
        quantity,
        watch: &watch,
        iterations: 0,
        log: Vec::new(),
        earlier: (0, 0, None),
    };
    let fitted = chain.solve(&u0).and_then(|(u, convergence)| {
        let (u, convergence) = chain.no_worse_than(u0, u, convergence);
        let x = obj.to_user(&u);
        chain.finish(params, &x, convergence, clock)
    });
    // The trace is written whatever the end; the fit's own error comes first.
    let written = watch.write_trace();
    let fitted = fitted?;
    written.map(|()| fitted)
}

/// The free members of `params` after checking the settings, each parameter, that no name
/// is given twice, and that `problem` has more samples than free parameters.
fn checked<'p>(
    problem: &dyn Residuals,
    params: &'p [FitParam],
    settings: &FitSettings,
) -> Result<Vec<&'p FitParam>, FitError> {
    settings.check()?;
    for (i, p) in params.iter().enumerate() {
        p.check()?;
        if params[..i].iter().any(|q| q.name == p.name) {
            return Err(FitError::DuplicateParam(p.name.clone()));
        }
    }
    let free: Vec<&FitParam> = params.iter().filter(|p| !p.fixed).collect();
    let n = problem.len();
    if n <= free.len() {
        return Err(FitError::BadData(format!(
            "{n} samples cannot determine {} free parameters",
            free.len()
        )));
    }
    Ok(free)
}

/// The solver chain of a fit: its objective, free parameters and settings, and the
/// iterations and log of its stages so far.
struct Chain<'a> {
    obj: &'a Objective<'a>,
    free: &'a [&'a FitParam],
    settings: &'a FitSettings,
    quantity: Quantity,
    /// The fit's observer of every stage.
    watch: &'a Watch,
    iterations: u64,
    log: Vec<String>,
    /// What an earlier run at the same point already spent (evaluations, failures, the last
    /// failure): [`with_errors`] completes a fit run without its errors.
    earlier: (u64, u64, Option<String>),
}

impl Chain<'_> {
    /// Whether the residuals are displacements of a simulated trajectory.
    fn is_trajectory(&self) -> bool {
        self.quantity == Quantity::Displacement
    }

    /// The stages of the chosen solver from `u0` (then, in a trajectory fit, the release of
    /// pinned parameters): where they end and how.
    fn solve(&mut self, u0: &[f64]) -> Result<(Vec<f64>, Convergence), FitError> {
        if u0.is_empty() {
            self.log.push("no free parameters: evaluated only".into());
            let reason = "nothing to fit".into();
            return Ok((u0.to_vec(), Convergence::Converged { reason }));
        }
        let settings = self.settings;
        let (u, convergence) = match settings.solver {
            Solver::NelderMead => self.nelder_mead(u0, settings.simplex_tol)?,
            Solver::Auto => {
                let (u, conv) = self.lm(u0)?;
                if conv.converged() {
                    (u, conv)
                } else {
                    // From where Levenberg–Marquardt got to, not from the start: restarting
                    // from the start threw its progress away, and a simplex from there was
                    // seen to end far worse.
                    self.log.push(
                        "levenberg_marquardt did not converge: Nelder–Mead from its best \
                         point, then again"
                            .into(),
                    );
                    let tol = settings.simplex_tol.max(settings.presearch_tol);
                    let (u, _) = self.nelder_mead(&u, tol)?;
                    self.lm(&u)?
                }
            }
            Solver::LevenbergMarquardt => self.lm(u0)?,
            Solver::ParticleSwarm => {
                let u = self.particle_swarm(u0)?;
                self.lm(&u)?
            }
        };
        if self.is_trajectory() {
            release_pinned(self, u, convergence)
        } else {
            Ok((u, convergence))
        }
    }

    /// Levenberg–Marquardt from `start`, logged. In a trajectory fit a refinement that pins a
    /// parameter on a bound stops there; the parameter is then released (see
    /// [`release_pinned`]).
    fn lm(&mut self, start: &[f64]) -> Result<(Vec<f64>, Convergence), FitError> {
        let out = self.refine(start)?;
        self.log.push(format!(
            "levenberg_marquardt: {} iterations, {:?}",
            out.iterations, out.convergence
        ));
        Ok((out.u, out.convergence))
    }

    /// Levenberg–Marquardt from `start`, its iterations counted; in a trajectory fit it stops
    /// where a parameter is pinned on a bound.
    fn refine(&mut self, start: &[f64]) -> Result<StageEnd, FitError> {
        let (obj, free) = (self.obj, self.free);
        let at_bound = |u: &[f64]| !pinned(obj, free, u).is_empty();
        let stop_at_bound: BoundStop = self.is_trajectory().then_some(&at_bound);
        let out =
            stages::levenberg_marquardt(obj, start, self.settings, stop_at_bound, self.watch)?;
        self.iterations += out.iterations;
        Ok(out)
    }

    /// Nelder–Mead from `start` to the simplex tolerance `tol`, logged.
    fn nelder_mead(
        &mut self,
        start: &[f64],
        tol: f64,
    ) -> Result<(Vec<f64>, Convergence), FitError> {
        let out = stages::nelder_mead(self.obj, start, tol, self.settings, self.watch)?;
        let (it, conv) = (out.iterations, out.convergence);
        self.iterations += it;
        self.log
            .push(format!("nelder_mead: {it} iterations, {conv:?}"));
        Ok((out.u, conv))
    }

    /// A fit never ends worse than its start: whatever the chain did, the start `u0` is kept
    /// if it is better than where the chain ended (`u`, `convergence`).
    fn no_worse_than(
        &mut self,
        u0: Vec<f64>,
        u: Vec<f64>,
        convergence: Convergence,
    ) -> (Vec<f64>, Convergence) {
        let start_cost = self.obj.cost(&u0).unwrap_or(f64::INFINITY);
        match self.obj.cost(&u) {
            Some(c) if c <= start_cost => (u, convergence),
            end => {
                self.log.push(format!(
                    "the solvers ended worse than the start (mean square {} > \
                     {start_cost:e}): the start is kept",
                    end.map_or("failed".to_string(), |c| format!("{c:e}"))
                ));
                let reason = "no solver improved on the start".into();
                (u0, Convergence::Failed { reason })
            }
        }
    }
}

/// Closest a parameter may end to a bound, as a fraction of its typical size (its scale: the
/// start value's magnitude, or a tenth of the box), before it counts as pinned there. A
/// fraction of the box's width would not do: in a wide box ([0, 1e9] for a cubic stiffness)
/// it pinned any value below 1000, where the map, exponential near its lower bound, is far
/// from flat (a volt-unit record's k3 ≈ 4 stopped the fit at once, 3× the residual).
const PINNED: f64 = 1e-6;

/// The free parameters (by index) that `u` puts on one of their bounds, where the bound
/// transform is flat.
fn pinned(obj: &Objective, free: &[&FitParam], u: &[f64]) -> Vec<usize> {
    let x = obj.to_user(u);
    free.iter()
        .zip(&x)
        .enumerate()
        .filter(|(_, (q, &v))| {
            let width = q.max - q.min;
            let span = q.effective_scale().min(width);
            (v - q.min).abs() <= PINNED * span || (q.max - v).abs() <= PINNED * span
        })
        .map(|(j, _)| j)
        .collect()
}

/// Trajectory fits: a parameter that the refinement drove onto a bound cannot come back, since
/// its map is flat there, even when the cost falls away from the bound along a joint move with
/// the others (from the identification's second stage, started from the free-vibration values,
/// ΔT went to its bound with S 0.0178 mm², while the optimum inside has 0.0035). So the pinned
/// parameters are released to their start values, the others kept, and Levenberg–Marquardt
/// runs again from there; the better end is kept. (Force-level fits, cheap to refine, let the
/// refinement run on along the bound instead: there a parameter often belongs on its bound.)
fn release_pinned(
    chain: &mut Chain,
    u: Vec<f64>,
    convergence: Convergence,
) -> Result<(Vec<f64>, Convergence), FitError> {
    let (obj, free) = (chain.obj, chain.free);
    let stuck = pinned(obj, free, &u);
    if stuck.is_empty() {
        return Ok((u, convergence));
    }
    let Some(cost) = obj.cost(&u) else {
        return Ok((u, convergence));
    };
    let mut restart = u.clone();
    for &j in &stuck {
        restart[j] = 0.0;
    }
    let out = chain.refine(&restart)?;
    let names: Vec<&str> = stuck.iter().map(|&j| free[j].name.as_str()).collect();
    Ok(match obj.cost(&out.u) {
        Some(c) if c < cost => {
            chain.log.push(format!(
                "{} ended on a bound: released to the start, levenberg_marquardt again: {} \
                 iterations, {:?} (mean square {cost:e} → {c:e})",
                names.join(", "),
                out.iterations,
                out.convergence
            ));
            (out.u, out.convergence)
        }
        end => {
            chain.log.push(format!(
                "{} ended on a bound: released to the start, the refinement ended no better \
                 ({}); the bound is kept",
                names.join(", "),
                end.map_or("failed".to_string(), |c| format!("mean square {c:e}"))
            ));
            (u, convergence)
        }
    })
}

impl Chain<'_> {
    /// The particle swarm over the whole box, logged: its best point, or `u0` if it found
    /// nothing better.
    fn particle_swarm(&mut self, u0: &[f64]) -> Result<Vec<f64>, FitError> {
        let obj = self.obj;
        let swarm = stages::particle_swarm(obj, self.settings, self.watch)?;
        let it = swarm.iterations;
        self.iterations += it;
        self.log.push(format!("particle_swarm: {it} iterations"));
        // Keep the start if the swarm found nothing better.
        let start_cost = obj.cost(u0).unwrap_or(f64::INFINITY).max(1e-300).ln();
        Ok(match swarm.best {
            Some((b, cost)) if cost < start_cost => b,
            _ => u0.to_vec(),
        })
    }

    /// The result at the chain's end, the user values `x`: residuals, standard errors
    /// (unless the settings leave them out) and statistics, with the chain's iterations and
    /// log.
    fn finish(
        self,
        params: &[FitParam],
        x: &[f64],
        mut convergence: Convergence,
        clock: Instant,
    ) -> Result<FitResult, FitError> {
        let (obj, mut log) = (self.obj, self.log);
        self.watch.announce(SolverStage::Errors);
        let n = obj.len();
        let mut r0 = vec![0.0; n];
        let Some(rss) = obj.residuals_user(x, &mut r0) else {
            return Err(FitError::Solver(format!(
                "the best point cannot be re-evaluated: {}",
                obj.last_failure().unwrap_or_default()
            )));
        };
        let p = self.free.len();
        let errors = if p > 0 && self.settings.errors {
            // From the problem's precise residuals where it has them (a simulation at a
            // tighter tolerance than the fit's), the fit's own otherwise.
            let mut precise = vec![0.0; n];
            let base = match obj.precise_residuals_user(x, &mut precise) {
                Some(Some(_)) => Some(precise.as_slice()),
                Some(None) => {
                    log.push(format!(
                        "standard errors: the precise simulation failed ({}): the Jacobian \
                         is the fit's own",
                        obj.last_failure().unwrap_or_default()
                    ));
                    None
                }
                None => None,
            };
            let (jac, rise) = jacobian(
                obj,
                self.free,
                x,
                base.unwrap_or(&r0),
                self.settings,
                base.is_some(),
            );
            noisy_columns(self.free, &rise, &mut log);
            let mut errors = standard_errors(&jac, &r0, rss, obj.correlation_span(), &mut log);
            errors.rise = rise;
            Some(errors)
        } else {
            None
        };
        let fitted = match errors {
            None if p > 0 => unsure_params(params, x),
            _ => fitted_params(params, x, errors.as_ref()),
        };
        let nf = n as f64;
        let mean = rss / nf;
        let ln_term = nf * mean.max(f64::MIN_POSITIVE).ln();
        let (evaluations, failures, last_failure) = (
            self.earlier.0 + obj.evaluations(),
            self.earlier.1 + obj.failures(),
            obj.last_failure().or(self.earlier.2),
        );
        if failures > 0 {
            log.push(failed_line(failures, last_failure.as_deref()));
        }
        if !x.iter().all(|v| v.is_finite()) {
            convergence = Convergence::Failed {
                reason: "a parameter is not finite".into(),
            };
        }
        let (correlation, error_blocks) = match errors {
            Some(e) => (e.robust.correlation, Some(e.blocks)),
            None => (vec![], None),
        };
        Ok(FitResult {
            params: fitted,
            correlation,
            error_blocks,
            n_points: n,
            n_free: p,
            rss,
            rms: mean.sqrt(),
            s_mm2: (self.quantity == Quantity::Displacement).then_some(mean * 1e6),
            aic: ln_term + 2.0 * p as f64,
            bic: ln_term + p as f64 * nf.ln(),
            evaluations,
            failures,
            last_failure,
            iterations: self.iterations,
            wall_seconds: clock.elapsed().as_secs_f64(),
            convergence,
            log,
        })
    }
}

/// How near a bound a parameter the data push past it counts as held by it, as a fraction of
/// the bound's own scale (see [`held_by`]). A bounded map flattens towards its bounds, so a
/// solver stops short of one it is pushed against (an offset of −124 N stopped at −99.93 in a
/// box of ±100 N, 0.07 % of the bound inside).
pub const HELD_REACH: f64 = 0.05;

/// The bound that holds `q` at `value`: the Gauss–Newton `step` from there crosses it, and
/// the parameter is within [`HELD_REACH`] of the bound's own scale (the larger of its |value|
/// and the typical size, at most the width), or within [`HELD_REACH`] of the box's width (of
/// its typical size, for a bound on one side only) with a step that would carry it past the
/// bound by at least its distance from it. So `c_s` in [0, 10⁴] stopped at 12.7 with a step
/// of −20 is not held (5 % of the width alone would reach 500), while a candidate started
/// next to nothing (its typical size then tiny) and pushed through 0 still is.
fn held_by(q: &FitParam, value: f64, step: f64) -> Option<BoundSide> {
    let width = q.max - q.min;
    let outer = HELD_REACH
        * if width.is_finite() {
            width
        } else {
            q.effective_scale()
        };
    let near = |bound: f64| HELD_REACH * bound.abs().max(q.effective_scale()).min(width);
    // Near on the bound's own scale; or within the outer reach, with a step that would carry
    // it past the bound by at least its distance from it.
    let held = |distance: f64, bound: f64| {
        distance <= near(bound) || (distance <= outer && step.abs() >= 2.0 * distance)
    };
    let to = value + step;
    if q.min.is_finite() && to < q.min && held(value - q.min, q.min) {
        Some(BoundSide::Lower)
    } else if q.max.is_finite() && to > q.max && held(q.max - value, q.max) {
        Some(BoundSide::Upper)
    } else {
        None
    }
}

/// Every parameter as fitted: a fixed one at its value with no error, a free one at its entry
/// of the free values `x` with its standard errors (none when nothing was free to fit) and the
/// bound that holds it, if one does.
fn fitted_params(params: &[FitParam], x: &[f64], errors: Option<&Errors>) -> Vec<FittedParam> {
    let mut free = x.iter().enumerate();
    params
        .iter()
        .filter_map(|q| {
            if q.fixed {
                return Some(FittedParam::held(&q.name, q.value));
            }
            let e = errors?;
            let (k, &value) = free.next()?;
            Some(FittedParam {
                name: q.name.clone(),
                value,
                std_error: e.robust.std_errors[k],
                naive_std_error: e.naive[k],
                fixed: false,
                held_by: held_by(q, value, e.step[k]),
                noisy_column: (e.rise[k] < NOISY_COLUMN).then_some(e.rise[k]),
            })
        })
        .collect()
}

/// The free parameters of `params` at the user values `x` with unknown standard errors: a
/// fit run without them ([`FitSettings::errors`]).
fn unsure_params(params: &[FitParam], x: &[f64]) -> Vec<FittedParam> {
    let mut free = x.iter();
    params
        .iter()
        .filter_map(|q| {
            if q.fixed {
                return Some(FittedParam::held(&q.name, q.value));
            }
            Some(FittedParam {
                name: q.name.clone(),
                value: *free.next()?,
                std_error: f64::NAN,
                naive_std_error: f64::NAN,
                fixed: false,
                held_by: None,
                noisy_column: None,
            })
        })
        .collect()
}

/// The log line of a fit whose evaluations failed `failures` times (`last`: the last reason).
fn failed_line(failures: u64, last: Option<&str>) -> String {
    format!(
        "{failures} evaluations failed and were scored as penalties; last: {}",
        last.unwrap_or_default()
    )
}

/// `fitted`, a fit of `problem` run without its standard errors ([`FitSettings::errors`]
/// off), completed with them at the point where it ended: the same result as the fit run
/// with them, but for the one more evaluation it counts. A search that ranks many starts by
/// their RMS computes the errors of the one it keeps only.
pub fn with_errors(
    problem: &dyn Residuals,
    params: &[FitParam],
    settings: &FitSettings,
    quantity: Quantity,
    fitted: FitResult,
) -> Result<FitResult, FitError> {
    let settings = FitSettings {
        errors: true,
        ..settings.clone()
    };
    let free = checked(problem, params, &settings)?;
    let transforms: Vec<_> = free.iter().map(|p| p.transform()).collect();
    let obj = Objective::new(problem, transforms.clone());
    let names: Vec<&str> = free.iter().map(|p| p.name.as_str()).collect();
    let watch = Watch::new(obj.tally(), None, None, (&names, transforms));
    let x: Vec<f64> = params
        .iter()
        .zip(&fitted.params)
        .filter(|(q, _)| !q.fixed)
        .map(|(_, f)| f.value)
        .collect();
    let mut log = fitted.log;
    if fitted.failures > 0 {
        log.pop();
    }
    let elapsed = std::time::Duration::from_secs_f64(fitted.wall_seconds.max(0.0));
    let clock = Instant::now()
        .checked_sub(elapsed)
        .unwrap_or_else(Instant::now);
    let chain = Chain {
        obj: &obj,
        free: &free,
        settings: &settings,
        quantity,
        watch: &watch,
        iterations: fitted.iterations,
        log,
        earlier: (fitted.evaluations, fitted.failures, fitted.last_failure),
    };
    chain.finish(params, &x, fitted.convergence, clock)
}

/// The Jacobian of the residuals `r0` at the user values `x` of the free parameters `free`:
/// exact where the problem gives one, else by forward differences — of the problem's precise
/// residuals when `precise` (then `r0` are those), of its own otherwise; and how far each
/// column stands above the residuals' noise (see [`forward_difference`]).
///
/// The difference steps are sized to where the fit ended: `fd_step` (up to
/// [`MAX_FD_STEP`]) times the larger of the parameter's typical size and its |value|. A
/// parameter that started near zero — an added term's amplitude started neutral, at a
/// millionth of its default — has a typical size of its start (2e-7 N for a yield force),
/// and steps of that size at an end of 0.5 N changed the simulated x less than the
/// integrator's own noise: the column was that noise, and the standard error 250 times too
/// small.
fn jacobian(
    obj: &Objective,
    free: &[&FitParam],
    x: &[f64],
    r0: &[f64],
    settings: &FitSettings,
    precise: bool,
) -> (DMatrix<f64>, Vec<f64>) {
    let (n, p) = (r0.len(), free.len());
    let eval = |point: &[f64], out: &mut [f64]| {
        if precise {
            matches!(obj.precise_residuals_user(point, out), Some(Some(_)))
        } else {
            obj.residuals_user(point, out).is_some()
        }
    };
    let mut jac = DMatrix::<f64>::zeros(n, p);
    let exact = obj
        .jacobian_user(x, &mut jac)
        .unwrap_or_else(|| vec![false; p]);
    if exact.iter().all(|&e| e) {
        return (jac, vec![f64::INFINITY; p]);
    }
    let size: Vec<f64> = free
        .iter()
        .zip(x)
        .map(|(q, v)| q.effective_scale().max(v.abs()))
        .collect();
    // Precise residuals are simulations at `ERROR_RTOL`: their step is the one
    // `FitSettings::for_simulation` gives that tolerance, where the fit's may be longer.
    let fd_step = if precise {
        settings.fd_step.min(ERROR_RTOL.sqrt())
    } else {
        settings.fd_step
    };
    let mut steps: Vec<f64> = size.iter().map(|s| fd_step * s).collect();
    // Steps above the residuals' noise (a noisy column would make a noisy standard
    // error), at most MAX_FD_STEP sizes and short enough that one side stays in bounds.
    let probe: Vec<f64> = free
        .iter()
        .zip(x)
        .map(|(q, v)| {
            let e = NOISE_PROBE * q.effective_scale();
            if v + e < q.max && v - e > q.min {
                e
            } else {
                0.0
            }
        })
        .collect();
    let noise = residual_noise(x, r0, &probe, &eval).unwrap_or(0.0);
    let floor = StepFloor {
        noise,
        max: free
            .iter()
            .zip(&size)
            .zip(&steps)
            .map(|((q, s), h)| (MAX_FD_STEP * s).min(0.49 * (q.max - q.min)).max(*h))
            .collect(),
    };
    let rise = forward_difference(
        x,
        r0,
        &mut steps,
        &floor,
        &|j, v| !(v > free[j].min && v < free[j].max),
        &eval,
        &exact,
        &mut jac,
        &|points| {
            if !precise {
                obj.prefetch_user(points);
            }
        },
    );
    (jac, rise)
}

/// A difference column that stands less than this many times above the residuals' noise
/// (its rms change over theirs) at the longest step allowed makes its parameter's standard
/// error uncertain (the noise then makes ≳ 15 % of the column): the fit says so.
pub const NOISY_COLUMN: f64 = 10.0;

/// A line in `log` naming the parameters (of `free`) whose difference columns stood less than
/// [`NOISY_COLUMN`] times above the residuals' noise (`rise`).
fn noisy_columns(free: &[&FitParam], rise: &[f64], log: &mut Vec<String>) {
    let noisy: Vec<String> = free
        .iter()
        .zip(rise)
        .filter(|(_, r)| **r < NOISY_COLUMN)
        .map(|(q, r)| format!("{} ({r:.1}×)", q.name))
        .collect();
    if !noisy.is_empty() {
        log.push(format!(
            "standard errors: the difference columns of {} stand less than {NOISY_COLUMN}× \
             above the residuals' noise: their errors are uncertain",
            noisy.join(", ")
        ));
    }
}

/// The standard errors of a fit: robust over blocks chosen from the residuals, and naive.
struct Errors {
    robust: covariance::Covariance,
    naive: Vec<f64>,
    blocks: ErrorBlocks,
    /// The Gauss–Newton step from the end, per free parameter.
    step: Vec<f64>,
    /// How far each free parameter's difference column stood above the residuals' noise.
    rise: Vec<f64>,
}

/// Standard errors from the Jacobian `jac` and the residuals `r` (sum of squares `rss`),
/// known to be correlated over `span` samples; a line in `log` when the blocks are too few
/// for the errors to be sure.
fn standard_errors(
    jac: &DMatrix<f64>,
    r: &[f64],
    rss: f64,
    span: usize,
    log: &mut Vec<String>,
) -> Errors {
    let blocks = covariance::blocks(jac, r, span);
    if !blocks.settled {
        log.push(format!(
            "standard errors: the residuals are correlated over about the whole record (even \
             {} blocks of {} samples are not long enough): the errors may still be too small",
            blocks.count, blocks.length
        ));
    } else if blocks.count < MIN_BLOCKS {
        log.push(format!(
            "standard errors: the residuals are correlated over {} samples, only {} blocks: \
             the errors are themselves uncertain",
            blocks.length, blocks.count
        ));
    }
    Errors {
        robust: covariance::sandwich(jac, r, blocks.length),
        naive: covariance::from_jacobian(jac, rss).std_errors,
        blocks,
        step: covariance::gauss_newton_step(jac, r),
        rise: vec![f64::INFINITY; jac.ncols()],
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// r_i = y_i − k·x_i.
    struct Line {
        x: Vec<f64>,
        y: Vec<f64>,
    }

    impl Residuals for Line {
        fn len(&self) -> usize {
            self.x.len()
        }
        fn residuals(&self, k: &[f64], sink: &mut dyn FnMut(usize, f64)) -> Result<(), String> {
            for (i, (x, y)) in self.x.iter().zip(&self.y).enumerate() {
                sink(i, y - k[0] * x);
            }
            Ok(())
        }
    }

    fn rss_at(line: &Line, k: f64) -> f64 {
        line.x
            .iter()
            .zip(&line.y)
            .map(|(x, y)| (y - k * x).powi(2))
            .sum()
    }

    /// A stiffness of 554 with wide bounds [0, 1e9] (those of `wall_impact.k_w`), started at
    /// its least-squares value: no solver, however few its iterations, may end worse. (The
    /// bound transform used to move this start to 1e6, "1e-3 of the width inside", and a
    /// short refit then ended 1e5 times worse than it started.)
    #[test]
    fn a_fit_started_at_the_optimum_never_ends_worse() {
        let x: Vec<f64> = (0..200).map(|i| (i as f64 * 0.1).sin() * 0.01).collect();
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, x)| 554.0 * x + 1e-3 * ((i * 7919 % 13) as f64 - 6.0))
            .collect();
        let line = Line { x, y };
        let best = line.x.iter().zip(&line.y).map(|(x, y)| x * y).sum::<f64>()
            / line.x.iter().map(|x| x * x).sum::<f64>();
        let start_rss = rss_at(&line, best);
        for solver in Solver::ALL {
            for iters in [1, 2, 200] {
                let params = [FitParam::new("k", best).bounds(0.0, 1e9)];
                let settings = FitSettings::default().solver(solver).max_iters(iters);
                let fit = run(&line, &params, &settings, None, Quantity::Force).unwrap();
                assert!(
                    fit.rss <= start_rss * (1.0 + 1e-12),
                    "{solver:?}, {iters} iterations: rss {} > start {start_rss}, k = {}",
                    fit.rss,
                    fit.params[0].value
                );
                assert!((fit.params[0].value / best - 1.0).abs() < 1e-6);
            }
        }
    }

    /// A slope the data put at −124 in a box of ±100: wherever the solvers stop short of the
    /// lower bound, the slope is held by it (and a fit's warnings say so); a slope of −95
    /// inside the same box, as near the bound, is held by nothing.
    #[test]
    fn a_parameter_the_data_push_past_a_bound_is_held_by_it() {
        for (truth, held) in [(-124.0, Some(BoundSide::Lower)), (-95.0, None)] {
            let line = sloped(truth);
            let params = [FitParam::new("k", 0.0).bounds(-100.0, 100.0).scale(0.1)];
            for solver in Solver::ALL {
                let settings = FitSettings::default().solver(solver);
                let fit = run(&line, &params, &settings, None, Quantity::Force).unwrap();
                let p = &fit.params[0];
                assert_eq!(
                    p.held_by, held,
                    "{solver:?}, truth {truth}: k = {}",
                    p.value
                );
                let flagged = super::super::fit_warnings(&fit, &params, None)
                    .iter()
                    .any(|w| w.kind() == "on_bound");
                assert_eq!(flagged, held.is_some(), "{solver:?}, truth {truth}");
            }
        }
    }

    /// 400 samples of a line of slope `truth` through a sine, with a little deterministic
    /// noise.
    fn sloped(truth: f64) -> Line {
        let x: Vec<f64> = (0..400).map(|i| (i as f64 * 0.05).sin()).collect();
        let y = x
            .iter()
            .enumerate()
            .map(|(i, x)| truth * x + 0.1 * ((i * 7919 % 13) as f64 - 6.0))
            .collect();
        Line { x, y }
    }

    /// A fit run without its standard errors and completed with them later is the fit run
    /// with them, to the bit, held by its bound or not.
    #[test]
    fn errors_completed_later_are_those_of_a_fit_run_with_them() {
        for truth in [-124.0, 37.0] {
            let line = sloped(truth);
            let params = [FitParam::new("k", 0.0).bounds(-100.0, 100.0).scale(0.1)];
            for solver in Solver::ALL {
                let settings = FitSettings::default().solver(solver);
                let whole = run(&line, &params, &settings, None, Quantity::Force).unwrap();
                let quick = settings.clone().errors(false);
                let bare = run(&line, &params, &quick, None, Quantity::Force).unwrap();
                assert!(
                    bare.params[0].std_error.is_nan(),
                    "{solver:?}: no errors yet"
                );
                assert!(bare.evaluations < whole.evaluations, "{solver:?}");
                let done = with_errors(&line, &params, &quick, Quantity::Force, bare).unwrap();
                let (a, b) = (&whole.params[0], &done.params[0]);
                assert_eq!(a.value.to_bits(), b.value.to_bits(), "{solver:?}, {truth}");
                assert_eq!(a.std_error.to_bits(), b.std_error.to_bits(), "{solver:?}");
                assert_eq!(a.naive_std_error.to_bits(), b.naive_std_error.to_bits());
                assert_eq!((a.held_by, a.noisy_column), (b.held_by, b.noisy_column));
                assert_eq!(whole.rss.to_bits(), done.rss.to_bits());
                assert_eq!(whole.correlation, done.correlation);
                assert_eq!(whole.log, done.log);
                assert_eq!(whole.iterations, done.iterations);
                assert_eq!(done.evaluations, whole.evaluations + 1, "{solver:?}");
            }
        }
    }

    /// The rule of [`held_by`] both ways: a parameter is held by a bound it is pushed past
    /// only when it stopped near it on the bound's scale.
    #[test]
    fn a_bound_holds_a_parameter_only_near_it_on_its_own_scale() {
        // c_s in [0, 1e4], typical size 2: at 12.69 it is far from its bound at 0 even if
        // the step from there crosses it; at 0.01 it is held.
        let c_s = FitParam::new("c_s", 2.0).bounds(0.0, 1e4);
        assert_eq!(held_by(&c_s, 12.6872, -20.0), None);
        assert_eq!(held_by(&c_s, 0.01, -1.0), Some(BoundSide::Lower));
        assert_eq!(held_by(&c_s, 0.01, 0.5), None);
        // An offset stopped 0.07 inside a bound of −100 the data push it past is held by it,
        // whatever its typical size; one 10 inside is not.
        for scale in [0.1, 1.0, 100.0] {
            let off = FitParam::new("f_off", 0.0)
                .bounds(-100.0, 100.0)
                .scale(scale);
            assert_eq!(held_by(&off, -99.93, -24.0), Some(BoundSide::Lower));
            assert_eq!(held_by(&off, 99.93, 24.0), Some(BoundSide::Upper));
            // 10 inside: not held when the step carries it only 5 past the bound, nor 11
            // inside (past 5 % of the width) whatever the step.
            assert_eq!(held_by(&off, -90.0, -15.0), None);
            assert_eq!(held_by(&off, -89.0, -300.0), None);
        }
        // A candidate started next to nothing (typical size 1e-6) and pushed through 0 is
        // held there, far inside a twentieth of its typical size or not.
        let f_y = FitParam::new("F_y", 1e-6).bounds(0.0, 1e3);
        assert_eq!(held_by(&f_y, 9e-8, -1e-6), Some(BoundSide::Lower));
        assert_eq!(held_by(&f_y, 9e-8, 1e-6), None);
        // A one-sided bound away from 0: its own size sets the reach.
        let k = FitParam::new("k", 1500.0)
            .bounds(1000.0, f64::INFINITY)
            .scale(1.0);
        assert_eq!(held_by(&k, 1010.0, -50.0), Some(BoundSide::Lower));
        assert_eq!(held_by(&k, 1100.0, -150.0), None);
    }
}
