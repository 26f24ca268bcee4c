//! Forward-difference Jacobians of residual vectors, column by column, with steps that rise
//! above the residuals' noise.
//!
//! A step that fails (the model errs there) is retried in the opposite direction; a column
//! whose both steps fail is NaN, and the parameter's standard error with it.
//!
//! Residuals from a simulation carry the integrator's error, which changes at random with any
//! change of the parameters (the adaptive steps change): on the 150 s forced sweep, at
//! `rtol` 1e-7, any perturbation (1e-9 or 1e-5 of a parameter alike) moves the residuals by
//! 6e-4 mm rms, while a step of 3e-4 of ΔT moves them by only 2e-4 mm — that column was noise,
//! and Levenberg–Marquardt stopped at S four times the optimum's. So the noise is measured
//! ([`residual_noise`]) and each column's step is lengthened until the change it makes stands
//! [`SIGNAL_TO_NOISE`] times above that noise (up to a largest step).
//!
//! The columns are independent, so they are computed in parallel (rayon): a fit along a
//! simulated record spends nearly all its time here, one simulation a column, and a fit that
//! runs alone (a base, a polish, the last candidate of a step) would otherwise leave all
//! cores but one idle. Each column's value depends on its own evaluations only, so the
//! Jacobian is the same whatever the order the columns finish in.

use nalgebra::DMatrix;
use rayon::prelude::*;

use crate::numerics::integrate::Settings;

/// Relative tolerance of the simulations behind a trajectory fit's standard errors, at the
/// loosest: the default's (see [`error_settings`]).
pub const ERROR_RTOL: f64 = 1e-7;

/// Absolute tolerance of the simulations behind a trajectory fit's standard errors, at the
/// loosest: the default's.
pub const ERROR_ATOL: f64 = 1e-9;

/// The integrator settings of the simulations behind the standard errors of a fit whose
/// simulations use `sim`: its tolerances tightened to [`ERROR_RTOL`] and [`ERROR_ATOL`], or
/// `None` when they are no looser.
///
/// A difference column's noise is the integrator's error, which jumps as the adaptive steps
/// change with the parameter; the noise probe of [`residual_noise`] (a millionth of each
/// parameter's scale) changes few steps and sees little of it. On the Silverbox-layout record
/// (87 000 samples in volts) a fit at `rtol` 1e-5 gave the cubic stiffness an error bar four
/// times smaller than at 1e-7 (its column partly the integrator's error) and no warning.
/// So a fit may run at a loose tolerance, but its Jacobian is computed at these.
pub fn error_settings(sim: &Settings) -> Option<Settings> {
    (sim.rtol > ERROR_RTOL || sim.atol > ERROR_ATOL).then(|| Settings {
        rtol: sim.rtol.min(ERROR_RTOL),
        atol: sim.atol.min(ERROR_ATOL),
        ..sim.clone()
    })
}

/// Change a difference step must make in the residuals, in multiples of their noise
/// (rms over the samples): the noise then contributes about `√2 / SIGNAL_TO_NOISE` (5 %)
/// to the column.
pub const SIGNAL_TO_NOISE: f64 = 30.0;

/// Tries at lengthening one column's step before the column is taken as it is.
const LENGTHEN_TRIES: usize = 3;

/// An evaluation of the residuals: `eval(x, out)` writes them to `out`, false on failure.
/// Shared across threads: the columns of a Jacobian are evaluated in parallel.
pub type Eval<'a> = &'a (dyn Fn(&[f64], &mut [f64]) -> bool + Sync);

/// The noise of the residuals at `x` (rms per residual), from a second difference along all
/// parameters at once: `r(x + e) + r(x − e) − 2·r(x)` with `e_j = probe[j]` cancels the
/// residuals' slope and leaves their noise (variance 6σ²) plus a curvature term of order
/// `probe²`, negligible for probes of 1e-6 of a scale. `None` if an evaluation fails. The two
/// evaluations run in parallel.
pub fn residual_noise(x: &[f64], r0: &[f64], probe: &[f64], eval: Eval) -> Option<f64> {
    let n = r0.len();
    let side = |sign: f64| {
        let point: Vec<f64> = x.iter().zip(probe).map(|(x, e)| x + sign * e).collect();
        let mut out = vec![0.0; n];
        eval(&point, &mut out).then_some(out)
    };
    let (plus, minus) = rayon::join(|| side(1.0), || side(-1.0));
    let (plus, minus) = (plus?, minus?);
    let ss: f64 = plus
        .iter()
        .zip(&minus)
        .zip(r0)
        .map(|((p, m), r)| (p + m - 2.0 * r).powi(2))
        .sum();
    let sigma = (ss / (6.0 * n.max(1) as f64)).sqrt();
    sigma.is_finite().then_some(sigma)
}

/// How long the steps of a Jacobian may grow to rise above the residuals' noise.
#[derive(Clone, Debug)]
pub struct StepFloor {
    /// Noise of the residuals, rms per residual (0: noiseless, steps never grow).
    pub noise: f64,
    /// Longest step of each parameter (same units as the steps).
    pub max: Vec<f64>,
}

/// Fill `jac` (N × p) with ∂r/∂x_j at `x`, where `r0` are the residuals at `x`, `steps[j]`
/// the step of parameter j and `eval(x, out)` computes residuals (false on failure).
/// `flip(j, x)` tells whether parameter j's step must go the other way (a bound ahead).
/// A column whose rms change is below `SIGNAL_TO_NOISE × floor.noise` is recomputed with a
/// longer step (up to `floor.max[j]`); the steps used are written back to `steps`, so a
/// caller that keeps them starts the next Jacobian from there. Columns marked in `exact` are
/// left as they are (known exactly). The columns are computed in parallel, after
/// `prefetch` is handed their first points (all at once: a problem whose evaluations share
/// work prepares it there; see [`super::objective::Residuals::prefetch`]).
///
/// Returns how far each column's change stands above the noise (its rms change over
/// `floor.noise`; infinite for an exact column or noiseless residuals): a column below
/// [`SIGNAL_TO_NOISE`] is partly noise, one below 1 mostly noise.
#[allow(clippy::too_many_arguments)]
pub fn forward_difference(
    x: &[f64],
    r0: &[f64],
    steps: &mut [f64],
    floor: &StepFloor,
    flip: &(dyn Fn(usize, f64) -> bool + Sync),
    eval: Eval,
    exact: &[bool],
    jac: &mut DMatrix<f64>,
    prefetch: &(dyn Fn(&[Vec<f64>]) + Sync),
) -> Vec<f64> {
    let todo: Vec<usize> = (0..steps.len())
        .filter(|&j| !exact.get(j).copied().unwrap_or(false))
        .collect();
    // Each column's first point, as `column` computes it: the problem may prepare them at once.
    if todo.len() >= 2 {
        let points: Vec<Vec<f64>> = todo
            .iter()
            .map(|&j| {
                let h0 = steps[j].abs();
                let h = if flip(j, x[j] + h0) { -h0 } else { h0 };
                let mut point = x.to_vec();
                point[j] = x[j] + h;
                point
            })
            .collect();
        prefetch(&points);
    }
    let columns: Vec<(usize, f64, Vec<f64>)> = todo
        .par_iter()
        .map(|&j| {
            let longest = floor.max.get(j).copied().unwrap_or(0.0);
            let (h, col) = column(x, r0, j, steps[j].abs(), longest, floor.noise, flip, eval);
            (j, h, col)
        })
        .collect();
    let mut rise = vec![f64::INFINITY; steps.len()];
    let n = r0.len().max(1) as f64;
    for (j, h, col) in columns {
        let change = h * (col.iter().map(|c| c * c).sum::<f64>() / n).sqrt();
        if floor.noise > 0.0 {
            rise[j] = change / floor.noise;
        }
        steps[j] = h;
        jac.column_mut(j).copy_from_slice(&col);
    }
    rise
}

/// Column `j` of the forward-difference Jacobian from a step of `h0`, lengthened (up to
/// `longest`) while its change stays below [`SIGNAL_TO_NOISE`] × `noise`: the step used and
/// the column (NaN throughout when no step could be evaluated).
#[allow(clippy::too_many_arguments)]
fn column(
    x: &[f64],
    r0: &[f64],
    j: usize,
    mut h0: f64,
    longest: f64,
    noise: f64,
    flip: &(dyn Fn(usize, f64) -> bool + Sync),
    eval: Eval,
) -> (f64, Vec<f64>) {
    let n = r0.len().max(1) as f64;
    let wanted = SIGNAL_TO_NOISE * noise;
    let mut point = x.to_vec();
    let mut col = vec![0.0; r0.len()];
    let mut ok = false;
    for attempt in 0..=LENGTHEN_TRIES {
        let mut h = if flip(j, x[j] + h0) { -h0 } else { h0 };
        ok = false;
        for _ in 0..2 {
            point[j] = x[j] + h;
            let dx = point[j] - x[j];
            if dx != 0.0 && eval(&point, &mut col) {
                for (c, r) in col.iter_mut().zip(r0) {
                    *c = (*c - r) / dx;
                }
                ok = true;
                break;
            }
            h = -h;
        }
        point[j] = x[j];
        if !ok || attempt == LENGTHEN_TRIES || h0 >= longest {
            break;
        }
        // The rms change this step made, against the noise it must stand above.
        let change = h0 * (col.iter().map(|c| c * c).sum::<f64>() / n).sqrt();
        if !(change < wanted) {
            break;
        }
        let grow = if change > 0.0 { wanted / change } else { 10.0 };
        h0 = (h0 * grow.clamp(2.0, 10.0)).min(longest);
    }
    if !ok {
        col.fill(f64::NAN);
    }
    (h0, col)
}
