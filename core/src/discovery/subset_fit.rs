//! A force-level fit scored on a subset of the samples only.
//!
//! The model is always evaluated along the whole record (so a model with internal state
//! evolves through the held-out cycles as it would in reality), and only the residuals of the
//! chosen samples enter the least squares. With every sample chosen this is an ordinary
//! [`ForceFit`].

use crate::fit::{
    fit_residuals, full_values, FitParam, FitResult, FitSettings, ForceData, ForceFit, Residuals,
};

/// The residuals of `fit` (all its parameters in `params`) at the samples `subset`.
struct SubsetResiduals<'a> {
    fit: &'a ForceFit,
    params: &'a [FitParam],
    data: ForceData<'a>,
    subset: &'a [usize],
}

impl Residuals for SubsetResiduals<'_> {
    fn len(&self) -> usize {
        self.subset.len()
    }

    fn residuals(&self, x: &[f64], sink: &mut dyn FnMut(usize, f64)) -> Result<(), String> {
        let full = full_values(self.params, x)?;
        let predicted = self
            .fit
            .predict(&self.data, &full)
            .map_err(|e| e.to_string())?;
        for (k, &i) in self.subset.iter().enumerate() {
            let r = self.data.f[i] - predicted[i];
            if !r.is_finite() {
                return Err(format!("non-finite force at sample {i}"));
            }
            sink(k, r);
        }
        Ok(())
    }
}

/// Fit `fit`'s parameters (its own settings are not used: `settings` are) on the samples
/// `subset` of `data`; statistics (RMS, AIC, BIC,
/// standard errors) are those of the subset.
pub(crate) fn fit_subset(
    fit: &ForceFit,
    data: &ForceData,
    subset: &[usize],
    settings: &FitSettings,
) -> Result<FitResult, crate::fit::FitError> {
    let params = fit.params();
    let problem = SubsetResiduals {
        fit,
        params: &params,
        data: *data,
        subset,
    };
    fit_residuals(&problem, &params, settings, None)
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
