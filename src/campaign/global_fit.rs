//! The joint force-level fit of `[global]`: every training record's measured F_STF against
//! the model's force along its kinematics, in one least-squares problem over
//! θ = (shared parameters, each law's coefficient `P0` and exponent `P_p`, the per-record
//! parameters `P@N` of unit N). It runs through the core's generic fitter
//! ([`stf_core::fit::fit_residuals`]: the same solver stages, Levenberg–Marquardt refinement and
//! block-robust standard errors as every per-record fit), each record's residuals predicted
//! by a [`ForceFit`] built as the per-record `fit` builds it.
//!
//! The residuals of all records are laid end to end, so the covariance's blocks of
//! consecutive samples may straddle two records at a boundary: a handful of blocks among
//! hundreds, taken as correlated when they are not, which errs on the side of larger errors.

use std::sync::Arc;

use anyhow::{Context, Result};
use stf_core::fit::{
    fit_residuals, full_values, FitParam, FitResult, ForceFit, Residuals, FORCE_OFFSET,
};
use stf_core::physics::force_model::ForceModel;

use super::global_file::{GlobalSpec, Law};

/// Where one value of a record's parameter vector comes from.
#[derive(Clone, Debug)]
pub enum Source {
    /// θ's `i`-th entry.
    Theta(usize),
    /// `θ[coefficient]·ratio^θ[exponent]`, `ratio` the record's condition over the reference.
    Law {
        /// Index of `P0` in θ.
        coefficient: usize,
        /// Index of `P_p` in θ.
        exponent: usize,
        /// The record's condition / the law's reference.
        ratio: f64,
        /// Index of the law in `GlobalSpec::laws`.
        law: usize,
    },
}

impl Source {
    /// The value at θ.
    pub fn value(&self, theta: &[f64]) -> f64 {
        match *self {
            Source::Theta(i) => theta[i],
            Source::Law {
                coefficient,
                exponent,
                ratio,
                ..
            } => theta[coefficient] * ratio.powf(theta[exponent]),
        }
    }
}

/// One record in the joint problem: its force data and how θ maps to its parameters.
pub struct JointRecord {
    /// The record's times, kinematics and measured force.
    pub t: Vec<f64>,
    /// Displacement, m.
    pub x: Vec<f64>,
    /// Velocity, m/s.
    pub v: Vec<f64>,
    /// Acceleration, m/s².
    pub a: Vec<f64>,
    /// Measured F_STF, N.
    pub f: Vec<f64>,
    /// The predictor (the model's parameters, then the offset if any).
    pub fit: ForceFit,
    /// The record's conditions, by name.
    pub conditions: Vec<(String, f64)>,
}

impl JointRecord {
    /// The record's force data.
    pub fn data(&self) -> stf_core::fit::ForceData<'_> {
        stf_core::fit::ForceData {
            t: &self.t,
            x: &self.x,
            v: &self.v,
            a: &self.a,
            f: &self.f,
        }
    }

    /// The value of a condition (NaN if the record lacks it).
    pub fn condition(&self, name: &str) -> f64 {
        self.conditions
            .iter()
            .find(|(n, _)| n == name)
            .map_or(f64::NAN, |(_, v)| *v)
    }
}

/// θ's layout: its parameters, and per record the sources of its parameter vector.
pub struct Layout {
    /// Every entry of θ (free and fixed).
    pub params: Vec<FitParam>,
    /// What each entry is: `shared`, `law coefficient`, `law exponent`, `per record`.
    pub roles: Vec<&'static str>,
    /// Per training record, the sources of its values (model's parameters, then offset).
    pub sources: Vec<Vec<Source>>,
}

/// The name of a law's exponent for parameter `p`.
pub fn exponent_name(p: &str) -> String {
    format!("{p}_p")
}

/// The name of a law's coefficient for parameter `p`.
pub fn coefficient_name(p: &str) -> String {
    format!("{p}0")
}

/// θ's layout for `spec` over `records` (each named by its unit number), the model's
/// parameters `model_params` (configured: start values and bounds) and the offset, if fitted.
/// `starts` gives per record the values its own fit found (same order), to start from.
pub fn layout(
    spec: &GlobalSpec,
    model_params: &[FitParam],
    offset: Option<&FitParam>,
    records: &[(usize, &JointRecord)],
    starts: &[Vec<f64>],
) -> Layout {
    let mut all: Vec<FitParam> = model_params.to_vec();
    all.extend(offset.cloned());
    let mut params = Vec::new();
    let mut roles = Vec::new();
    let mut sources = vec![Vec::new(); records.len()];
    for (k, p) in all.iter().enumerate() {
        let column: Vec<f64> = starts.iter().map(|s| s[k]).collect();
        let law = spec.laws.iter().position(|l| l.param == p.name);
        if let Some((index, law)) = law.filter(|_| !p.fixed).map(|i| (i, &spec.laws[i])) {
            let (c0, expo) = law_start(law, p, records, &column);
            let i = params.len();
            params.push(clamped(p.clone(), c0).named(coefficient_name(&p.name)));
            params.push(
                FitParam::new(exponent_name(&p.name), expo)
                    .bounds(-50.0, 50.0)
                    .scale(1.0),
            );
            roles.extend(["law coefficient", "law exponent"]);
            for (j, (_, r)) in records.iter().enumerate() {
                sources[j].push(Source::Law {
                    coefficient: i,
                    exponent: i + 1,
                    ratio: r.condition(&law.condition) / law.reference,
                    law: index,
                });
            }
        } else if p.fixed || spec.shared.contains(&p.name) {
            let mean = column.iter().sum::<f64>() / column.len().max(1) as f64;
            let start = if p.fixed { p.value } else { mean };
            for s in &mut sources {
                s.push(Source::Theta(params.len()));
            }
            params.push(clamped(p.clone(), start));
            roles.push("shared");
        } else {
            for (j, (unit, _)) in records.iter().enumerate() {
                sources[j].push(Source::Theta(params.len()));
                params.push(clamped(p.clone(), column[j]).named(format!("{}@{unit}", p.name)));
                roles.push("per record");
            }
        }
    }
    Layout {
        params,
        roles,
        sources,
    }
}

/// Renaming a fit parameter.
trait Named {
    fn named(self, name: String) -> Self;
}

impl Named for FitParam {
    fn named(mut self, name: String) -> Self {
        self.name = name;
        self
    }
}

/// `p` starting at `value`, kept strictly inside its bounds (a start on a bound stalls the
/// bound transform); its own start if `value` is not finite.
fn clamped(p: FitParam, value: f64) -> FitParam {
    if !value.is_finite() || p.fixed {
        return p;
    }
    let (lo, hi) = (p.min, p.max);
    let margin = if lo.is_finite() && hi.is_finite() {
        1e-6 * (hi - lo)
    } else {
        0.0
    };
    let v = value.clamp(lo + margin, hi - margin);
    p.value(v)
}

/// A law's start: the least-squares line of ln P against ln(c/reference) over the records'
/// own fits (the configured start and exponent 0 if any is not positive).
fn law_start(
    law: &Law,
    p: &FitParam,
    records: &[(usize, &JointRecord)],
    column: &[f64],
) -> (f64, f64) {
    let pts: Vec<(f64, f64)> = records
        .iter()
        .zip(column)
        .map(|((_, r), v)| ((r.condition(&law.condition) / law.reference).ln(), v.ln()))
        .collect();
    if pts.iter().any(|(x, y)| !x.is_finite() || !y.is_finite()) || pts.len() < 2 {
        return (p.value, 0.0);
    }
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    if sxx <= 0.0 {
        return (my.exp(), 0.0);
    }
    let slope = sxy / sxx;
    ((my - slope * mx).exp(), slope)
}

/// The joint least-squares problem.
struct Joint<'a> {
    params: &'a [FitParam],
    records: Vec<&'a JointRecord>,
    sources: &'a [Vec<Source>],
    /// Where each record's residuals start.
    starts: Vec<usize>,
    len: usize,
}

impl Residuals for Joint<'_> {
    fn len(&self) -> usize {
        self.len
    }

    fn residuals(&self, x: &[f64], sink: &mut dyn FnMut(usize, f64)) -> Result<(), String> {
        let theta = full_values(self.params, x)?;
        for ((r, sources), &start) in self.records.iter().zip(self.sources).zip(&self.starts) {
            let values: Vec<f64> = sources.iter().map(|s| s.value(&theta)).collect();
            let predicted = r
                .fit
                .predict(&r.data(), &values)
                .map_err(|e| e.to_string())?;
            for (i, (f, p)) in r.f.iter().zip(&predicted).enumerate() {
                sink(start + i, f - p);
            }
        }
        Ok(())
    }
}

/// Fit θ of `layout` to `records` (in the layout's order) with `settings`.
pub fn fit(
    layout: &Layout,
    records: &[&JointRecord],
    settings: &stf_core::fit::FitSettings,
) -> Result<FitResult> {
    let mut starts = Vec::with_capacity(records.len());
    let mut len = 0;
    for r in records {
        starts.push(len);
        len += r.f.len();
    }
    let problem = Joint {
        params: &layout.params,
        records: records.to_vec(),
        sources: &layout.sources,
        starts,
        len,
    };
    fit_residuals(&problem, &layout.params, settings, None).context("the global fit")
}

/// A record's predictor as the per-record `fit` builds it: the model with its configured
/// parameters, and the offset `f_off` when the experiment fits one.
pub fn predictor(model: Arc<dyn ForceModel>, params: &[FitParam], offset: bool) -> ForceFit {
    let mut fit = ForceFit::new(model);
    for p in params {
        fit = fit.param(p.clone());
    }
    if offset {
        fit = fit.offset(FitParam::new(FORCE_OFFSET, 0.0).bounds(-100.0, 100.0));
    }
    fit
}

/// The force RMS of `values` (model's, then offset) predicting `record`.
pub fn rms_of(record: &JointRecord, values: &[f64]) -> Result<f64> {
    let predicted = record.fit.predict(&record.data(), values)?;
    let n = record.f.len().max(1) as f64;
    let ss: f64 = record
        .f
        .iter()
        .zip(&predicted)
        .map(|(f, p)| (f - p).powi(2))
        .sum();
    Ok((ss / n).sqrt())
}
