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

use super::global_file::Law;

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
    pub fn data(&self) -> stf_core::data::force_data::ForceData<'_> {
        stf_core::data::force_data::ForceData {
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

/// θ's layout for the `shared` parameters and the `laws` over `records` (each named by its unit number), the model's
/// parameters `model_params` (configured: start values and bounds) and the offset, if fitted.
/// `starts` gives per record the values its own fit found (same order), to start from.
pub fn layout(
    shared: &[String],
    laws: &[Law],
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
        let law = laws.iter().position(|l| l.param == p.name);
        if let Some((index, law)) = law.filter(|_| !p.fixed).map(|i| (i, &laws[i])) {
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
        } else if p.fixed || shared.contains(&p.name) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use stf_core::physics::force_model::{ModelError, ModelState};
    use stf_core::physics::param_spec::ParamSpec;

    /// f = a·v + b·x.
    struct Lin(Vec<ParamSpec>);

    impl ForceModel for Lin {
        fn name(&self) -> &str {
            "lin"
        }
        fn params(&self) -> &[ParamSpec] {
            &self.0
        }
        fn force(&self, p: &[f64], s: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
            Ok(p[0] * s.v + p[1] * s.x)
        }
    }

    fn model() -> Arc<dyn ForceModel> {
        Arc::new(Lin(vec![
            ParamSpec::new("a", "N·s/m", 1.0, 0.0, 100.0, ""),
            ParamSpec::new("b", "N/m", 1.0, -10.0, 10.0, ""),
        ]))
    }

    /// A record at condition `c` whose force is exactly `a·v + b·x`.
    fn record(c: f64, a: f64, b: f64) -> JointRecord {
        let t: Vec<f64> = (0..400).map(|i| i as f64 * 0.01).collect();
        let x: Vec<f64> = t.iter().map(|t| (3.0 * t).sin()).collect();
        let v: Vec<f64> = t.iter().map(|t| 3.0 * (3.0 * t).cos()).collect();
        let f = x.iter().zip(&v).map(|(x, v)| a * v + b * x).collect();
        let params: Vec<FitParam> = model().params().iter().map(FitParam::from_spec).collect();
        JointRecord {
            a: vec![0.0; t.len()],
            t,
            x,
            v,
            f,
            fit: predictor(model(), &params, false),
            conditions: vec![("c".into(), c)],
        }
    }

    #[test]
    fn a_law_and_a_shared_parameter_are_recovered_jointly() {
        // a = 3·(c/2)^1.5, b = 0.7 on every record.
        let records: Vec<JointRecord> = [1.0, 2.0, 3.0]
            .iter()
            .map(|&c| record(c, 3.0 * (c / 2.0_f64).powf(1.5), 0.7))
            .collect();
        let numbered: Vec<(usize, &JointRecord)> = records.iter().enumerate().collect();
        let laws = [Law {
            param: "a".into(),
            condition: "c".into(),
            reference: 2.0,
        }];
        let params: Vec<FitParam> = model().params().iter().map(FitParam::from_spec).collect();
        let starts = vec![vec![1.0, 1.0]; 3];
        let layout = layout(&["b".into()], &laws, &params, None, &numbered, &starts);
        let names: Vec<&str> = layout.params.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["a0", "a_p", "b"]);
        assert_eq!(layout.roles, ["law coefficient", "law exponent", "shared"]);
        let refs: Vec<&JointRecord> = records.iter().collect();
        let result = fit(&layout, &refs, &Default::default()).unwrap();
        for (name, truth) in [("a0", 3.0), ("a_p", 1.5), ("b", 0.7)] {
            let v = result.value(name).unwrap();
            assert!((v - truth).abs() < 1e-6, "{name} = {v}");
        }
        assert_eq!(result.n_points, 1200);
    }

    #[test]
    fn a_parameter_neither_shared_nor_a_law_stays_per_record() {
        let records: Vec<JointRecord> = [(1.0, 2.0), (2.0, -1.0)]
            .iter()
            .map(|&(c, b)| record(c, 1.5, b))
            .collect();
        let numbered: Vec<(usize, &JointRecord)> = records
            .iter()
            .enumerate()
            .map(|(i, r)| (i + 4, r))
            .collect();
        let params: Vec<FitParam> = model().params().iter().map(FitParam::from_spec).collect();
        let starts = vec![vec![1.0, 1.0]; 2];
        let layout = layout(&["a".into()], &[], &params, None, &numbered, &starts);
        let names: Vec<&str> = layout.params.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["a", "b@4", "b@5"]);
        let refs: Vec<&JointRecord> = records.iter().collect();
        let result = fit(&layout, &refs, &Default::default()).unwrap();
        assert!((result.value("b@4").unwrap() - 2.0).abs() < 1e-6);
        assert!((result.value("b@5").unwrap() + 1.0).abs() < 1e-6);
        assert!((result.value("a").unwrap() - 1.5).abs() < 1e-6);
    }
}
