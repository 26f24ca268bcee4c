//! The force level of discovery ([`ForceLevel`], a [`Level`] for the loop of
//! [`super::search`]): records with a measured F_STF and kinematics, every model fitted to
//! the force along them. Its candidates start from a small multi-start ([`candidate_starts`],
//! [`ForceLevel::best_trial`]); by default earlier effects are re-checked after each
//! acceptance ([`super::reconsider`]) and an accepted model is not polished.
//!
//! Each step cuts the held-out cycles into blocks at least as long as the residual's
//! correlation ([`super::blocks`]) and measures the current model's noise floor — the force
//! sensor's noise with the kinematics' noise propagated through that model
//! ([`ForceFit::noise_floor`]) — so that a candidate is judged by independent units and by the
//! share of the excess over that floor it removes ([`super::acceptance`]).

use std::sync::Arc;

use rayon::prelude::*;

use super::acceptance;
use super::blocks::{block_length, Blocks};
use super::candidate::Candidate;
use super::choice::{self, Said, Trial, Yardstick};
use super::costly_first::costly_first;
use super::error::DiscoveryError;
use super::findings::Discovery;
use super::force_gap::{locate_gap, GapLocation};
use super::holdout::{rms_over, HoldoutSplit};
use super::level::Level;
use super::score::CandidateScore;
use super::search;
use super::search_model::SearchModel;
use super::settings::DiscoverySettings;
use crate::data::force_data::ForceData;
use crate::fit::{
    Convergence, FitParam, FitResult, FitSettings, ForceFit, NoiseFloor, FORCE_OFFSET,
};
use crate::physics::force_model::{ForceModel, Reach};
use crate::physics::model_sum::neutral_amplitude;
use crate::physics::track::MAX_LANES;
use crate::regimes::Cycle;

impl SearchModel {
    /// The force fit of this stage starting from its values, clamped into the bounds. A value
    /// on a bound is moved inside by the fit's bound transform; any other value is the start
    /// as it is. (This used to move values 1 % of the width below an upper bound, so a refit
    /// from a training fit with `p` = 3 started elsewhere; the stall it worked around was the
    /// transform moving interior starts, now fixed.)
    ///
    /// The offset `f_off` (with `settings.fit_offset`) is bounded by ± `reach` (twice the
    /// record's largest |force|) and scaled to a thousandth of it, as a plain fit bounds it:
    /// unbounded at a scale of 0.1 N, a 120 N offset cost Levenberg–Marquardt so many damped
    /// steps that the base's fit stopped far from its optimum.
    fn force_fit(
        &self,
        settings: &DiscoverySettings,
        reach: f64,
    ) -> Result<ForceFit, DiscoveryError> {
        let model = self.model()?;
        let mut fit = started_fit(&model, &self.values).settings(settings.fit.clone());
        if settings.fit_offset {
            let start = self
                .values
                .get(model.params().len())
                .copied()
                .unwrap_or(0.0);
            let offset = FitParam::new(FORCE_OFFSET, start.clamp(-reach, reach))
                .bounds(-reach, reach)
                .scale(1e-3 * reach);
            fit = fit.offset(offset);
        }
        Ok(fit)
    }

    /// This stage with every model parameter that sits on a bound (within 1e-9 of the width)
    /// restarted from its default, or `None` when none does. A parameter pinned on a bound by
    /// the fit of a model that lacked an effect (n = 1 for a power law absorbing a yield
    /// force) hardly leaves it when the effect is added: the bound map is flat there.
    fn released(&self) -> Option<SearchModel> {
        let specs = self.parts.iter().flat_map(|p| p.params());
        let mut values = self.values.clone();
        let mut any = false;
        for (spec, v) in specs.zip(values.iter_mut()) {
            let tol = 1e-9 * (spec.max - spec.min).abs();
            let pinned = (*v - spec.min).abs() <= tol || (*v - spec.max).abs() <= tol;
            if pinned && *v != spec.default {
                *v = spec.default;
                any = true;
            }
        }
        any.then(|| SearchModel {
            parts: self.parts.clone(),
            values,
        })
    }
}

/// The force fit of `model` from `values` (its parameters', each clamped into its bounds).
pub(super) fn started_fit(model: &Arc<dyn ForceModel>, values: &[f64]) -> ForceFit {
    let fit = ForceFit::new(model.clone());
    model
        .params()
        .iter()
        .zip(values)
        .fold(fit, |fit, (spec, &v)| {
            fit.param(FitParam::from_spec(spec).value(v.clamp(spec.min, spec.max)))
        })
}

/// The start values of `model`'s parameters for adding it to a model whose residual over
/// `subset` is `r`, and the starts of a multi-start: the first is the defaults; then, when the
/// force is proportional to the first parameter (checked numerically: doubling it doubles the
/// force along the record), the best `extra` points of a coarse grid over the other
/// parameters ([`start_grid`]) by variable projection — with those fixed, the first parameter
/// is the linear least squares of `r` on the force, and the point is scored by the residual
/// sum of squares left. Each start's first parameter is that least-squares value (or 1e-3 of
/// its default when the slope is not positive: the effect is then absent, or of the other
/// sign). A start far from the answer (k3 = 1e5 for an effect of 1e4) cost
/// Levenberg–Marquardt dozens of iterations creeping along a log-like bound map, and a start
/// at the defaults alone left `power_law + yield` in a poorer local minimum (F_y 0.052 N for
/// 0.08 N).
fn candidate_starts(
    model: &Arc<dyn ForceModel>,
    data: &ForceData,
    subset: &[usize],
    r: &[f64],
    extra: usize,
) -> Vec<Vec<f64>> {
    let specs = model.params();
    let defaults: Vec<f64> = specs.iter().map(|s| s.default).collect();
    let Some(first) = specs.first() else {
        return vec![defaults];
    };
    let fit = ForceFit::new(model.clone());
    let mut doubled = defaults.clone();
    doubled[0] *= 2.0;
    if data.check_increasing().is_err() {
        return vec![defaults];
    }
    // The model at the subset's samples only, one value a row of it.
    let along = |values: &[f64]| fit.predict_checked_rows(data, values, Some(subset));
    let (Ok(f1), Ok(f2)) = (along(&defaults), along(&doubled)) else {
        return vec![defaults];
    };
    // Against the largest force: `predict` returns measured − residual, whose rounding is
    // relative to the measured force, not to a force near zero.
    let largest = f2.iter().map(|f| f.abs()).fold(0.0, f64::max);
    let proportional = f1
        .iter()
        .zip(&f2)
        .all(|(f1, f2)| (f2 - 2.0 * f1).abs() <= 1e-9 * largest);
    if !proportional || first.default == 0.0 {
        return vec![defaults];
    }
    // The start from `values` (first parameter at its default) whose force at the subset's
    // samples is `f`, and the residual sum of squares it leaves; `None` when that force is
    // zero.
    let project = |values: &[f64], f: &[f64]| -> Option<(Vec<f64>, f64)> {
        let (rf, ff) = subset
            .iter()
            .zip(f)
            .fold((0.0, 0.0), |(rf, ff), (&i, &f)| (rf + r[i] * f, ff + f * f));
        if !(ff > 0.0 && ff.is_finite() && rf.is_finite()) {
            return None;
        }
        let slope = rf / ff;
        let (v, drop) = if slope > 0.0 {
            (slope * first.default, rf * rf / ff)
        } else {
            (1e-3 * first.default, 0.0)
        };
        let mut start = values.to_vec();
        if v > first.min && v < first.max {
            start[0] = v;
        }
        Some((start, -drop))
    };
    let Some((at_defaults, _)) = project(&defaults, &f1) else {
        return vec![defaults];
    };
    let mut starts = vec![at_defaults];
    if extra == 0 || specs.len() < 2 {
        return starts;
    }
    // Each grid point evaluates the model along the whole record: in parallel, in order; a
    // model with state integrated at a few points side by side (`ForceFit::predict_lanes`,
    // the same values as one by one).
    let points: Vec<Vec<f64>> = start_grid(&specs[1..])
        .into_iter()
        .map(|point| {
            let mut values = defaults.clone();
            values[1..].copy_from_slice(&point);
            values
        })
        .collect();
    let mut scored: Vec<(Vec<f64>, f64)> = points
        .par_chunks(MAX_LANES)
        .flat_map_iter(|chunk| {
            let forces: Vec<Option<Vec<f64>>> = match fit.predict_lanes(data, chunk, Some(subset)) {
                Some(forces) => forces.into_iter().map(Some).collect(),
                None => chunk.iter().map(|values| along(values).ok()).collect(),
            };
            let at = chunk.iter().zip(forces);
            at.filter_map(|(values, f)| project(values, &f?))
                .collect::<Vec<_>>()
        })
        .collect();
    scored.sort_by(|a, b| a.1.total_cmp(&b.1));
    for (start, _) in scored {
        if starts.len() <= extra && starts.iter().all(|s| s[1..] != start[1..]) {
            starts.push(start);
        }
    }
    starts
}

/// Points per parameter of the start grid, and the most points in all.
const GRID_POINTS: usize = 4;
const GRID_MAX: usize = 256;

/// A coarse grid over the parameters `specs`: for each, its default and [`GRID_POINTS`]
/// points spread evenly across its bounds — in the logarithm when the range is positive and
/// spans more than a decade (a lower bound of 0 counts as 1e-4 of the upper), linearly
/// otherwise — at the middles of equal sub-ranges, so no point lies on a bound. With many
/// parameters the points per parameter are fewer, to keep the grid within [`GRID_MAX`].
fn start_grid(specs: &[crate::physics::param_spec::ParamSpec]) -> Vec<Vec<f64>> {
    let mut per = GRID_POINTS;
    while per > 1 && (per + 1).pow(specs.len() as u32) > GRID_MAX {
        per -= 1;
    }
    specs
        .iter()
        .map(|s| {
            let lo = if s.min > 0.0 { s.min } else { 1e-4 * s.max };
            let log = lo > 0.0 && s.max > 10.0 * lo;
            let mut axis = vec![s.default];
            for k in 0..per {
                let u = (k as f64 + 0.5) / per as f64;
                let v = if log {
                    (lo.ln() + u * (s.max.ln() - lo.ln())).exp()
                } else {
                    s.min + u * (s.max - s.min)
                };
                if v.is_finite() && v != s.default {
                    axis.push(v);
                }
            }
            axis
        })
        .fold(vec![Vec::new()], |grid, axis| {
            grid.iter()
                .flat_map(|point| axis.iter().map(|&v| [point.as_slice(), &[v]].concat()))
                .collect()
        })
}

/// How costly a candidate's fits are expected to be, for ordering (larger first): a model
/// with internal state is integrated along the record at every evaluation, and more
/// parameters mean more columns and iterations.
fn cost_rank(model: &Arc<dyn ForceModel>) -> (bool, usize) {
    (model.n_internal() > 0, model.params().len())
}

/// Find the effects missing from `base` among `candidates`, at force level.
///
/// `data` holds the measured kinematics and F_STF; `cycles` cut it into whole cycles (e.g.
/// [`crate::regimes::cycles_from_phase`]), every `settings.holdout_every`-th of which is held
/// out to score the fits. The acceptance rule is that of [`super::acceptance`]. A candidate
/// whose model is already a part of the base (by name) is not tried. Each candidate's trial
/// is a small multi-start (its defaults, `settings.extra_starts` points of a grid over its
/// nonlinear parameters, and the current model's parameters pinned on a bound released), of
/// which the best training fit is scored. A candidate whose fit fails is scored as failed,
/// not an error; a base that cannot be fitted is an error.
///
/// ```
/// use std::sync::Arc;
/// use stf_core::discovery::{discover_force, Candidate, DiscoverySettings};
/// use stf_core::data::force_data::ForceData;
/// use stf_core::physics::force_model::{ForceModel, ModelError, ModelState};
/// use stf_core::physics::param_spec::ParamSpec;
/// use stf_core::regimes::cycles_from_phase;
///
/// struct Term(&'static str, Vec<ParamSpec>, fn(&ModelState) -> f64);
/// impl ForceModel for Term {
///     fn name(&self) -> &str { self.0 }
///     fn params(&self) -> &[ParamSpec] { &self.1 }
///     fn force(&self, p: &[f64], s: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
///         Ok(p[0] * (self.2)(s))
///     }
/// }
/// let spec = |n: &str| vec![ParamSpec::new(n, "", 1.0, 0.0, 100.0, "")];
/// let damper: Arc<dyn ForceModel> = Arc::new(Term("damper", spec("c"), |s| s.v));
/// let spring: Arc<dyn ForceModel> = Arc::new(Term("spring", spec("k"), |s| s.x));
/// // 40 cycles at 6 rad/s; F = 2·v + 0.5·x plus a deterministic "noise".
/// let t: Vec<f64> = (0..8400).map(|i| i as f64 / 200.0).collect();
/// let phi: Vec<f64> = t.iter().map(|t| 6.0 * t).collect();
/// let x: Vec<f64> = phi.iter().map(|p| 0.01 * p.sin()).collect();
/// let v: Vec<f64> = phi.iter().map(|p| 0.06 * p.cos()).collect();
/// let a: Vec<f64> = x.iter().map(|x| -36.0 * x).collect();
/// let f: Vec<f64> = (0..t.len())
///     .map(|i| 2.0 * v[i] + 0.5 * x[i] + 1e-4 * ((i * 7919 % 13) as f64 - 6.0))
///     .collect();
/// let data = ForceData::new(&t, &x, &v, &a, &f);
/// let cycles = cycles_from_phase(&t, &phi).unwrap();
/// let found = discover_force(damper, &[Candidate::new("spring", spring)], &data, &cycles,
///                            &DiscoverySettings::default()).unwrap();
/// assert_eq!(found.effects, ["spring"]);
/// assert!(found.gap_after < 0.2 * found.gap_before);
/// ```
pub fn discover_force(
    base: Arc<dyn ForceModel>,
    candidates: &[Candidate],
    data: &ForceData,
    cycles: &[Cycle],
    settings: &DiscoverySettings,
) -> Result<Discovery, DiscoveryError> {
    settings.check()?;
    let level = ForceLevel::new(data, cycles, settings)?;
    search::discover(&level, base, candidates, settings)
}

/// The force level: the measured kinematics and F_STF, their cycles and split, the force
/// sensor's noise and the settings.
pub(super) struct ForceLevel<'a> {
    data: &'a ForceData<'a>,
    cycles: &'a [Cycle],
    split: HoldoutSplit,
    sensor: f64,
    settings: &'a DiscoverySettings,
    /// The offset's bound: twice the largest |measured force| (1 N for a record of zeros).
    offset_reach: f64,
}

impl<'a> ForceLevel<'a> {
    /// The force level of `data` cut into `cycles`, with the sensor's noise of `settings` or
    /// estimated from the record.
    pub(super) fn new(
        data: &'a ForceData<'a>,
        cycles: &'a [Cycle],
        settings: &'a DiscoverySettings,
    ) -> Result<Self, DiscoveryError> {
        let sensor = settings.floor_of(data.f, "force", "N")?;
        let split = HoldoutSplit::new(data.t.len(), cycles, settings.holdout_every)?;
        let largest = data
            .f
            .iter()
            .filter(|f| f.is_finite())
            .fold(0.0_f64, |m, f| m.max(f.abs()));
        Ok(ForceLevel {
            data,
            cycles,
            split,
            sensor,
            settings,
            offset_reach: if largest > 0.0 { 2.0 * largest } else { 1.0 },
        })
    }

    /// The trial with the lowest training RMS (a converged fit before a failed one) among
    /// those run from the stages `stage(start)` for each of candidate `c`'s starts
    /// ([`candidate_starts`] against the residual `r`), and from the first of them
    /// [`SearchModel::released`] when a parameter of it sits on a bound: the multi-start of a
    /// candidate. Its evaluations and wall time are those of all the runs; the first run's
    /// error if every run fails.
    fn best_trial(
        &self,
        c: &Candidate,
        r: &[f64],
        stage: impl Fn(&[f64]) -> SearchModel,
    ) -> Result<Trial, DiscoveryError> {
        let train = &self.split.train;
        let mut starts =
            candidate_starts(&c.model, self.data, train, r, self.settings.extra_starts);
        let mut stages: Vec<SearchModel> = starts.iter().map(|s| stage(s)).collect();
        if let Some(released) = stages.first().and_then(SearchModel::released) {
            stages.push(released);
        }
        // The neutral start: the current model's optimum with the candidate's amplitude at
        // next to nothing, so that no candidate ends worse than the model it extends.
        if let Some(amp) = neutral_amplitude(c.model.as_ref()) {
            let mut neutral: Vec<f64> = c.model.params().iter().map(|s| s.default).collect();
            neutral[0] = amp;
            starts.push(neutral);
            stages.push(stage(&starts[starts.len() - 1]));
        }
        // The starts are independent fits: in parallel (a costly candidate's starts would
        // otherwise hold a step's last core alone), kept in their order. They are ranked by
        // their training RMS alone, so only the one kept is given its standard errors and its
        // residual at every sample: the same trial as when every start had them.
        let quick = FitSettings {
            errors: false,
            ..self.settings.fit.clone()
        };
        let fits: Vec<Result<(SearchModel, FitResult), DiscoveryError>> = stages
            .par_iter()
            .map(|s| {
                let fit = s.force_fit(self.settings, self.offset_reach)?;
                s.fitted(fit.fit_rows(self.data, Some(train), &quick, None))
            })
            .collect();
        let (evaluations, wall) = fits.iter().flatten().fold((0, 0.0), |(e, w), (_, t)| {
            (e + t.evaluations, w + t.wall_seconds)
        });
        let failed = |t: &FitResult| matches!(t.convergence, Convergence::Failed { .. });
        let best = (0..fits.len()).reduce(|best, next| match (&fits[best], &fits[next]) {
            (Err(_), Ok(_)) => next,
            (Ok((_, b)), Ok((_, t))) if (failed(t), t.rms) < (failed(b), b.rms) => next,
            _ => best,
        });
        let Some(best) = best else {
            return Err(DiscoveryError::BadSettings("no start to fit from".into()));
        };
        let (start, (_, quick_fit)) = match fits.into_iter().nth(best) {
            Some(Ok(fit)) => (&stages[best], fit),
            Some(Err(e)) => return Err(e),
            None => return Err(DiscoveryError::BadSettings("no start to fit from".into())),
        };
        let fit = start.force_fit(self.settings, self.offset_reach)?;
        let spent = (quick_fit.evaluations, quick_fit.wall_seconds);
        let completed = fit.with_errors_rows(self.data, Some(train), &self.settings.fit, quick_fit);
        let (stage, mut train_fit) = start.fitted(completed)?;
        let r = self.residual(&stage)?;
        let h = rms_over(&r, &self.split.holdout);
        // Every start's evaluations and time, and the errors' of the one kept.
        train_fit.evaluations = evaluations + (train_fit.evaluations - spent.0);
        train_fit.wall_seconds = wall + (train_fit.wall_seconds - spent.1);
        Ok(Trial {
            stage,
            train: train_fit,
            holdout: self.held_out(&r),
            holdout_mse: h * h,
        })
    }

    /// The blocks of the paired test for a model whose residual is `r` (every sample).
    fn blocks(&self, r: &[f64]) -> Blocks {
        Blocks::new(
            &self.split,
            block_length(r, &self.split, self.settings.filter_window),
        )
    }
}

impl Level for ForceLevel<'_> {
    const SAID: &'static Said = &choice::FORCE;
    /// From the defaults: the training fit of the base as it stood.
    const FIRST_FROM_FIT: bool = false;
    const RECHECK: bool = true;

    fn settings(&self) -> &DiscoverySettings {
        self.settings
    }

    fn split(&self) -> &HoldoutSplit {
        &self.split
    }

    /// The base's defaults, and the offset (if fitted) at the mean of the measured force less
    /// the base's at its defaults: the offset's least-squares value for them, so a large sensor
    /// offset is not left for the fit to walk to.
    fn start(&self, base: &Arc<dyn ForceModel>) -> SearchModel {
        let mut start = SearchModel::at_defaults(base, &[], self.settings.fit_offset);
        if self.settings.fit_offset {
            let r = self.residual(&start).unwrap_or_default();
            let finite: Vec<f64> = r.into_iter().filter(|v| v.is_finite()).collect();
            if !finite.is_empty() {
                let mean = finite.iter().sum::<f64>() / finite.len() as f64;
                if let Some(off) = start.values.last_mut() {
                    *off = mean.clamp(-self.offset_reach, self.offset_reach);
                }
            }
        }
        start
    }

    fn fit(
        &self,
        stage: &SearchModel,
        subset: &[usize],
        settings: &DiscoverySettings,
    ) -> Result<(SearchModel, FitResult), DiscoveryError> {
        let fit = stage.force_fit(settings, self.offset_reach)?;
        stage.fitted(fit.fit_rows(self.data, Some(subset), &settings.fit, None))
    }

    /// Measured minus modelled force at every sample.
    fn residual(&self, stage: &SearchModel) -> Result<Vec<f64>, DiscoveryError> {
        let fit = stage.force_fit(self.settings, self.offset_reach)?;
        let predicted = fit
            .predict(self.data, &stage.values)
            .map_err(|e| stage.fit_error(e))?;
        Ok(self
            .data
            .f
            .iter()
            .zip(&predicted)
            .map(|(m, p)| m - p)
            .collect())
    }

    /// The held-out samples' residuals.
    fn held_out(&self, r: &[f64]) -> Vec<f64> {
        self.split.holdout.iter().map(|&i| r[i]).collect()
    }

    /// The force sensor's noise with the kinematics' noise of `settings.motion_noise`
    /// propagated through the model at its values.
    fn floor(&self, stage: &SearchModel) -> Result<NoiseFloor, DiscoveryError> {
        let Some(motion) = self.settings.motion_noise else {
            return Ok(NoiseFloor::force(self.sensor, 0.0));
        };
        let fit = stage.force_fit(self.settings, self.offset_reach)?;
        fit.noise_floor(self.data, &stage.values, self.sensor, motion)
            .map_err(|e| stage.fit_error(e))
    }

    fn gap(
        &self,
        stage: &SearchModel,
        floor: &NoiseFloor,
    ) -> Result<(Vec<f64>, GapLocation), DiscoveryError> {
        let r = self.residual(stage)?;
        let location = locate_gap(&r, self.data, self.cycles, floor.sigma);
        let location = if self.settings.regimes {
            location
        } else {
            super::force_gap::without_regimes(location)
        };
        Ok((r, location))
    }

    /// Over blocks cut for the base's training residual, at least the floor's uncertainty.
    fn base_excess(&self, current: &Trial, floor: &NoiseFloor) -> Result<f64, DiscoveryError> {
        let blocks = self.blocks(&self.residual(&current.stage)?);
        Ok(choice::excess(
            &blocks.rms(&current.holdout),
            current.holdout_mse,
            floor.sigma,
            self.settings.floor_band(floor.propagated),
            self.settings,
        ))
    }

    /// Blocks cut for `current`'s residual, its own floor: the block test
    /// ([`acceptance::block_gain_z`]) and the floor's uncertainty band.
    fn measured<T>(
        &self,
        current: &Trial,
        base_excess: f64,
        then: impl FnOnce(&Yardstick) -> T,
    ) -> Result<T, DiscoveryError> {
        let blocks = self.blocks(&self.residual(&current.stage)?);
        let floor = self.floor(&current.stage)?;
        Ok(then(&Yardstick {
            gain_z: &|a: &[f64], b: &[f64]| acceptance::block_gain_z(a, b, &blocks),
            units: &|h: &[f64]| blocks.rms(h),
            base_excess,
            floor,
            floor_band: self.settings.floor_band(floor.propagated),
            block_samples: Some(blocks.length),
            reach: Reach::of(self.data.x, self.data.v),
        }))
    }

    /// Each candidate a small multi-start ([`candidate_starts`], [`ForceLevel::best_trial`]); the
    /// candidates are independent trials against the same current model: fitted in
    /// parallel, the costliest started first ([`costly_first`]), scored in their order.
    fn score_step(
        &self,
        step: usize,
        tried: &[&Candidate],
        current: &Trial,
        yardstick: &Yardstick,
    ) -> Result<Vec<(CandidateScore, Option<Trial>)>, DiscoveryError> {
        let settings = self.settings;
        let current_residual = self.residual(&current.stage)?;
        let score = |index: usize| {
            let c = tried[index];
            settings
                .observer
                .candidate(step, index, tried.len(), &c.name);
            let best = self.best_trial(c, &current_residual, |start| {
                current.stage.with(&c.model, start, 0)
            });
            let n_own = c.model.params().len();
            let s = choice::scored(&c.name, n_own, best, current, yardstick, settings);
            settings.observer.scored(step, &s.0);
            s
        };
        Ok(costly_first(
            tried.len(),
            |i| cost_rank(&tried[i].model),
            score,
        ))
    }

    fn replacement_trial(
        &self,
        c: &Candidate,
        rest: &SearchModel,
        part: usize,
        residual: &[f64],
    ) -> Result<Trial, DiscoveryError> {
        self.best_trial(c, residual, |start| {
            rest.inserting(part, 0, &c.model, start)
        })
    }

    fn closing_notes(
        &self,
        [gap_before, gap_after]: [f64; 2],
        floor: &NoiseFloor,
        final_name: &str,
        where_after: &str,
    ) -> Vec<String> {
        let gap = format!(
            "gap {gap_before:.4} N → {gap_after:.4} N (noise floor {:.4} N: force sensor {:.4} \
             N, kinematics through the model {:.4} N); final `{final_name}`: {where_after}",
            floor.sigma, floor.measured, floor.propagated,
        );
        [vec![gap], floor_doubts(floor, gap_after, self.settings)].concat()
    }
}

/// Where the final floor `floor` is itself uncertain, given the final gap `gap_after` (N):
/// sentences for the verdict notes. The floor rests on estimates — the force sensor's noise
/// from the record's third differences, the kinematics' noise from the filter's gain, carried
/// through the model by a linearisation — and leaves out the derivative filter's error where
/// ẍ jumps (stick–slip), which a model with an added mass multiplies.
fn floor_doubts(floor: &NoiseFloor, gap_after: f64, settings: &DiscoverySettings) -> Vec<String> {
    let mut doubts = Vec::new();
    if settings.motion_noise.is_none() {
        doubts.push(
            "the noise floor is the force sensor's alone: the kinematics' noise is not known \
             here, so the floor may be too low and an effect that only follows the kinematics' \
             noise or the filter's bias could pass the share test"
                .to_string(),
        );
    } else if floor.propagated > floor.measured {
        doubts.push(format!(
            "the noise floor is uncertain: its larger part ({:.4} of {:.4} N) is the \
             kinematics' noise propagated through the model, an estimate from the derivative \
             filter's gain that leaves out the filter's error where ẍ jumps (stick–slip); an \
             effect smaller than that uncertainty (the floor with this part {}× larger: {:.4} N) \
             is not named",
            floor.propagated,
            floor.sigma,
            settings.kinematics_uncertainty,
            floor
                .measured
                .hypot(settings.kinematics_uncertainty * floor.propagated)
        ));
    }
    if gap_after > 1.2 * floor.sigma {
        doubts.push(format!(
            "the final residual ({gap_after:.4} N) is {:.2}× the noise floor: either an effect \
             the candidates cannot express is missing, or the floor leaves out what the \
             kinematics carry (the derivative filter's bias); do not read the model as complete",
            gap_after / floor.sigma
        ));
    } else if gap_after < 0.9 * floor.sigma {
        doubts.push(format!(
            "the final residual ({gap_after:.4} N) is below the noise floor ({:.4} N): the floor \
             is overestimated, and shares of the excess over it are understated",
            floor.sigma
        ));
    }
    doubts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::force_model::{ModelError, ModelState};
    use crate::physics::param_spec::ParamSpec;

    /// F = a·tanh(v/s): proportional to `a`, nonlinear in `s`.
    struct Smooth(Vec<ParamSpec>);
    impl ForceModel for Smooth {
        fn name(&self) -> &str {
            "smooth"
        }
        fn params(&self) -> &[ParamSpec] {
            &self.0
        }
        fn force(&self, p: &[f64], s: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
            Ok(p[0] * (s.v / p[1]).tanh())
        }
    }

    fn smooth() -> Arc<dyn ForceModel> {
        Arc::new(Smooth(vec![
            ParamSpec::new("a", "N", 1.0, 0.0, 100.0, ""),
            ParamSpec::new("s", "m/s", 1e-3, 1e-6, 1.0, ""),
        ]))
    }

    #[test]
    fn the_grid_holds_each_default_and_no_bound() {
        // The grid is over the parameters after the first (the scale).
        let specs = smooth().params()[1..].to_vec();
        let grid = start_grid(&specs);
        assert_eq!(grid.len(), GRID_POINTS + 1);
        assert!(grid.iter().any(|p| p[..] == [1e-3]));
        for p in &grid {
            for (v, s) in p.iter().zip(&specs) {
                assert!(*v > s.min && *v < s.max, "{v} on a bound of {}", s.name);
            }
        }
        // The positive range of `s` spans six decades: spread in the logarithm.
        let s: Vec<f64> = grid.iter().map(|p| p[0]).filter(|&v| v != 1e-3).collect();
        let ratios: Vec<f64> = s.windows(2).map(|w| w[1] / w[0]).collect();
        assert!(
            ratios.iter().all(|r| (r / ratios[0] - 1.0).abs() < 1e-9),
            "{s:?}"
        );
        // Many parameters: fewer points each, within the cap.
        let many = vec![specs[0].clone(); 6];
        let g = start_grid(&many);
        assert!(g.len() <= GRID_MAX && g.len() > 1, "{}", g.len());
    }

    #[test]
    fn a_grid_start_lands_near_a_smoothing_speed_far_from_its_default() {
        // The residual to explain: 0.5·tanh(v/0.02), v a slow sweep of speeds.
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.01).collect();
        let v: Vec<f64> = t.iter().map(|t| 0.1 * (0.7 * t).sin()).collect();
        let x = vec![0.0; n];
        let a = vec![0.0; n];
        let r: Vec<f64> = v.iter().map(|v| 0.5 * (v / 0.02).tanh()).collect();
        let data = ForceData::new(&t, &x, &v, &a, &r);
        let all: Vec<usize> = (0..n).collect();
        let starts = candidate_starts(&smooth(), &data, &all, &r, 1);
        assert_eq!(starts.len(), 2, "{starts:?}");
        // The first: the default s, its scale the least squares there.
        assert_eq!(starts[0][1], 1e-3);
        assert!(starts[0][0] > 0.0 && starts[0][0] < 1.0, "{starts:?}");
        // The second: within one grid step (10^1.5) of the true s, and a scale near 0.5.
        let s = starts[1][1];
        assert!(s > 0.02 / 31.7 && s < 0.02 * 31.7, "{s}");
        assert!((starts[1][0] - 0.5).abs() < 0.25, "{starts:?}");
        // No extra start asked: the defaults only.
        assert_eq!(candidate_starts(&smooth(), &data, &all, &r, 0).len(), 1);
    }

    #[test]
    fn an_uncertain_floor_is_said() {
        let with = DiscoverySettings {
            motion_noise: Some(crate::data::kinematics::MotionNoise::default()),
            ..DiscoverySettings::default()
        };
        // The sensor's noise dominates and the gap is at the floor: nothing to say.
        let sure = NoiseFloor::force(0.02, 0.005);
        assert!(floor_doubts(&sure, sure.sigma, &with).is_empty());
        // The kinematics' part dominates: said, with the floor at its uncertainty.
        let kin = NoiseFloor::force(0.02, 0.04);
        let d = floor_doubts(&kin, kin.sigma, &with);
        assert_eq!(d.len(), 1, "{d:?}");
        assert!(
            d[0].contains("uncertain") && d[0].contains("0.0825"),
            "{d:?}"
        );
        // No kinematics' noise known; a gap far above or below the floor.
        let none = floor_doubts(&sure, sure.sigma, &DiscoverySettings::default());
        assert!(none[0].contains("sensor's alone"), "{none:?}");
        assert!(floor_doubts(&sure, 1.3 * sure.sigma, &with)[0].contains("1.30×"));
        assert!(floor_doubts(&sure, 0.8 * sure.sigma, &with)[0].contains("overestimated"));
    }

    #[test]
    fn only_parameters_pinned_on_a_bound_are_released() {
        let stage = |values: Vec<f64>| SearchModel {
            parts: vec![smooth()],
            values,
        };
        assert!(stage(vec![3.0, 0.05]).released().is_none());
        let r = stage(vec![3.0, 1.0]).released().unwrap();
        assert_eq!(r.values, [3.0, 1e-3]);
        let r = stage(vec![0.0, 1e-6]).released().unwrap();
        assert_eq!(r.values, [1.0, 1e-3]);
    }
}
