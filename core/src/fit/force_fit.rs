//! Force-level calibration: an STF model's force against a measured F_STF.
//!
//! Residual of sample i: `F_meas,i − (m_a·a_i + f(t_i, x_i, v_i, z_i) + f_off)`, with the
//! kinematics (x, v, a) given — typically from the derivative filter. A model with internal
//! state is integrated along the measured kinematics with one classical Runge–Kutta (RK4)
//! step per sample interval, x and v interpolated linearly between the samples (the midpoint
//! stages use their means); z starts from the model's own initial state at the first sample.
//! Memoryless models cost one call per sample, models with state four. Nothing is allocated
//! per sample; an evaluation allocates only the model's few state variables.
//!
//! ```
//! use std::sync::Arc;
//! use stf_core::data::force_data::ForceData;
//! use stf_core::fit::ForceFit;
//! use stf_core::physics::force_model::{ForceModel, ModelError, ModelState};
//! use stf_core::physics::param_spec::ParamSpec;
//! struct Lin(Vec<ParamSpec>);
//! impl ForceModel for Lin {
//!     fn name(&self) -> &str { "lin" }
//!     fn params(&self) -> &[ParamSpec] { &self.0 }
//!     fn force(&self, p: &[f64], s: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
//!         Ok(p[0] * s.v)
//!     }
//! }
//! let model = Arc::new(Lin(vec![ParamSpec::new("c", "N·s/m", 1.0, 0.0, 100.0, "")]));
//! let t: Vec<f64> = (0..100).map(|i| i as f64 * 0.01).collect();
//! let v: Vec<f64> = t.iter().map(|t| (5.0 * t).cos()).collect();
//! let f: Vec<f64> = v.iter().map(|v| 3.0 * v).collect();
//! let zeros = vec![0.0; t.len()];
//! let data = ForceData::new(&t, &zeros, &v, &zeros, &f);
//! let result = ForceFit::new(model).fit(&data, None).unwrap();
//! assert!((result.value("c").unwrap() - 3.0).abs() < 1e-6);
//! ```

use std::sync::Arc;

use derive_setters::Setters;
use nalgebra::DMatrix;

use super::driver;
use super::error::FitError;
use super::filter_noise::{self, FilterNoise};
use super::fit_param::{full_values, held, FitParam};
use super::noise_floor::Quantity;
use super::objective::{written_and_summed, Residuals};
use super::part_cache::PartCache;
use super::result::{FitProgress, FitResult};
use super::row_halves;
use super::solver::{FitSettings, Solver};
use crate::data::force_data::ForceData;
use crate::physics::force_model::ForceModel;
use crate::physics::track::Track;

/// A force-level calibration of one STF model (a [`crate::physics::model_sum::ModelSum`] is one model).
#[derive(Clone, Setters)]
#[setters(generate = false)]
pub struct ForceFit {
    model: Arc<dyn ForceModel>,
    params: Vec<FitParam>,
    unknown: Vec<String>,
    offset: Option<FitParam>,
    /// Settings of the optimiser.
    #[setters(generate)]
    settings: FitSettings,
    /// How v and a were made from x, for [`ForceFit::fit`] to correct its estimates for
    /// their noise ([`filter_noise`](super::filter_noise)) and to take the blocks of its
    /// standard errors at least twice the filter's window long; `None`: v and a taken as
    /// exact.
    #[setters(generate)]
    filter_noise: Option<FilterNoise>,
}

/// Name of the constant force offset parameter, N.
pub const FORCE_OFFSET: &str = "f_off";

impl ForceFit {
    /// Fit every parameter of `model` from its defaults within its bounds; no offset.
    pub fn new(model: Arc<dyn ForceModel>) -> Self {
        let params = model.params().iter().map(FitParam::from_spec).collect();
        ForceFit {
            model,
            params,
            unknown: Vec::new(),
            offset: None,
            settings: FitSettings::default(),
            filter_noise: None,
        }
    }

    /// Start value, bounds or fixing of one of the model's parameters (by its name).
    pub fn param(mut self, p: FitParam) -> Self {
        match self.params.iter_mut().find(|q| q.name == p.name) {
            Some(slot) => *slot = p,
            None => self.unknown.push(p.name),
        }
        self
    }

    /// Add a constant force offset `f_off` (N) to the model's force; fit it unless `fixed`.
    /// Its name is replaced by [`FORCE_OFFSET`].
    pub fn offset(mut self, mut p: FitParam) -> Self {
        p.name = FORCE_OFFSET.to_string();
        if p.scale.is_none() && p.value == 0.0 {
            p.scale = Some(0.1);
        }
        self.offset = Some(p);
        self
    }

    /// The parameters as they stand (model's, then the offset).
    pub fn params(&self) -> Vec<FitParam> {
        let mut all = self.params.clone();
        all.extend(self.offset.clone());
        all
    }

    /// Run the fit; `observer` is called after every iteration of every solver stage. With
    /// [`ForceFit::filter_noise`] set, the estimates are then corrected for the filter's
    /// noise in v and a ([`filter_noise::correct`]).
    pub fn fit(
        &self,
        data: &ForceData,
        observer: Option<&(dyn Fn(FitProgress) + Sync)>,
    ) -> Result<FitResult, FitError> {
        let result = self.fit_rows(data, None, &self.settings, observer)?;
        match &self.filter_noise {
            Some(noise) => filter_noise::correct(self, data, noise, result),
            None => Ok(result),
        }
    }

    /// The fit started at `values` (the model's parameters, then the offset), refined by
    /// Levenberg–Marquardt without a trace and without the filter-noise correction.
    pub(super) fn started_at(&self, values: &[f64]) -> ForceFit {
        let mut fit = self.clone();
        let slots = fit.params.iter_mut().chain(fit.offset.as_mut());
        for (p, &v) in slots.zip(values) {
            p.value = v;
        }
        fit.filter_noise = None;
        fit.settings.solver = Solver::Auto;
        fit.settings.trace = None;
        fit
    }

    /// [`ForceFit::fit_rows`] on all samples with the fit's own settings, no observer.
    pub(super) fn fit_plain(&self, data: &ForceData) -> Result<FitResult, FitError> {
        self.fit_rows(data, None, &self.settings, None)
    }

    /// Fit on the samples `rows` only (strictly increasing; `None`: all) with `settings`
    /// instead of the fit's own; statistics (RMS, AIC, BIC, standard errors) are those of
    /// the rows. The model is still evaluated along the whole record where it has internal
    /// state, so the state evolves through the samples left out as it would in reality.
    pub fn fit_rows(
        &self,
        data: &ForceData,
        rows: Option<&[usize]>,
        settings: &FitSettings,
        observer: Option<&(dyn Fn(FitProgress) + Sync)>,
    ) -> Result<FitResult, FitError> {
        if let Some(name) = self.unknown.first() {
            return Err(FitError::UnknownParam {
                name: name.clone(),
                known: self
                    .model
                    .params()
                    .iter()
                    .map(|s| s.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
        data.check_increasing()?;
        if let Some(rows) = rows {
            let n = data.t.len();
            if rows.windows(2).any(|w| w[0] >= w[1]) || rows.last().is_some_and(|&l| l >= n) {
                return Err(FitError::BadData(format!(
                    "the samples to fit must increase strictly and lie within the {n} samples"
                )));
            }
        }
        let all = self.params();
        driver::run(
            &self.residuals(data, &all, rows),
            &all,
            settings,
            observer,
            Quantity::Force,
        )
    }

    /// `fitted`, a [`ForceFit::fit_rows`] on `rows` run without its standard errors
    /// ([`FitSettings::errors`] off), completed with them ([`driver::with_errors`]).
    pub fn with_errors_rows(
        &self,
        data: &ForceData,
        rows: Option<&[usize]>,
        settings: &FitSettings,
        fitted: FitResult,
    ) -> Result<FitResult, FitError> {
        let all = self.params();
        let problem = self.residuals(data, &all, rows);
        driver::with_errors(&problem, &all, settings, Quantity::Force, fitted)
    }

    /// The residuals of this fit's model (every parameter in `all`) on the samples `rows`.
    fn residuals<'a>(
        &'a self,
        data: &ForceData<'a>,
        all: &'a [FitParam],
        rows: Option<&'a [usize]>,
    ) -> ForceResiduals<'a> {
        ForceResiduals {
            model: self.model.as_ref(),
            data: *data,
            all,
            rows,
            span: self.filter_noise.map_or(1, |n| n.filter.window()),
            parts: PartCache::of(self.model.as_ref()),
        }
    }

    /// The modelled force (with the offset, if any) at every sample for the full parameter
    /// vector `values` (the model's parameters, then the offset), along the kinematics.
    pub fn predict(&self, data: &ForceData, values: &[f64]) -> Result<Vec<f64>, FitError> {
        self.predict_rows(data, values, None)
    }

    /// [`ForceFit::predict`] at the samples `rows` only (strictly increasing; `None`: every
    /// sample), one value a row; a model with internal state is still integrated along every
    /// sample.
    pub fn predict_rows(
        &self,
        data: &ForceData,
        values: &[f64],
        rows: Option<&[usize]>,
    ) -> Result<Vec<f64>, FitError> {
        data.check_increasing()?;
        self.predict_checked_rows(data, values, rows)
    }

    /// [`ForceFit::predict_rows`] on `data` that [`ForceData::check_increasing`] has passed:
    /// a start grid predicts the same record at many points, and checking its 150 000 samples'
    /// finiteness at each was 1.6 % of a force-level discovery.
    pub(crate) fn predict_checked_rows(
        &self,
        data: &ForceData,
        values: &[f64],
        rows: Option<&[usize]>,
    ) -> Result<Vec<f64>, FitError> {
        let all = held(&self.params(), values)?;
        let problem = ForceResiduals {
            model: self.model.as_ref(),
            data: *data,
            all: &all,
            rows,
            span: 1,
            parts: None,
        };
        let mut out: Vec<f64> = (0..problem.len()).map(|k| data.f[problem.row(k)]).collect();
        problem
            .residuals(&[], &mut |k, r| out[k] -= r)
            .map_err(FitError::BadData)?;
        Ok(out)
    }

    /// [`ForceFit::predict_checked_rows`] at each of the full parameter vectors `values`, the
    /// model's state integrated for all of them side by side
    /// ([`ForceModel::mass_and_force_lanes`]; the same values to the bit); `None` where that
    /// is not done (a model without one internal variable, too many vectors, a model error):
    /// then each is predicted on its own.
    pub(crate) fn predict_lanes(
        &self,
        data: &ForceData,
        values: &[Vec<f64>],
        rows: Option<&[usize]>,
    ) -> Option<Vec<Vec<f64>>> {
        let n_model = self.model.params().len();
        let params = self.params();
        let full: Vec<Vec<f64>> = values
            .iter()
            .map(|v| full_values(&held(&params, v).ok()?, &[]).ok())
            .collect::<Option<_>>()?;
        let ps: Vec<&[f64]> = full.iter().map(|f| &f[..n_model]).collect();
        let track = Track {
            t: data.t,
            x: data.x,
            v: data.v,
        };
        let found = self.model.mass_and_force_lanes(&ps, &track, rows)?;
        let n = track.len_at(rows);
        let predicted = full.iter().zip(found).map(|(f, (mass, force))| {
            let offset = f.get(n_model).copied().unwrap_or(0.0);
            (0..n)
                .map(|k| {
                    let i = rows.map_or(k, |r| r[k]);
                    // As `predict_checked_rows`: measured less the residual.
                    let r = data.f[i] - (mass[k] * data.a[i] + force[k] + offset);
                    data.f[i] - r
                })
                .collect()
        });
        Some(predicted.collect())
    }
}

/// The residuals of a force-level fit, at every sample or at the samples `rows` only.
struct ForceResiduals<'a> {
    model: &'a dyn ForceModel,
    data: ForceData<'a>,
    /// Model parameters, then the offset if any.
    all: &'a [FitParam],
    /// The samples whose residuals count (strictly increasing), or `None` for all. A model
    /// with internal state is still integrated along every sample.
    rows: Option<&'a [usize]>,
    /// Samples over which the kinematics' noise is correlated: the derivative filter's
    /// window (1: v and a taken as exact).
    span: usize,
    /// The parts' contributions kept between evaluations (a sum with state: its difference
    /// columns evaluate only the part they change).
    parts: Option<PartCache>,
}

impl ForceResiduals<'_> {
    /// The sample behind residual `k`.
    fn row(&self, k: usize) -> usize {
        self.rows.map_or(k, |r| r[k])
    }

    /// The kinematics the model is evaluated along.
    fn track(&self) -> Track<'_> {
        Track {
            t: self.data.t,
            x: self.data.x,
            v: self.data.v,
        }
    }

    /// The residuals at free values `x`, each passed to `each(k, r_k)` in order of `k`.
    fn stream(&self, x: &[f64], mut each: impl FnMut(usize, f64)) -> Result<(), String> {
        let n_model = self.model.params().len();
        let full = full_values(self.all, x)?;
        let p = &full[..n_model];
        let offset = full.get(n_model).copied().unwrap_or(0.0);
        let d = &self.data;
        let n = self.len();
        let (mut mass, mut force) = (vec![0.0; n], vec![0.0; n]);
        match &self.parts {
            Some(parts) => {
                parts.mass_and_force_along(p, &self.track(), self.rows, &mut mass, &mut force)
            }
            None => row_halves::mass_and_force_along(
                self.model,
                p,
                &self.track(),
                self.rows,
                &mut mass,
                &mut force,
            ),
        }
        .map_err(|e| e.to_string())?;
        for k in 0..n {
            let i = self.row(k);
            each(k, d.f[i] - (mass[k] * d.a[i] + force[k] + offset));
        }
        Ok(())
    }
}

impl Residuals for ForceResiduals<'_> {
    fn len(&self) -> usize {
        self.rows.map_or(self.data.t.len(), <[usize]>::len)
    }

    fn correlation_span(&self) -> usize {
        self.span
    }

    fn residuals(&self, x: &[f64], sink: &mut dyn FnMut(usize, f64)) -> Result<(), String> {
        self.stream(x, sink)
    }

    /// Written and summed in order, as streaming them gives, without a `dyn` call per
    /// residual.
    fn residuals_into(&self, x: &[f64], out: &mut [f64]) -> Result<f64, String> {
        let mut rss = 0.0;
        self.stream(x, written_and_summed(out, &mut rss))?;
        Ok(rss)
    }

    /// A sum with state: its parts with state integrated at the points side by side and kept
    /// ([`PartCache::prefetch`]).
    fn prefetch(&self, points: &[Vec<f64>]) {
        let Some(parts) = &self.parts else {
            return;
        };
        let n_model = self.model.params().len();
        let full: Vec<Vec<f64>> = points
            .iter()
            .filter_map(|x| full_values(self.all, x).ok())
            .map(|mut f| {
                f.truncate(n_model);
                f
            })
            .collect();
        parts.prefetch(&full, &self.track(), self.rows);
    }

    /// Exact for models that give their [`ForceModel::gradient`]: built-ins without state,
    /// and the memoryless parts of a sum (a part with state leaves NaN columns). A
    /// memoryless part's gradient needs no state, so nothing is integrated here.
    fn jacobian(&self, x: &[f64], jac: &mut DMatrix<f64>) -> Option<Result<(), String>> {
        let m = self.model;
        let n_model = m.params().len();
        if self.is_empty() {
            return None;
        }
        let full = match full_values(self.all, x) {
            Ok(f) => f,
            Err(e) => return Some(Err(e)),
        };
        let p = &full[..n_model];
        let n = self.len();
        let mut grad = vec![0.0; n * n_model];
        match row_halves::gradient_along(m, p, &self.track(), self.data.a, self.rows, &mut grad) {
            Ok(true) => {}
            Ok(false) => return None,
            Err(e) => return Some(Err(e.to_string())),
        }
        // Column of each free parameter among all (the offset, the last, has slope 1).
        let free = (0..self.all.len()).filter(|&j| !self.all[j].fixed);
        let columns = jac.as_mut_slice().chunks_exact_mut(n);
        for (column, j) in columns.zip(free) {
            if j < n_model {
                for (out, g) in column.iter_mut().zip(&grad[j * n..(j + 1) * n]) {
                    *out = -g;
                }
            } else {
                column.fill(-1.0);
            }
        }
        Some(Ok(()))
    }
}
