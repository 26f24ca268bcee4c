//! Force-level estimates freed of the derivative filter's noise (SIMEX).
//!
//! At force level, v and a are estimated from the noisy x by the derivative filter, and enter
//! the model: errors in the variables. Their noise (σ_v of about 1 mm/s on the rig's records)
//! pulls the estimates of a nonlinear damping law off the truth by about σ_v² — a bias the
//! residuals cannot show, which no covariance of them accounts for: over 40 noise seeds of a
//! power law on the source study's sweep, K and n came out 0.5–1.3 standard errors low.
//!
//! Simulation–extrapolation (SIMEX, Cook & Stefanski 1994) measures that bias on the record
//! itself: the fit is repeated on copies of the record whose x carries `replicates` fresh
//! draws of noise as large as its own (σ_x), filtered as the record was, so that v and a carry
//! twice the noise variance. The bias grows with that variance, to first order linearly, so
//! the estimate at none is extrapolated: `θ̂ = 2·θ₁ − mean(θ₂)` (θ₁ the record's fit, θ₂ the
//! copies'). The standard error adds the extrapolation's own spread, `var(θ₂)/replicates`.
//! The filter's own attenuation of v is left alone: on the rig's records it moves the
//! estimates by less than 0.03 of a standard error.

use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

use super::error::FitError;
use super::force_fit::ForceFit;
use super::result::FitResult;
use crate::data::force_data::ForceData;
use crate::numerics::derivative::{sample_step, PolyFilter};

/// How the kinematics of a force-level fit were made from x: the derivative filter and the
/// position noise it was fed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterNoise {
    /// The derivative filter that made v and a from x.
    pub filter: PolyFilter,
    /// The position noise σ_x, m.
    pub sigma_x: f64,
    /// Re-noised copies of the record fitted (0: no correction).
    pub replicates: usize,
}

/// Re-noised copies of the record a correction fits by default: their spread adds
/// `1/REPLICATES` of the noise's own share to the variance.
pub const REPLICATES: usize = 4;

/// The seed of the copies' noise: fits stay deterministic.
const SEED: u64 = 0x5eed_f17e;

impl FilterNoise {
    /// The filter `filter` fed x with noise `sigma_x`, corrected over [`REPLICATES`] copies.
    pub fn new(filter: PolyFilter, sigma_x: f64) -> Self {
        FilterNoise {
            filter,
            sigma_x,
            replicates: REPLICATES,
        }
    }
}

/// `result` (the fit of `fit` to `data`) with its estimates corrected for the filter's noise
/// and their standard errors widened by the correction's spread, as the module says. A fit
/// without noise, without free parameters, or one whose copies do not fit, is returned as it
/// is (the log says why). Parameters held by a bound or without a finite error keep their
/// values; corrected ones stay within their bounds. RSS, RMS, AIC and BIC are those of the
/// corrected values.
pub fn correct(
    fit: &ForceFit,
    data: &ForceData,
    noise: &FilterNoise,
    mut result: FitResult,
) -> Result<FitResult, FitError> {
    let free: Vec<usize> = (0..result.params.len())
        .filter(|&j| !result.params[j].fixed)
        .collect();
    if !(noise.sigma_x > 0.0) || noise.replicates < 2 || free.is_empty() {
        return Ok(result);
    }
    let dt = sample_step(data.t).map_err(|e| FitError::BadData(e.to_string()))?;
    let start = fit.started_at(&result.params.iter().map(|p| p.value).collect::<Vec<_>>());
    let draws = copies(&start, data, noise, dt)?;
    let Some(draws) = draws else {
        result
            .log
            .push("filter noise: a re-noised copy did not fit; estimates left as fitted".into());
        return Ok(result);
    };
    let bounds = fit.params();
    let b = draws.len() as f64;
    let mut moved = Vec::new();
    for &j in &free {
        let p = &mut result.params[j];
        if p.held_by.is_some() || !p.std_error.is_finite() {
            continue;
        }
        let mean = draws.iter().map(|d| d[j]).sum::<f64>() / b;
        let spread = draws.iter().map(|d| (d[j] - mean).powi(2)).sum::<f64>() / (b - 1.0);
        let value = (2.0 * p.value - mean).clamp(bounds[j].min, bounds[j].max);
        moved.push(format!(
            "{} {:+.3}σ",
            p.name,
            (value - p.value) / p.std_error
        ));
        p.value = value;
        p.std_error = (p.std_error.powi(2) + spread / b).sqrt();
    }
    let values: Vec<f64> = result.params.iter().map(|p| p.value).collect();
    let predicted = fit.predict(data, &values)?;
    let rss: f64 = data
        .f
        .iter()
        .zip(&predicted)
        .map(|(f, m)| (f - m).powi(2))
        .sum();
    if rss > 0.0 && result.rss > 0.0 {
        let shift = result.n_points as f64 * (rss / result.rss).ln();
        result.aic += shift;
        result.bic += shift;
    }
    result.rss = rss;
    result.rms = (rss / result.n_points.max(1) as f64).sqrt();
    result.log.push(format!(
        "filter noise: estimates corrected by simulation–extrapolation over {} copies of x \
         re-noised by σ_x = {:.3e} m ({})",
        draws.len(),
        noise.sigma_x,
        moved.join(", ")
    ));
    Ok(result)
}

/// The values (all parameters, in the fit's order) `start` reaches on each of the re-noised
/// copies of `data`; `None` if one did not converge.
fn copies(
    start: &ForceFit,
    data: &ForceData,
    noise: &FilterNoise,
    dt: f64,
) -> Result<Option<Vec<Vec<f64>>>, FitError> {
    let mut rng = StdRng::seed_from_u64(SEED);
    let normal = Normal::new(0.0, noise.sigma_x)
        .map_err(|e| FitError::BadData(format!("position noise {}: {e}", noise.sigma_x)))?;
    let mut draws = Vec::with_capacity(noise.replicates);
    for _ in 0..noise.replicates {
        let x: Vec<f64> = data.x.iter().map(|x| x + normal.sample(&mut rng)).collect();
        let d = noise
            .filter
            .apply(dt, &x)
            .map_err(|e| FitError::BadData(e.to_string()))?;
        let copy = ForceData::new(data.t, &x, &d.d1, &d.d2, data.f);
        let r = start.fit_plain(&copy)?;
        if !r.convergence.converged() {
            return Ok(None);
        }
        draws.push(r.params.iter().map(|p| p.value).collect());
    }
    Ok(Some(draws))
}
