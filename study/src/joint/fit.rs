//! The joint fit of `[global]`: every training record's measured signal against its
//! prediction, in one least-squares problem over θ = (shared parameters, each law's
//! coefficient `P0` and exponent `P_p`, the per-record parameters `P@N` of unit N). At force
//! level a record's measured F_STF is predicted along its kinematics by a [`ForceFit`] built as
//! the per-record `fit` builds it; at trajectory level its measured x by simulating its
//! oscillator with a [`TrajectoryFit`], the one its own `fit` ran. It runs through the core's
//! generic fitter ([`stf_core::fit::fit_residuals`], at trajectory level
//! [`stf_core::fit::fit_trajectory_residuals`]: the same solver stages, refinement rules and
//! block-robust standard errors as every per-record fit of that level). A trial θ at which a
//! record's simulation fails is an error of the residuals: the fitter scores it as a penalty
//! and rejects the step, as in a per-record trajectory fit.
//!
//! The residuals of all records are laid end to end, so the covariance's blocks of
//! consecutive samples may straddle two records at a boundary: a handful of blocks among
//! hundreds, taken as correlated when they are not, which errs on the side of larger errors.
//! Each record keeps its last predictions ([`PredictionCache`]), so a Jacobian column of a
//! per-record parameter re-simulates only its own record.

use std::sync::Arc;

use anyhow::{Context, Result};
use rayon::prelude::*;
use stf_core::fit::{
    fit_residuals, fit_trajectory_residuals, full_values, FitError, FitParam, FitResult, ForceFit,
    Residuals, TrajectoryData, TrajectoryFit, FORCE_OFFSET,
};
use stf_core::physics::channel_law::EXPONENT_BOUNDS;
use stf_core::physics::force_model::ForceModel;

use super::prediction_cache::PredictionCache;
use super::spec::{Form, Law};
use crate::experiment::FitLevel;

/// Where one value of a record's parameter vector comes from.
#[derive(Clone, Debug)]
pub enum Source {
    /// θ's `i`-th entry.
    Theta(usize),
    /// `θ[coefficient]·ratio^θ[exponent]`, `ratio` the record's condition over the reference,
    /// clamped into the parameter's bounds.
    Law {
        /// Index of `P0` in θ.
        coefficient: usize,
        /// Index of `P_p` in θ.
        exponent: usize,
        /// The record's condition / the law's reference.
        ratio: f64,
        /// Index of the law in `GlobalSpec::laws`.
        law: usize,
        /// The parameter's (widest) bounds, which the law's value is clamped into.
        bounds: (f64, f64),
    },
    /// A law with a form ([`Form`]) of `x`, the record's condition over the reference, its
    /// coefficients θ's entries from `first` on (in [`Form::coefficients`]' order).
    Form {
        /// The law's form.
        form: Form,
        /// Index of its first coefficient in θ.
        first: usize,
        /// The record's condition / the law's reference.
        x: f64,
        /// Index of the law in `GlobalSpec::laws`.
        law: usize,
        /// The parameter's (widest) bounds, which the law's value is clamped into.
        bounds: (f64, f64),
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
                bounds,
                ..
            } => power_value(theta[coefficient], theta[exponent], ratio, bounds),
            Source::Form {
                form,
                first,
                x,
                bounds,
                ..
            } => form_value(form, theta, first, x, bounds),
        }
    }
}

/// The plain law `P0·ratio^P_p`, clamped into the parameter's `bounds` as a law with a form
/// is ([`form_value`]): the model never sees a value its parameter may not take.
pub fn power_value(coefficient: f64, exponent: f64, ratio: f64, bounds: (f64, f64)) -> f64 {
    let (lo, hi) = bounds;
    (coefficient * ratio.powf(exponent)).clamp(lo, hi)
}

/// The value of `form` at `x`, its coefficients θ's entries from `first` on, clamped into
/// the parameter's `bounds` — as a record's own channel law clamps it
/// ([`stf_core::physics::channel_law::ChannelLaw`]): the model never sees a value its
/// parameter may not take.
pub fn form_value(form: Form, theta: &[f64], first: usize, x: f64, bounds: (f64, f64)) -> f64 {
    let (lo, hi) = bounds;
    form.value(&theta[first..first + form.coefficients().len()], x)
        .clamp(lo, hi)
}

/// How a record's signal is predicted.
pub enum RecordFit {
    /// Force level: the model's force along the record's kinematics.
    Force(ForceFit),
    /// Trajectory level: the record's oscillator with the model, simulated from its first
    /// sample; `t`, `x` the measured record (s, m).
    Trajectory {
        /// The fit the record's own `fit` ran.
        fit: TrajectoryFit,
        /// Times, s.
        t: Vec<f64>,
        /// Measured displacement, m.
        x: Vec<f64>,
    },
}

/// One record in the joint problem: its data, how θ maps to its parameters and how they
/// predict its signal.
pub struct JointRecord {
    /// The record's times (of its kinematics), s.
    pub t: Vec<f64>,
    /// Displacement, m.
    pub x: Vec<f64>,
    /// Velocity, m/s.
    pub v: Vec<f64>,
    /// Acceleration, m/s².
    pub a: Vec<f64>,
    /// Force, N: measured F_STF (force level, the signal fitted) or the force recovered with
    /// the record's oscillator (trajectory level: only the data scales use it).
    pub f: Vec<f64>,
    /// The predictor.
    pub fit: RecordFit,
    /// The record's parameters, in the order of the predictor's values (force level: the
    /// model's, then the offset; trajectory level: the fit's free parameters).
    pub params: Vec<FitParam>,
    /// The record's conditions, by name.
    pub conditions: Vec<(String, f64)>,
    /// Its recent predictions.
    pub cache: PredictionCache,
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

    /// The measured signal the fit aims at: F_STF (N) or x (m).
    pub fn target(&self) -> &[f64] {
        match &self.fit {
            RecordFit::Force(_) => &self.f,
            RecordFit::Trajectory { x, .. } => x,
        }
    }

    /// The signal predicted with `values` (in the order of [`JointRecord::params`]).
    pub fn predict(&self, values: &[f64]) -> Result<Vec<f64>, FitError> {
        match &self.fit {
            RecordFit::Force(fit) => fit.predict(&self.data(), values),
            RecordFit::Trajectory { fit, t, x } => fit.predict(&TrajectoryData { t, x }, values),
        }
    }

    /// [`JointRecord::predict`] through the record's cache.
    fn predict_cached(&self, values: &[f64]) -> Result<Arc<Vec<f64>>, String> {
        self.cache
            .get_or_predict(values, || self.predict(values).map_err(|e| e.to_string()))
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

impl Layout {
    /// The bounds the value of law `index` is clamped into.
    pub fn law_bounds(&self, index: usize) -> Option<(f64, f64)> {
        self.sources.iter().flatten().find_map(|s| match *s {
            Source::Form { law, bounds, .. } | Source::Law { law, bounds, .. } if law == index => {
                Some(bounds)
            }
            _ => None,
        })
    }
}

/// The name of a law's exponent for parameter `p`.
pub fn exponent_name(p: &str) -> String {
    format!("{p}_p")
}

/// The name of a law's coefficient for parameter `p`.
pub fn coefficient_name(p: &str) -> String {
    format!("{p}0")
}

/// The names of a law's coefficients of form `form` for parameter `p` (`F_y_base`,
/// `F_y_gain`, `F_y_exp`: as the records' own channel laws name them).
pub fn form_names(form: Form, p: &str) -> Vec<String> {
    form.coefficients()
        .iter()
        .map(|suffix| format!("{p}_{suffix}"))
        .collect()
}

/// θ's layout for the `shared` parameters and the `laws` over `records` (each named by its
/// unit number; their [`JointRecord::params`] name the same parameters in the same order,
/// start values and bounds configured). `starts` gives per record the values its own fit
/// found (same order), to start from. A shared parameter or a law's coefficient takes the
/// widest of the records' bounds.
pub fn layout(
    shared: &[String],
    laws: &[Law],
    records: &[(usize, &JointRecord)],
    starts: &[Vec<f64>],
) -> Layout {
    let mut layout = Layout {
        params: Vec::new(),
        roles: Vec::new(),
        sources: vec![Vec::new(); records.len()],
    };
    let Some((_, first)) = records.first() else {
        return layout;
    };
    for (k, p) in first.params.iter().enumerate() {
        let column: Vec<f64> = starts.iter().map(|s| s[k]).collect();
        let widest = widest(p, records.iter().map(|(_, r)| &r.params[k]));
        let law = laws.iter().position(|l| l.param == p.name);
        if let Some(index) = law.filter(|_| !p.fixed) {
            layout.push_law(index, &laws[index], &widest, records, &column);
        } else if p.fixed || shared.contains(&p.name) {
            let mean = column.iter().sum::<f64>() / column.len().max(1) as f64;
            let start = if p.fixed { p.value } else { mean };
            for s in &mut layout.sources {
                s.push(Source::Theta(layout.params.len()));
            }
            layout.params.push(clamped(widest, start));
            layout.roles.push("shared");
        } else {
            for (j, (unit, r)) in records.iter().enumerate() {
                let own = r.params[k].clone();
                layout.sources[j].push(Source::Theta(layout.params.len()));
                let name = format!("{}@{unit}", own.name);
                layout.params.push(clamped(own, column[j]).named(name));
                layout.roles.push("per record");
            }
        }
    }
    layout
}

impl Layout {
    /// θ's entries for law `index` of parameter `p` (its widest bounds): the coefficient
    /// and the exponent, started from the line through the records' own values `column`.
    fn push_law(
        &mut self,
        index: usize,
        law: &Law,
        p: &FitParam,
        records: &[(usize, &JointRecord)],
        column: &[f64],
    ) {
        if let Some(form) = law.form {
            return self.push_form(index, law, form, p, records, column);
        }
        let (c0, expo) = law_start(law, p, records, column);
        let i = self.params.len();
        self.params
            .push(clamped(p.clone(), c0).named(coefficient_name(&p.name)));
        self.params.push(
            FitParam::new(exponent_name(&p.name), expo)
                .bounds(-50.0, 50.0)
                .scale(1.0),
        );
        self.roles.extend(["law coefficient", "law exponent"]);
        for (j, (_, r)) in records.iter().enumerate() {
            self.sources[j].push(Source::Law {
                coefficient: i,
                exponent: i + 1,
                ratio: r.condition(&law.condition) / law.reference,
                law: index,
                bounds: (p.min, p.max),
            });
        }
    }
}

impl Layout {
    /// θ's entries for law `index` of form `form` of parameter `p` (its widest bounds):
    /// the base within P's bounds, the gain within ± P's range over the records' largest
    /// |x|, the exponent within [`EXPONENT_BOUNDS`] from 1; started from the least-squares
    /// line of the records' own values `column` against x.
    fn push_form(
        &mut self,
        index: usize,
        law: &Law,
        form: Form,
        p: &FitParam,
        records: &[(usize, &JointRecord)],
        column: &[f64],
    ) {
        let xs: Vec<f64> = records
            .iter()
            .map(|(_, r)| law.ratio(r.condition(&law.condition)))
            .collect();
        let (base, gain) = form_start(form, &xs, column);
        let reach = xs.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        let range = p.max - p.min;
        let spread = match form {
            Form::Power => reach
                .powf(EXPONENT_BOUNDS.0)
                .min(reach.powf(EXPONENT_BOUNDS.1)),
            _ => reach,
        };
        let g = if spread > 0.0 && range.is_finite() {
            10.0 * range / spread
        } else {
            f64::INFINITY
        };
        let first = self.params.len();
        for (suffix, name) in form.coefficients().iter().zip(form_names(form, &p.name)) {
            let param = match *suffix {
                "base" => clamped(p.clone(), base).named(name),
                "gain" => {
                    let start = if gain.is_finite() {
                        gain.clamp(-g, g)
                    } else {
                        0.0
                    };
                    FitParam::new(name, start).bounds(-g, g)
                }
                _ => FitParam::new(name, 1.0)
                    .bounds(EXPONENT_BOUNDS.0, EXPONENT_BOUNDS.1)
                    .scale(1.0),
            };
            self.params.push(param);
            self.roles.push(if *suffix == "exp" {
                "law exponent"
            } else {
                "law coefficient"
            });
        }
        for (j, x) in xs.into_iter().enumerate() {
            self.sources[j].push(Source::Form {
                form,
                first,
                x,
                law: index,
                bounds: (p.min, p.max),
            });
        }
    }
}

/// A law of form `form`'s start: base and gain of the least-squares line of the values `ys`
/// against `xs` (through 0 for a linear law; against |x| for a power law, exponent 1).
fn form_start(form: Form, xs: &[f64], ys: &[f64]) -> (f64, f64) {
    let xs: Vec<f64> = match form {
        Form::Power => xs.iter().map(|x| x.abs()).collect(),
        _ => xs.to_vec(),
    };
    let n = xs.len().max(1) as f64;
    if form == Form::Linear {
        let sxx: f64 = xs.iter().map(|x| x * x).sum();
        let sxy: f64 = xs.iter().zip(ys).map(|(x, y)| x * y).sum();
        return (0.0, if sxx > 0.0 { sxy / sxx } else { 0.0 });
    }
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxx: f64 = xs.iter().map(|x| (x - mx).powi(2)).sum();
    let sxy: f64 = xs.iter().zip(ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let gain = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    (my - gain * mx, gain)
}

/// `p` with the widest bounds among `all` (the same parameter on every record).
fn widest<'a>(p: &FitParam, all: impl Iterator<Item = &'a FitParam>) -> FitParam {
    let mut out = p.clone();
    for q in all {
        out.min = out.min.min(q.min);
        out.max = out.max.max(q.max);
    }
    out
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
        let predicted: Vec<Arc<Vec<f64>>> = self
            .records
            .par_iter()
            .zip(self.sources)
            .map(|(r, sources)| {
                let values: Vec<f64> = sources.iter().map(|s| s.value(&theta)).collect();
                r.predict_cached(&values)
            })
            .collect::<Result<_, String>>()?;
        for ((r, p), &start) in self.records.iter().zip(&predicted).zip(&self.starts) {
            for (i, (y, p)) in r.target().iter().zip(p.iter()).enumerate() {
                sink(start + i, y - p);
            }
        }
        Ok(())
    }
}

/// Fit θ of `layout` to `records` (in the layout's order) with `settings`, at `level`: at
/// trajectory level by the rules of a trajectory fit (the records' residuals are
/// displacements).
pub fn fit(
    layout: &Layout,
    records: &[&JointRecord],
    settings: &stf_core::fit::FitSettings,
    level: FitLevel,
) -> Result<FitResult> {
    let mut starts = Vec::with_capacity(records.len());
    let mut len = 0;
    for r in records {
        starts.push(len);
        len += r.target().len();
    }
    let problem = Joint {
        params: &layout.params,
        records: records.to_vec(),
        sources: &layout.sources,
        starts,
        len,
    };
    let result = if level == FitLevel::Trajectory {
        fit_trajectory_residuals(&problem, &layout.params, settings, None)
    } else {
        fit_residuals(&problem, &layout.params, settings, None)
    };
    result.context("the global fit")
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

/// The RMS of `record`'s measured signal against its prediction with `values` (in its
/// parameters' order), SI (N or m).
pub fn rms_of(record: &JointRecord, values: &[f64]) -> Result<f64> {
    let predicted = record.predict(values)?;
    let target = record.target();
    let n = target.len().max(1) as f64;
    let ss: f64 = target
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
            fit: RecordFit::Force(predictor(model(), &params, false)),
            params,
            conditions: vec![("c".into(), c)],
            cache: PredictionCache::default(),
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
            form: None,
        }];
        let starts = vec![vec![1.0, 1.0]; 3];
        let layout = layout(&["b".into()], &laws, &numbered, &starts);
        let names: Vec<&str> = layout.params.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["a0", "a_p", "b"]);
        assert_eq!(layout.roles, ["law coefficient", "law exponent", "shared"]);
        let refs: Vec<&JointRecord> = records.iter().collect();
        let result = fit(&layout, &refs, &Default::default(), FitLevel::Force).unwrap();
        for (name, truth) in [("a0", 3.0), ("a_p", 1.5), ("b", 0.7)] {
            let v = result.value(name).unwrap();
            assert!((v - truth).abs() < 1e-6, "{name} = {v}");
        }
        assert_eq!(result.n_points, 1200);
    }

    #[test]
    fn an_affine_law_with_an_offset_is_recovered_including_at_a_zero_condition() {
        // a = 2 + 1.5·c, b = 0.7 on every record; one record at c = 0.
        let records: Vec<JointRecord> = [0.0, 1.0, 3.0]
            .iter()
            .map(|&c| record(c, 2.0 + 1.5 * c, 0.7))
            .collect();
        let numbered: Vec<(usize, &JointRecord)> = records.iter().enumerate().collect();
        let laws = [Law {
            param: "a".into(),
            condition: "c".into(),
            reference: 1.0,
            form: Some(Form::Affine),
        }];
        let starts = vec![vec![1.0, 1.0]; 3];
        let layout = layout(&["b".into()], &laws, &numbered, &starts);
        let names: Vec<&str> = layout.params.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["a_base", "a_gain", "b"]);
        let refs: Vec<&JointRecord> = records.iter().collect();
        let result = fit(&layout, &refs, &Default::default(), FitLevel::Force).unwrap();
        for (name, truth) in [("a_base", 2.0), ("a_gain", 1.5), ("b", 0.7)] {
            let v = result.value(name).unwrap();
            assert!((v - truth).abs() < 1e-6, "{name} = {v}");
        }
    }

    #[test]
    fn a_power_law_with_an_offset_is_recovered() {
        // a = 1 + 2·(c/2)^1.5.
        let records: Vec<JointRecord> = [1.0, 2.0, 3.0, 4.0]
            .iter()
            .map(|&c| record(c, 1.0 + 2.0 * (c / 2.0_f64).powf(1.5), 0.7))
            .collect();
        let numbered: Vec<(usize, &JointRecord)> = records.iter().enumerate().collect();
        let laws = [Law {
            param: "a".into(),
            condition: "c".into(),
            reference: 2.0,
            form: Some(Form::Power),
        }];
        let starts: Vec<Vec<f64>> = records.iter().map(|_| vec![1.0, 0.7]).collect();
        let layout = layout(&["b".into()], &laws, &numbered, &starts);
        let refs: Vec<&JointRecord> = records.iter().collect();
        let result = fit(&layout, &refs, &Default::default(), FitLevel::Force).unwrap();
        for (name, truth) in [("a_base", 1.0), ("a_gain", 2.0), ("a_exp", 1.5)] {
            let v = result.value(name).unwrap();
            assert!((v - truth).abs() < 1e-5, "{name} = {v}");
        }
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
        let starts = vec![vec![1.0, 1.0]; 2];
        let layout = layout(&["a".into()], &[], &numbered, &starts);
        let names: Vec<&str> = layout.params.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["a", "b@4", "b@5"]);
        let refs: Vec<&JointRecord> = records.iter().collect();
        let result = fit(&layout, &refs, &Default::default(), FitLevel::Force).unwrap();
        assert!((result.value("b@4").unwrap() - 2.0).abs() < 1e-6);
        assert!((result.value("b@5").unwrap() + 1.0).abs() < 1e-6);
        assert!((result.value("a").unwrap() - 1.5).abs() < 1e-6);
    }

    /// The plain law is clamped into its parameter's bounds ([0, 100] for `a`), as a law
    /// with a form is: a = 60·(c/2)² leaves them at c = 3 (135), where the records' `a` is
    /// held at 100; the joint fit recovers the law exactly only if it holds it there too.
    #[test]
    fn the_plain_law_is_clamped_into_the_parameters_bounds() {
        let records: Vec<JointRecord> = [1.0, 2.0, 3.0]
            .iter()
            .map(|&c| record(c, (60.0 * (c / 2.0_f64).powi(2)).min(100.0), 0.7))
            .collect();
        let numbered: Vec<(usize, &JointRecord)> = records.iter().enumerate().collect();
        let laws = [Law {
            param: "a".into(),
            condition: "c".into(),
            reference: 2.0,
            form: None,
        }];
        let starts = vec![vec![50.0, 1.0]; 3];
        let layout = layout(&["b".into()], &laws, &numbered, &starts);
        assert_eq!(layout.law_bounds(0), Some((0.0, 100.0)));
        let theta = [60.0, 2.0, 0.7];
        let values: Vec<f64> = layout.sources.iter().map(|s| s[0].value(&theta)).collect();
        assert_eq!(values, [15.0, 60.0, 100.0]);
        let refs: Vec<&JointRecord> = records.iter().collect();
        let result = fit(&layout, &refs, &Default::default(), FitLevel::Force).unwrap();
        for (name, truth) in [("a0", 60.0), ("a_p", 2.0), ("b", 0.7)] {
            let v = result.value(name).unwrap();
            assert!((v - truth).abs() < 1e-6, "{name} = {v}");
        }
    }
}
