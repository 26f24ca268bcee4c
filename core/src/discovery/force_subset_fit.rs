//! A force-level fit scored on a subset of the samples only.
//!
//! A model with internal state is evaluated along the whole record (so its state evolves
//! through the held-out cycles as it would in reality), a memoryless one at the chosen samples
//! only; only the residuals of the chosen samples enter the least squares. With every sample
//! chosen this is an ordinary [`ForceFit`].

use crate::data::force_data::ForceData;
use crate::fit::{FitResult, FitSettings, ForceFit};

/// Fit `fit`'s parameters (its own settings are not used: `settings` are) on the samples
/// `subset` of `data` (strictly increasing); statistics (RMS, AIC, BIC, standard errors) are
/// those of the subset.
pub(crate) fn fit_subset(
    fit: &ForceFit,
    data: &ForceData,
    subset: &[usize],
    settings: &FitSettings,
) -> Result<FitResult, crate::fit::FitError> {
    fit.fit_rows(data, Some(subset), settings, None)
}

/// Measured minus modelled force at every sample, for the full parameter vector `values`.
pub(crate) fn residuals(
    fit: &ForceFit,
    data: &ForceData,
    values: &[f64],
) -> Result<Vec<f64>, crate::fit::FitError> {
    let predicted = fit.predict(data, values)?;
    Ok(data.f.iter().zip(&predicted).map(|(m, p)| m - p).collect())
}

/// RMS of `r` over the samples `subset` (0 for an empty subset).
pub(crate) fn rms_over(r: &[f64], subset: &[usize]) -> f64 {
    if subset.is_empty() {
        return 0.0;
    }
    let ss: f64 = subset.iter().map(|&i| r[i] * r[i]).sum();
    (ss / subset.len() as f64).sqrt()
}

/// RMS of all of `r` (0 when empty).
pub(crate) fn rms(r: &[f64]) -> f64 {
    if r.is_empty() {
        return 0.0;
    }
    (r.iter().map(|v| v * v).sum::<f64>() / r.len() as f64).sqrt()
}
