//! A parameter of a fit: start value, bounds, fixed or free, typical size.

use derive_setters::Setters;
use serde::Serialize;

use super::error::FitError;
use super::transform::BoundTransform;
use crate::physics::param_spec::ParamSpec;

/// Which bound of a parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BoundSide {
    /// The lower bound.
    Lower,
    /// The upper bound.
    Upper,
}

impl BoundSide {
    /// `lower` or `upper`.
    pub fn name(self) -> &'static str {
        match self {
            BoundSide::Lower => "lower",
            BoundSide::Upper => "upper",
        }
    }
}

/// One parameter of a fit, as the user gives it.
///
/// ```
/// use stf_core::fit::FitParam;
/// let k = FitParam::new("k", 250.0).bounds(100.0, 400.0);
/// let m = FitParam::new("m", 7.65).fixed(true);
/// assert!(!k.fixed && m.fixed);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Setters)]
pub struct FitParam {
    /// Name: an oscillator parameter (`k`), a model parameter (`K`, `power_law.K`) or an
    /// offset (`x_off`, `f_off`).
    #[setters(skip)]
    pub name: String,
    /// Start value (the value used if fixed).
    pub value: f64,
    /// Lower bound (`-inf`: none).
    #[setters(skip)]
    pub min: f64,
    /// Upper bound (`inf`: none).
    #[setters(skip)]
    pub max: f64,
    /// Held at `value`, not fitted.
    pub fixed: bool,
    /// Typical size of the parameter, for the initial simplex, the global search box and
    /// finite-difference steps; `None`: |value|, or a tenth of the bounds' width if the value
    /// is 0, or 1.
    #[setters(strip_option)]
    pub scale: Option<f64>,
}

/// The value of every parameter of `params`, in order: a fixed one's own value, a free one's
/// from `free` (the free values in order); an error if `free` is too short.
///
/// ```
/// use stf_core::fit::{full_values, FitParam};
/// let params = [FitParam::new("a", 1.0).fixed(true), FitParam::new("b", 2.0)];
/// assert_eq!(full_values(&params, &[5.0]).unwrap(), vec![1.0, 5.0]);
/// assert!(full_values(&params, &[]).is_err());
/// ```
pub fn full_values(params: &[FitParam], free: &[f64]) -> Result<Vec<f64>, String> {
    let mut free = free.iter();
    params
        .iter()
        .map(|p| {
            if p.fixed {
                Ok(p.value)
            } else {
                free.next()
                    .copied()
                    .ok_or_else(|| "too few free values".to_string())
            }
        })
        .collect()
}

/// `params` held at `values` (one per parameter, in order): each fixed at its value; an
/// error naming both counts if they differ.
pub(crate) fn held(params: &[FitParam], values: &[f64]) -> Result<Vec<FitParam>, FitError> {
    if values.len() != params.len() {
        return Err(FitError::BadData(format!(
            "{} values given for {} parameters",
            values.len(),
            params.len()
        )));
    }
    let hold = |(p, &value): (&FitParam, &f64)| FitParam {
        value,
        fixed: true,
        ..p.clone()
    };
    Ok(params.iter().zip(values).map(hold).collect())
}

impl FitParam {
    /// A free, unbounded parameter starting at `value`.
    pub fn new(name: impl Into<String>, value: f64) -> Self {
        FitParam {
            name: name.into(),
            value,
            min: f64::NEG_INFINITY,
            max: f64::INFINITY,
            fixed: false,
            scale: None,
        }
    }

    /// A free parameter with the default and bounds of a model's spec.
    pub fn from_spec(spec: &ParamSpec) -> Self {
        FitParam::new(spec.name.clone(), spec.default).bounds(spec.min, spec.max)
    }

    /// Bounds (either may be infinite).
    pub fn bounds(mut self, min: f64, max: f64) -> Self {
        self.min = min;
        self.max = max;
        self
    }

    /// Check bounds and start value.
    pub fn check(&self) -> Result<(), FitError> {
        if self.min.partial_cmp(&self.max) != Some(std::cmp::Ordering::Less) {
            return Err(FitError::BadBounds {
                name: self.name.clone(),
                min: self.min,
                max: self.max,
            });
        }
        if !(self.value.is_finite() && self.value >= self.min && self.value <= self.max) {
            return Err(FitError::OutOfBounds {
                name: self.name.clone(),
                value: self.value,
                min: self.min,
                max: self.max,
            });
        }
        if let Some(s) = self.scale {
            if !(s > 0.0 && s.is_finite()) {
                return Err(FitError::BadSettings(format!(
                    "parameter `{}`: scale must be positive and finite (got {s})",
                    self.name
                )));
            }
        }
        Ok(())
    }

    /// The typical size used when none is given.
    pub fn effective_scale(&self) -> f64 {
        if let Some(s) = self.scale {
            return s;
        }
        if self.value != 0.0 {
            self.value.abs()
        } else if self.min.is_finite() && self.max.is_finite() {
            0.1 * (self.max - self.min)
        } else {
            1.0
        }
    }

    /// The change of variables that keeps this parameter inside its bounds.
    pub fn transform(&self) -> BoundTransform {
        BoundTransform::new(self.value, self.min, self.max, self.effective_scale())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validation_names_the_fault() {
        assert!(FitParam::new("a", 1.0).check().is_ok());
        assert!(matches!(
            FitParam::new("a", 1.0).bounds(2.0, 1.0).check(),
            Err(FitError::BadBounds { .. })
        ));
        assert!(matches!(
            FitParam::new("a", 5.0).bounds(0.0, 1.0).check(),
            Err(FitError::OutOfBounds { .. })
        ));
        assert!(matches!(
            FitParam::new("a", f64::NAN).check(),
            Err(FitError::OutOfBounds { .. })
        ));
        assert!(FitParam::new("a", 1.0).scale(0.0).check().is_err());
        assert!(FitParam::new("a", 1.0).bounds(1.0, 2.0).check().is_ok());
    }

    #[test]
    fn default_scale_follows_the_value_then_the_bounds() {
        assert_eq!(FitParam::new("a", -3.0).effective_scale(), 3.0);
        assert_eq!(
            FitParam::new("a", 0.0).bounds(0.0, 10.0).effective_scale(),
            1.0
        );
        assert_eq!(FitParam::new("a", 0.0).effective_scale(), 1.0);
        assert_eq!(FitParam::new("a", 0.0).scale(1e-3).effective_scale(), 1e-3);
    }
}
