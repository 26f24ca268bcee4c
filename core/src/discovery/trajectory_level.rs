//! The trajectory level of discovery ([`TrajectoryLevel`], a [`Level`] for the loop of
//! [`super::search`]): for records with a measured displacement only.
//!
//! The oscillator is simulated with the current STF model and compared with the measured x,
//! `S(μ) = mean((x_exp − x_sim − x_off)²)`; the oscillator's own parameters named in the setup
//! (e.g. `k`, `c`, friction; `m`, `k`, `c` for a rig driven by a measured force `u`) are
//! refitted with every model. The loop is that of [`super::search`]:
//!
//! 1. fit the base (and the oscillator) on the whole record: the x gap before;
//! 2. locate the x residual by ω band of the cycles and by region of the simulated motion
//!    against the displacement noise floor;
//! 3. add each candidate, refit everything on the training samples — the simulation runs
//!    through the whole record, so the held-out cycles (every `holdout_every`-th whole cycle)
//!    are predicted by a model that never saw them — and score the x residual there with the
//!    paired test and the BIC on the training samples ([`super::acceptance`]). The paired
//!    test pairs whole held-out cycles (their mean squared residual), not samples: a
//!    simulated x residual is correlated over a cycle, so per-sample pairs would count one
//!    cycle's misfit hundreds of times and overstate the evidence. With a force hint (the
//!    force recovered from the record's kinematics) a screen comes first: every candidate is
//!    fitted at force level to that force, and when one lowers it clearly, only the three
//!    that lower it most are fitted at trajectory level. Each candidate fitted starts from the
//!    best of its starts after a short fit (its force-level fit, and a screen of its
//!    amplitude on three bases); the candidates run in parallel;
//! 4. repeat until nothing is significant or `max_effects` are added;
//! 5. refit the final model and the oscillator on the whole record: gap before and after.
//!
//! Gaps, held-out and training RMS are displacements (m); `S` is reported in mm². At this
//! level [`DiscoverySettings::noise_sigma`] is the displacement noise σ (m) and
//! [`DiscoverySettings::fit_offset`] fits the displacement offset `x_off`.

use std::sync::Arc;

use rayon::prelude::*;

use super::acceptance;
use super::candidate::Candidate;
use super::choice::{self, Said, Trial, Yardstick};
use super::error::DiscoveryError;
use super::findings::{Discovery, TrajectoryPart};
use super::force_gap::GapLocation;
use super::force_level::{emit_scored, inside};
use super::force_subset_fit::{fit_subset, rms, rms_over};
use super::holdout::HoldoutSplit;
use super::level::Level;
use super::score::CandidateScore;
use super::scout::Scout;
use super::search;
use super::search_model::SearchModel;
use super::settings::DiscoverySettings;
use super::trajectory_gap::locate_x_gap;
use super::trajectory_subset_fit::{fit_on, Rig, Run, Track};
use crate::fit::{
    check_same_terms, FitParam, FitResult, FitSettings, ForceData, ForceFit, NoiseFloor, Solver,
    TrajectoryData, TrajectoryFit, DISPLACEMENT_OFFSET,
};
use crate::physics::force_model::{ForceModel, Reach};
use crate::physics::oscillator_params::{OscParam, OscillatorParams};
use crate::physics::param_spec::ParamSpec;
use crate::regimes::Cycle;

/// The oscillator side of a trajectory-level discovery: the oscillator, its drive, its
/// initial state and integrator, and its parameters refitted with every model (names of
/// [`OscillatorParams::NAMES`] or the initial state, with start values and bounds) — a
/// [`TrajectoryFit`] without a model, whose free parameters are those refitted — and the
/// force hint.
///
/// ```
/// use std::sync::Arc;
/// use stf_core::discovery::TrajectorySetup;
/// use stf_core::physics::excitation::Excitation;
/// use stf_core::fit::{FitParam, TrajectoryFit};
/// use stf_core::physics::oscillator_params::OscillatorParams;
/// let fit = TrajectoryFit::new(OscillatorParams::FREE, Arc::new(Excitation::None))
///     .free(FitParam::new("k", 268.0).bounds(100.0, 400.0))
///     .initial(0.03, 0.0);
/// let setup = TrajectorySetup::new(fit);
/// assert_eq!(setup.fit.free_params().len(), 1);
/// ```
#[derive(Clone)]
pub struct TrajectorySetup {
    /// The oscillator and its refitted parameters (the fit's settings and model unused).
    pub fit: TrajectoryFit,
    /// The STF force recovered from the record's kinematics with the setup's oscillator, if
    /// known: every model is first fitted to it at force level (milliseconds) for its start.
    pub force_hint: Option<ForceHint>,
}

/// The record's filtered velocity and acceleration and the STF force recovered from them
/// (the drive − m·a − k·x − F_R(v), with the setup's oscillator).
#[derive(Clone, Debug)]
pub struct ForceHint {
    /// Velocity, m/s.
    pub v: Vec<f64>,
    /// Acceleration, m/s².
    pub a: Vec<f64>,
    /// Recovered STF force, N.
    pub f: Vec<f64>,
}

impl TrajectorySetup {
    /// The oscillator of `fit`, its free parameters refitted with every model, no force hint.
    pub fn new(fit: TrajectoryFit) -> Self {
        TrajectorySetup {
            fit,
            force_hint: None,
        }
    }
    /// Start every model from its force-level fit to `hint`.
    pub fn force_hint(mut self, hint: ForceHint) -> Self {
        self.force_hint = Some(hint);
        self
    }
}

/// The paired z of the gain of per-cycle RMS residuals `new` over `reference`, on the log
/// scale: `dᵢ = 2·ln(reference_i / new_i)` (the log-ratio of cycle i's mean squared residual),
/// `z = mean(d) / (sd(d)/√N)`. A cycle is the unit: residuals within one are correlated. The
/// log makes cycles of small and large amplitude count alike: an effect that grows with
/// amplitude (a cubic spring) removes most of each cycle's misfit, a different share of
/// different sizes, and a difference of squares would vary so much across cycles that a few
/// held-out cycles could never show it. +∞ for a consistent gain without spread, 0 with fewer
/// than two cycles or no difference.
pub(super) fn cycle_gain_z(reference: &[f64], new: &[f64]) -> f64 {
    let d: Vec<f64> = reference
        .iter()
        .zip(new)
        .map(|(a, b)| 2.0 * (a.max(f64::MIN_POSITIVE) / b.max(f64::MIN_POSITIVE)).ln())
        .collect();
    if d.iter().any(|v| !v.is_finite()) {
        return 0.0;
    }
    acceptance::mean_z(&d)
}

/// The RMS of `r` over each held-out cycle: `holdout` holds whole cycles of increasing
/// samples, never two neighbouring cycles (one in `holdout_every` ≥ 2 is held out), so each
/// run of consecutive indices is one cycle.
fn cycle_rms(r: &[f64], holdout: &[usize]) -> Vec<f64> {
    let mut out = Vec::new();
    let (mut sum, mut count) = (0.0, 0usize);
    for (k, &i) in holdout.iter().enumerate() {
        let value = r.get(i).copied().unwrap_or(f64::NAN);
        sum += value * value;
        count += 1;
        let ends = holdout.get(k + 1).is_none_or(|&next| next != i + 1);
        if ends {
            out.push((sum / count as f64).sqrt());
            (sum, count) = (0.0, 0);
        }
    }
    out
}

impl SearchModel {
    /// Every parameter of the fit, starting from this stage's values.
    fn params(&self, setup: &TrajectorySetup, model: &Arc<dyn ForceModel>) -> Vec<FitParam> {
        let mut out: Vec<FitParam> = Vec::with_capacity(self.values.len());
        let mut values = self.values.iter().copied();
        for p in &setup.fit.free {
            let v = values.next().unwrap_or(p.value);
            out.push(p.clone().value(inside(v, p.min, p.max)));
        }
        for spec in model.params() {
            let v = values.next().unwrap_or(spec.default);
            out.push(FitParam::from_spec(spec).value(inside(v, spec.min, spec.max)));
        }
        if let Some(v) = values.next() {
            out.push(
                FitParam::new(DISPLACEMENT_OFFSET, v.clamp(-0.05, 0.05))
                    .bounds(-0.05, 0.05)
                    .scale(1e-3),
            );
        }
        out
    }

    /// Fit on `subset`: the stage with the fitted values, and the fit.
    fn fit_simulated(
        &self,
        track: &dyn Track,
        setup: &TrajectorySetup,
        subset: &[usize],
        settings: &DiscoverySettings,
    ) -> Result<(SearchModel, FitResult), DiscoveryError> {
        let model = self.model()?;
        let mut params = self.params(setup, &model);
        if track.fixes_start() {
            for p in &mut params {
                p.fixed |= crate::fit::INITIAL_STATE.contains(&p.name.as_str());
            }
        }
        self.fitted(fit_on(track, &model, &params, subset, &settings.fit))
    }

    /// The simulated run of this stage at its values.
    fn run(&self, rig: &Rig) -> Result<Run, DiscoveryError> {
        let model = self.model()?;
        rig.run(&model, &self.values)
            .map_err(|e| DiscoveryError::BadData(format!("simulating `{}`: {e}", self.name())))
    }

    /// The displacement residual of this stage at its values (the integration alone).
    fn residual(&self, rig: &Rig) -> Result<Vec<f64>, DiscoveryError> {
        let model = self.model()?;
        rig.residual(&model, &self.values)
            .map_err(|e| DiscoveryError::BadData(format!("simulating `{}`: {e}", self.name())))
    }

    /// Fit on the training samples and score on the held-out ones.
    fn trial_simulated(
        &self,
        rig: &Rig,
        setup: &TrajectorySetup,
        split: &HoldoutSplit,
        settings: &DiscoverySettings,
    ) -> Result<Trial, DiscoveryError> {
        let (stage, train) = self.fit_simulated(rig, setup, &split.train, settings)?;
        let r = stage.residual(rig)?;
        let h = rms_over(&r, &split.holdout);
        Ok(Trial {
            stage,
            train,
            holdout: cycle_rms(&r, &split.holdout),
            holdout_mse: h * h,
        })
    }
}

impl SearchModel {
    /// This stage with its model's parameters fitted at force level to the recovered force of
    /// `hint` on (every k-th of) the `train` samples — from its values, from them with the
    /// last part's amplitude near zero, and from the models' defaults, the best kept — and
    /// that fit's RMS residual; the oscillator's values are kept. `None` if no fit succeeds.
    fn force_started(
        &self,
        rig: &Rig,
        hint: &ForceHint,
        train: &[usize],
    ) -> Option<(SearchModel, f64)> {
        let model = self.model().ok()?;
        let n_osc = rig.oscillator.len();
        let n_model = model.params().len();
        let current = self.values.get(n_osc..n_osc + n_model)?;
        let defaults: Vec<f64> = model.params().iter().map(|s| s.default).collect();
        // A start, not a result: a few dozen iterations at a loose tolerance (a degenerate
        // effect — a vanishing yield force that leaves its smoothing speed free — otherwise
        // creeps for seconds).
        let settings = FitSettings::default()
            .solver(Solver::LevenbergMarquardt)
            .max_iters(40)
            .tol(1e-6);
        // Every k-th sample, at most `HINT_SAMPLES`: the recovered force is filtered, so a
        // thinned record holds the same information for a start. The model is evaluated at
        // those samples only — a model with internal state too, its state stepped across the
        // wider spacing (a few ms at most on a rig record; a relaxation faster than that makes
        // a poorer start, and the screened start remains).
        let stride = train.len().div_ceil(HINT_SAMPLES).max(1);
        let kept: Vec<usize> = train.iter().copied().step_by(stride).collect();
        let [t, x, v, a, f] = [rig.t, rig.x, &hint.v, &hint.a, &hint.f]
            .map(|s| kept.iter().map(|&i| s[i]).collect::<Vec<f64>>());
        let data = ForceData {
            t: &t,
            x: &x,
            v: &v,
            a: &a,
            f: &f,
        };
        let subset: Vec<usize> = (0..kept.len()).collect();
        let mut best: Option<(f64, Vec<f64>)> = None;
        // Also from the current values with the last part's amplitude near zero: the model
        // without the new effect, nested — a fit from there does no worse than the current
        // model's own, so the screen's gains are not lost to a poor start.
        let mut nested = current.to_vec();
        if let Some((i, spec)) = self.amplitude(n_osc) {
            nested[i - n_osc] = inside(1e-3 * spec.default, spec.min, spec.max);
        }
        for start in [current, nested.as_slice(), defaults.as_slice()] {
            let mut fit = ForceFit::new(model.clone());
            for (spec, &v) in model.params().iter().zip(start) {
                fit = fit.param(FitParam::from_spec(spec).value(inside(v, spec.min, spec.max)));
            }
            let Ok(r) = fit_subset(&fit, &data, &subset, &settings) else {
                continue;
            };
            if best.as_ref().is_none_or(|(rms, _)| r.rms < *rms) {
                best = Some((r.rms, r.params.iter().map(|p| p.value).collect()));
            }
        }
        let (rms, fitted) = best?;
        let mut values = self.values.clone();
        values[n_osc..n_osc + n_model].copy_from_slice(&fitted);
        let stage = SearchModel {
            parts: self.parts.clone(),
            values,
        };
        Some((stage, rms))
    }
}

/// Most samples of the force-level fit that starts a trajectory fit (see
/// [`SearchModel::force_started`]).
const HINT_SAMPLES: usize = 20_000;

/// Factors of the new effect's first parameter tried before its fit (see
/// [`SearchModel::starts`]).
const SCREEN: [f64; 6] = [1.0, 3.0, 0.3, 0.1, 0.03, 0.01];

/// Iterations of the short Levenberg–Marquardt fit that ranks a candidate's starts (see
/// [`SearchModel::started`]).
const START_ITERS: u64 = 6;

impl SearchModel {
    /// The starts of this stage's fit (a new effect last): the force-level start `hinted` (on
    /// the current oscillator and on the setup's, to which its force was recovered: a base
    /// whose friction `T` has absorbed a yield force would count it twice), and the screened
    /// start — of three bases (the current values, the current model on the
    /// setup's oscillator `osc_start`, every parameter at its default on `osc_start`) with the
    /// effect's first parameter (its amplitude, by the models' convention) at each of `SCREEN`
    /// × its default, the one of lowest training S, one simulation each.
    ///
    /// A trajectory is a strongly non-linear function of a stiffness or a force amplitude, so
    /// a fit from a default far from the data's value ends in a local minimum worse than the
    /// model without the effect; the screen starts it near the right size. A base that lacks
    /// an effect often refits the oscillator, and its own law, into a basin of their own (a
    /// lower `k` standing in for a missing stiffening) from which the sum cannot climb out;
    /// the other bases start outside it. The force-level start is kept apart: its starting S
    /// can be the worse while its basin is the right one (a power law gone linear standing in
    /// for a missing yield force: 0.47 mm screened against 0.07 mm from the force-level start
    /// after six iterations, on the paper's sweep). Parameters with a negative lower bound or
    /// a non-positive default are not scaled.
    fn starts(
        &self,
        track: &dyn Track,
        train: &[usize],
        osc_start: &[f64],
        hinted: Option<&SearchModel>,
    ) -> Vec<SearchModel> {
        // The force-level fit is to the force recovered with the setup's oscillator: it is
        // tried on that oscillator, and on the current one.
        let mut out: Vec<SearchModel> = Vec::new();
        if let Some(h) = hinted.filter(|h| h.values.len() == self.values.len()) {
            out.push(h.clone());
            let on_setup = h.on_oscillator(osc_start);
            if on_setup != h.values {
                out.push(SearchModel {
                    parts: self.parts.clone(),
                    values: on_setup,
                });
            }
        }
        let screen = self.amplitude(osc_start.len()).zip(self.model().ok());
        let mut best = (f64::INFINITY, self.values.clone());
        for values in self.bases(osc_start) {
            if let Some(((i, spec), model)) = &screen {
                let mut values = values;
                for f in SCREEN {
                    values[*i] = inside(spec.default * f, spec.min, spec.max);
                    if let Ok(residual) = track.residual(model, &values) {
                        let s = rms_over(&residual, train);
                        if s < best.0 {
                            best = (s, values.clone());
                        }
                    }
                }
            }
        }
        if !out.iter().any(|o| o.values == best.1) {
            out.push(SearchModel {
                parts: self.parts.clone(),
                values: best.1,
            });
        }
        out
    }

    /// The current values; the current model on the oscillator `osc_start`; every parameter
    /// at its default on `osc_start` (the offset, if any, as it is).
    fn bases(&self, osc_start: &[f64]) -> [Vec<f64>; 3] {
        let from_start = self.on_oscillator(osc_start);
        let mut fresh = from_start.clone();
        let defaults = self
            .parts
            .iter()
            .flat_map(|p| p.params().iter().map(|s| s.default));
        for (v, d) in fresh.iter_mut().skip(osc_start.len()).zip(defaults) {
            *v = d;
        }
        [self.values.clone(), from_start, fresh]
    }

    /// This stage's values with the oscillator's (the first ones) set to `osc`.
    fn on_oscillator(&self, osc: &[f64]) -> Vec<f64> {
        let mut values = self.values.clone();
        for (v, &s) in values.iter_mut().zip(osc) {
            *v = s;
        }
        values
    }

    /// The last part's first parameter and its index in `values` (after `n_osc` oscillator
    /// values), if it can be screened: a non-negative lower bound and a positive default.
    fn amplitude(&self, n_osc: usize) -> Option<(usize, ParamSpec)> {
        let extra = self.parts.last()?;
        let spec = extra.params().first()?;
        let n_model: usize = self.parts.iter().map(|p| p.params().len()).sum();
        let i = (n_osc + n_model).checked_sub(extra.params().len())?;
        (spec.min >= 0.0 && spec.default > 0.0 && i < self.values.len()).then(|| (i, spec.clone()))
    }

    /// The best of `starts` after a short fit of each (`START_ITERS` Levenberg–Marquardt
    /// iterations on the training samples): the stage a full fit continues from. One start
    /// is returned as it is.
    fn started(
        starts: Vec<SearchModel>,
        track: &dyn Track,
        setup: &TrajectorySetup,
        train: &[usize],
        settings: &DiscoverySettings,
    ) -> Option<SearchModel> {
        if starts.len() < 2 {
            return starts.into_iter().next();
        }
        let mut short = settings.levenberg_marquardt(None);
        short.fit = short.fit.max_iters(START_ITERS);
        let mut best: Option<(f64, SearchModel)> = None;
        for start in &starts {
            let Ok((stage, fit)) = start.fit_simulated(track, setup, train, &short) else {
                continue;
            };
            if best.as_ref().is_none_or(|(rms, _)| fit.rms < *rms) {
                best = Some((fit.rms, stage));
            }
        }
        best.map(|(_, s)| s).or_else(|| starts.into_iter().next())
    }
}

/// Candidates fitted at trajectory level in a step, at most: the others are ranked out by the
/// screen of [`Trials::step`].
const SCREEN_KEEP: usize = 3;

/// The least gain, as a share of the current model's mean square at force level, for the
/// screen of [`Trials::step`] to rank.
const SCREEN_MIN_GAIN: f64 = 0.01;

/// Fewest samples a cycle for the force-level screen of [`Trials::step`] to rank: below it the
/// derivative filter's ẍ, and with it the recovered force, is mostly bias (on an electronic
/// oscillator at 9 samples a period the screen ranked the true cubic spring 5th of 6).
const SCREEN_MIN_SAMPLES: usize = 20;

/// Most Levenberg–Marquardt iterations of a candidate's trial at trajectory level.
const TRIAL_ITERS: u64 = 60;

/// Most Levenberg–Marquardt iterations of a candidate's trial on the whole record after its
/// scout (see [`super::scout`]).
const SCOUTED_TRIAL_ITERS: u64 = 15;

/// Candidates fitted on the whole record in a scouted step, at most: the others are ranked
/// out by their fits on the scout (see [`Trials::step`]).
const SCOUT_KEEP: usize = 3;

/// The least share of the best candidate's gain on the scout for a candidate to be tried on
/// the whole record in a scouted step (see [`Trials::step`]). A candidate that lowers the
/// scout's mean square by a fraction of what the best one does cannot win the step unless
/// the best one fails on the whole record; on Silverbox's 100 000 samples `jamming_on_off`
/// (5 % of the excess explained) cost more than the two cubic springs' trials together.
const SCOUT_SHARE: f64 = 0.2;

/// Why a scouted candidate is not fitted on the whole record, if it is not: its scout rank
/// (`rank` of `of`, gain in m²) is past [`SCOUT_KEEP`], its gain is under [`SCOUT_SHARE`] of
/// the best candidate's `best`, or its scout fit (`start_rms`, m) is no better than the
/// current model's training RMS `current` on the whole record — where the search failed, and
/// a short polish does not climb out.
fn left_out(
    scout_rank: Option<(usize, usize, f64)>,
    best: f64,
    start_rms: f64,
    current: f64,
) -> Option<String> {
    if let Some((r, of, gain)) = scout_rank {
        if r >= SCOUT_KEEP {
            return Some(format!(
                "not fitted on the whole record: the scout ranks it {} of {of} (it lowers the \
                 scout's mean square by {:.3e} mm²)",
                r + 1,
                gain * 1e6
            ));
        }
        if best > 0.0 && gain < SCOUT_SHARE * best {
            return Some(format!(
                "not fitted on the whole record: on the scout it lowers the mean square by \
                 {:.3e} mm², less than {:.0} % of the best candidate's {:.3e} mm²",
                gain * 1e6,
                SCOUT_SHARE * 100.0,
                best * 1e6
            ));
        }
    }
    (start_rms >= current).then(|| {
        format!(
            "not fitted on the whole record: its scout fit leaves the training RMS at {:.4} mm, \
             not below the current model's {:.4} mm",
            start_rms * 1e3,
            current * 1e3
        )
    })
}

/// The force-level screen of a step's candidates ([`Trials::force_screen`]).
struct ForceScreen {
    /// Each candidate's force-level start and that fit's RMS (N).
    hinted: Vec<Option<(SearchModel, f64)>>,
    /// Each one's gain over the current model's mean square (N²).
    gains: Vec<Option<f64>>,
    /// Each one's rank by its gain (0 the best).
    rank: Vec<usize>,
    /// Whether the screen ranks out all but [`SCREEN_KEEP`].
    screened: bool,
}

/// What every candidate trial of a run shares.
struct Trials<'a, 'r> {
    rig: &'a Rig<'r>,
    setup: &'a TrajectorySetup,
    split: &'a HoldoutSplit,
    osc_start: &'a [f64],
    yardstick: &'a Yardstick<'a>,
    settings: &'a DiscoverySettings,
    /// Whether the force-level screen may rank candidates (enough samples a cycle for the
    /// recovered force to mean something).
    screen: bool,
    /// Where a candidate's values are searched before its trial on the whole record, on a
    /// long record.
    scout: Option<&'a Scout<'r>>,
}

/// The scout of a record of at least [`DiscoverySettings::scout_from`] samples; `None` for a
/// shorter record, or when the record makes no scout.
fn scout_of<'r>(
    rig: &Rig<'r>,
    cycles: &[Cycle],
    train: &[usize],
    settings: &DiscoverySettings,
) -> Option<Scout<'r>> {
    if settings.scout_from == 0 || rig.t.len() < settings.scout_from {
        return None;
    }
    Scout::new(rig, cycles, train)
}

impl Trials<'_, '_> {
    /// The scores of the candidates `tried` against `current` in `step`, in their order.
    ///
    /// A screen first (when the setup has a force hint): each candidate, added to the current
    /// model, is fitted at force level to the force recovered from the kinematics (a
    /// fraction of a second each), and ranked by how much it lowers that fit's mean square
    /// below the current model's. When the best gain is at least [`SCREEN_MIN_GAIN`] of the
    /// current model's mean square, only the best [`SCREEN_KEEP`] are fitted at trajectory
    /// level (starts, short fits, the trial; in parallel) and the others are reported as not
    /// fitted, with their gain and rank; otherwise all are fitted. A trajectory fit costs
    /// hundreds of simulations. On a scouted record each candidate's values are searched on
    /// the scout, and when more than [`SCOUT_KEEP`] were searched only the best
    /// [`SCOUT_KEEP`] by their scout fit's gain are tried on the whole record.
    fn step(
        &self,
        step: usize,
        tried: &[&Candidate],
        current: &Trial,
    ) -> Vec<(CandidateScore, Option<Trial>)> {
        let n_osc = self.rig.oscillator.len();
        let withs: Vec<SearchModel> = tried
            .iter()
            .map(|c| {
                let defaults: Vec<f64> = c.model.params().iter().map(|s| s.default).collect();
                current.stage.with(&c.model, &defaults, n_osc)
            })
            .collect();
        let ForceScreen {
            hinted,
            gains,
            rank,
            screened,
        } = self.force_screen(&withs, current);
        let searched: Vec<Option<(SearchModel, f64, f64)>> = (0..tried.len())
            .into_par_iter()
            .map(|i| {
                if screened && rank[i] >= SCREEN_KEEP {
                    return None;
                }
                self.settings
                    .observer
                    .candidate(step, i, tried.len(), &tried[i].name);
                let h = hinted[i].as_ref().map(|(s, _)| s);
                Some(self.searched(withs[i].clone(), h))
            })
            .collect();
        let scout_rank = self.scout_ranks(&searched, current);
        let best_scout_gain = scout_rank
            .iter()
            .flatten()
            .map(|&(_, _, gain)| gain)
            .fold(f64::NEG_INFINITY, f64::max);
        (0..tried.len())
            .into_par_iter()
            .map(|i| {
                let c = &tried[i];
                let Some((stage, _, start_rms)) = &searched[i] else {
                    let why = format!(
                        "not fitted at trajectory level: the force-level screen ranks it {} of \
                         {} (it lowers the recovered force's mean square by {:.3e} N²)",
                        rank[i] + 1,
                        tried.len(),
                        gains[i].unwrap_or(f64::NAN)
                    );
                    return (choice::failed(&c.name, why), None);
                };
                if let Some(why) = left_out(
                    scout_rank[i],
                    best_scout_gain,
                    *start_rms,
                    current.train.rms,
                ) {
                    return (choice::failed(&c.name, why), None);
                }
                let s = self.scored(c, stage.clone(), current);
                emit_scored(self.settings, step, Some(&s));
                s
            })
            .collect()
    }

    /// The force-level screen of the candidates `withs` (each added to `current`): each one's
    /// force-level start and its RMS, its gain over `current` (N²), its rank by the gain, and
    /// whether the screen ranks out all but [`SCREEN_KEEP`].
    fn force_screen(&self, withs: &[SearchModel], current: &Trial) -> ForceScreen {
        let train = &self.split.train;
        let hint = self.setup.force_hint.as_ref();
        let hinted: Vec<Option<(SearchModel, f64)>> = withs
            .par_iter()
            .map(|w| hint.and_then(|h| w.force_started(self.rig, h, train)))
            .collect();
        let reference = hint
            .and_then(|h| current.stage.force_started(self.rig, h, train))
            .map(|(_, rms)| rms);
        let gains: Vec<Option<f64>> = hinted
            .iter()
            .map(|h| Some(reference? * reference? - h.as_ref()?.1.powi(2)))
            .collect();
        let mut order: Vec<usize> = (0..withs.len()).collect();
        order.sort_by(|&a, &b| {
            let g = |i: usize| gains[i].unwrap_or(f64::INFINITY);
            g(b).total_cmp(&g(a))
        });
        let mut rank = vec![0; withs.len()];
        for (r, &i) in order.iter().enumerate() {
            rank[i] = r;
        }
        // The screen ranks only when the recovered force asks for something: its best gain
        // at least `SCREEN_MIN_GAIN` of the current model's mean square. Otherwise every
        // candidate is fitted — a small stiffening (k3·x³ of 0.01 N) is lost in the recovered
        // force's noise and still moves x near resonance.
        let best_gain = gains
            .iter()
            .flatten()
            .fold(f64::NEG_INFINITY, |a, &b| a.max(b));
        let screened = self.screen
            && withs.len() > SCREEN_KEEP
            && reference.is_some_and(|r| best_gain > SCREEN_MIN_GAIN * r * r);
        ForceScreen {
            hinted,
            gains,
            rank,
            screened,
        }
    }

    /// Each searched candidate's rank among them by the gain of its scout fit over the
    /// current model on the scout, their number and the gain (mean square, m²); all `None`
    /// without a scout, or when no more than [`SCOUT_KEEP`] were searched.
    fn scout_ranks(
        &self,
        searched: &[Option<(SearchModel, f64, f64)>],
        current: &Trial,
    ) -> Vec<Option<(usize, usize, f64)>> {
        let mut out = vec![None; searched.len()];
        let of = searched.iter().flatten().count();
        let Some(scout) = self.scout.filter(|_| of > SCOUT_KEEP) else {
            return out;
        };
        let Ok(model) = current.stage.model() else {
            return out;
        };
        let Ok(r) = scout.residual(&model, &current.stage.values) else {
            return out;
        };
        let reference = rms_over(&r, &scout.train).powi(2);
        let mut order: Vec<(usize, f64)> = searched
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.as_ref().map(|(_, ms, _)| (i, reference - ms)))
            .collect();
        order.sort_by(|a, b| b.1.total_cmp(&a.1));
        for (r, (i, gain)) in order.into_iter().enumerate() {
            out[i] = Some((r, of, gain));
        }
        out
    }

    /// Where candidate `with`'s trial starts (`with`: the current model with it added at its
    /// defaults; `hinted`: its force-level start): the best of its starts, fitted on the
    /// scout when there is one; its mean square on the scout's training samples (m²;
    /// infinite without a scout) and its RMS on the whole record's training samples (m; NaN
    /// without a scout).
    fn searched(&self, with: SearchModel, hinted: Option<&SearchModel>) -> (SearchModel, f64, f64) {
        let (track, train): (&dyn Track, &[usize]) = match self.scout {
            Some(scout) => (scout, &scout.train),
            None => (self.rig, &self.split.train),
        };
        let starts = with.starts(track, train, self.osc_start, hinted);
        let stage =
            SearchModel::started(starts, track, self.setup, train, self.settings).unwrap_or(with);
        match self.scout {
            Some(scout) => {
                let on = (self.rig, self.setup, self.split.train.as_slice());
                scouted(stage, scout, on, &trial_settings(self.settings))
            }
            None => (stage, f64::INFINITY, f64::NAN),
        }
    }

    /// The trial of candidate `c` from `stage` on the whole record, scored against
    /// `current`. Scouted, the search is done: the trial polishes, at most
    /// `SCOUTED_TRIAL_ITERS` iterations (a candidate still wandering then is scored where it
    /// stopped, as one wandering on the whole record is after `TRIAL_ITERS`).
    fn scored(
        &self,
        c: &Candidate,
        stage: SearchModel,
        current: &Trial,
    ) -> (CandidateScore, Option<Trial>) {
        let mut settings = trial_settings(self.settings);
        if self.scout.is_some() {
            let iters = settings.fit.max_iters.min(SCOUTED_TRIAL_ITERS);
            settings.fit = settings.fit.max_iters(iters);
        }
        choice::scored(
            &c.name,
            c.model.params().len(),
            stage.trial_simulated(self.rig, self.setup, self.split, &settings),
            current,
            self.yardstick,
            self.settings,
        )
    }
}

/// Where a fit scouted on `scout` continues on the whole record: `stage` fitted on the scout
/// if that lowers the whole record's RMS at the samples `train`, else `stage` (one
/// simulation of each); with its mean square on the scout's training samples (m²) and its RMS
/// at `train` (m).
fn scouted(
    stage: SearchModel,
    scout: &Scout,
    (rig, setup, train): (&Rig, &TrajectorySetup, &[usize]),
    settings: &DiscoverySettings,
) -> (SearchModel, f64, f64) {
    let on_scout = |s: &SearchModel| {
        s.model()
            .ok()
            .and_then(|m| scout.residual(&m, &s.values).ok())
            .map_or(f64::INFINITY, |r| rms_over(&r, &scout.train).powi(2))
    };
    let train_rms = |s: &SearchModel| {
        s.residual(rig)
            .map_or(f64::INFINITY, |r| rms_over(&r, train))
    };
    let before = train_rms(&stage);
    let Ok((fitted, fit)) = stage.fit_simulated(scout, setup, &scout.train, settings) else {
        let ms = on_scout(&stage);
        return (stage, ms, before);
    };
    let after = train_rms(&fitted);
    if after < before {
        (fitted, fit.rms * fit.rms, after)
    } else {
        let ms = on_scout(&stage);
        (stage, ms, before)
    }
}

/// Find the effects missing from `base` among `candidates`, at trajectory level.
///
/// `data` is the measured displacement; `cycles` cut it into whole cycles (of the rotor, or
/// of x itself, [`crate::regimes::cycles_from_x`]), every `settings.holdout_every`-th of which
/// is held out. `setup` says how the oscillator is driven and which of its parameters are
/// refitted with every model. Candidates already in the base (by model name) are skipped; a
/// candidate whose fit fails is scored as failed; a base that cannot be fitted is an error.
/// The result's [`Discovery::trajectory`] holds the oscillator as refitted.
pub fn discover_trajectory(
    base: Arc<dyn ForceModel>,
    candidates: &[Candidate],
    data: &TrajectoryData,
    cycles: &[Cycle],
    setup: &TrajectorySetup,
    settings: &DiscoverySettings,
) -> Result<Discovery, DiscoveryError> {
    settings.validate()?;
    let level = TrajectoryLevel::new(data, cycles, setup, settings)?;
    let base_params: Vec<(&ParamSpec, bool)> = base.params().iter().map(|s| (s, true)).collect();
    check_same_terms(&base_params, &level.rig.oscillator, &setup.fit.excitation)
        .map_err(|e| DiscoveryError::BadSettings(format!("the base `{}`: {e}", base.name())))?;
    search::discover(&level, base, candidates, settings)
}

/// The trajectory level: the measured displacement, its cycles and split, the oscillator
/// (the rig) simulated with every model, the displacement noise floor, and the scout and
/// screen that choose which candidates are fitted in full.
pub(super) struct TrajectoryLevel<'a> {
    data: &'a TrajectoryData<'a>,
    cycles: &'a [Cycle],
    setup: &'a TrajectorySetup,
    rig: Rig<'a>,
    split: HoldoutSplit,
    /// The displacement noise σ, m.
    floor: f64,
    /// The refitted oscillator parameters' start values.
    osc_start: Vec<f64>,
    /// Whether the force-level screen may rank candidates.
    screen: bool,
    scout: Option<Scout<'a>>,
    settings: &'a DiscoverySettings,
}

impl<'a> TrajectoryLevel<'a> {
    /// The trajectory level of `data` cut into `cycles`, the oscillator as `setup` says.
    pub(super) fn new(
        data: &'a TrajectoryData<'a>,
        cycles: &'a [Cycle],
        setup: &'a TrajectorySetup,
        settings: &'a DiscoverySettings,
    ) -> Result<Self, DiscoveryError> {
        let n = data.t.len();
        if data.x.len() != n || n < 8 {
            return Err(DiscoveryError::BadData(format!(
                "t and x must have equal lengths ≥ 8 (got {n} and {})",
                data.x.len()
            )));
        }
        for p in &setup.fit.free {
            let initial = crate::fit::INITIAL_STATE.contains(&p.name.as_str());
            if p.name.parse::<OscParam>().is_err() && !initial {
                return Err(DiscoveryError::BadSettings(format!(
                    "`{}` is not an oscillator parameter or the initial state; known: {}, x0, v0",
                    p.name,
                    OscillatorParams::NAMES.join(", ")
                )));
            }
        }
        let floor = settings.floor_of(data.x, "displacement", "m")?;
        let rig = Rig {
            system: setup.fit.system,
            excitation: setup.fit.excitation.clone(),
            oscillator: setup.fit.free.iter().map(|p| p.name.as_str()).collect(),
            initial: setup.fit.initial,
            sim: setup.fit.sim.clone(),
            fit_offset: settings.fit_offset,
            fixed_start: false,
            t: data.t,
            x: data.x,
        };
        let split = HoldoutSplit::new(n, cycles, settings.holdout_every)?;
        let scout = scout_of(&rig, cycles, &split.train, settings);
        Ok(TrajectoryLevel {
            data,
            cycles,
            setup,
            osc_start: setup.fit.free.iter().map(|p| p.value).collect(),
            screen: n / cycles.len().max(1) >= SCREEN_MIN_SAMPLES,
            rig,
            split,
            floor,
            scout,
            settings,
        })
    }
}

impl Level for TrajectoryLevel<'_> {
    fn said(&self) -> &'static Said {
        &choice::DISPLACEMENT
    }

    fn n_before(&self) -> usize {
        self.setup.fit.free.len()
    }

    fn settings(&self) -> &DiscoverySettings {
        self.settings
    }

    fn split(&self) -> &HoldoutSplit {
        &self.split
    }

    /// A candidate with a parameter that is the same term as a refitted one (`viscous`
    /// while `c` is refitted) would be fitted twice over the same valley: it is left out with
    /// a note saying why.
    fn admitted(&self, candidates: &[Candidate]) -> (Vec<Candidate>, Vec<String>) {
        let refitted = &self.rig.oscillator;
        let mut kept = Vec::new();
        let mut notes = Vec::new();
        for c in candidates {
            match c
                .model
                .params()
                .iter()
                .find_map(|s| s.same_as.filter(|o| refitted.contains(o)).map(|o| (s, o)))
            {
                Some((spec, osc)) => notes.push(format!(
                    "`{}` not tried: its `{}` is the same term as the refitted oscillator's \
                     `{osc}`",
                    c.name, spec.name
                )),
                None => kept.push(c.clone()),
            }
        }
        (kept, notes)
    }

    /// The oscillator's start, the base's defaults: fitted at force level to the force hint
    /// if any, then on the scout if any.
    fn start(&self, base: &Arc<dyn ForceModel>) -> SearchModel {
        let settings = self.settings;
        let start = SearchModel {
            values: self
                .osc_start
                .iter()
                .copied()
                .chain(base.params().iter().map(|s| s.default))
                .chain(settings.fit_offset.then_some(0.0))
                .collect(),
            parts: vec![base.clone()],
        };
        let all: Vec<usize> = (0..self.samples()).collect();
        let start = match &self.setup.force_hint {
            Some(h) => start
                .force_started(&self.rig, h, &all)
                .map_or(start, |(s, _)| s),
            None => start,
        };
        match &self.scout {
            Some(s) => {
                let lm = settings.levenberg_marquardt(None);
                scouted(start, s, (&self.rig, self.setup, &all), &lm).0
            }
            None => start,
        }
    }

    fn fit(
        &self,
        stage: &SearchModel,
        subset: &[usize],
        settings: &DiscoverySettings,
    ) -> Result<(SearchModel, FitResult), DiscoveryError> {
        stage.fit_simulated(&self.rig, self.setup, subset, settings)
    }

    fn residual(&self, stage: &SearchModel) -> Result<Vec<f64>, DiscoveryError> {
        stage.residual(&self.rig)
    }

    fn trial(
        &self,
        stage: &SearchModel,
        settings: &DiscoverySettings,
    ) -> Result<Trial, DiscoveryError> {
        stage.trial_simulated(&self.rig, self.setup, &self.split, settings)
    }

    /// From the base's whole-record fit: from the defaults it can end in a basin of its
    /// own, and every candidate would then be scored against that.
    fn first_trial(
        &self,
        _: &SearchModel,
        base_full: &SearchModel,
    ) -> Result<Trial, DiscoveryError> {
        self.trial(base_full, self.settings)
    }

    /// The displacement noise, whatever the model.
    fn floor(&self, _: &SearchModel) -> Result<NoiseFloor, DiscoveryError> {
        Ok(NoiseFloor::displacement(self.floor))
    }

    fn gap(
        &self,
        stage: &SearchModel,
        floor: &NoiseFloor,
    ) -> Result<(Vec<f64>, GapLocation), DiscoveryError> {
        let run = stage.run(&self.rig)?;
        let location = locate_x_gap(&run, self.cycles, floor.sigma);
        Ok((run.residual, location))
    }

    /// At least twice what `3σ/√N` held-out samples resolve.
    fn base_excess(&self, current: &Trial, _: &NoiseFloor) -> Result<f64, DiscoveryError> {
        let floor = self.floor;
        let resolvable = 3.0 * floor / (self.split.holdout.len().max(1) as f64).sqrt();
        Ok((current.holdout_mse - floor * floor).max(2.0 * floor * resolvable))
    }

    /// Whether the force-level screen runs, and the scout.
    fn search_notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        let n = self.samples();
        if !self.screen && self.setup.force_hint.is_some() {
            let per_cycle = n / self.cycles.len().max(1);
            notes.push(format!(
                "no force-level screen: {per_cycle} samples a cycle leave the recovered force to \
                 the derivative filter's bias (a screen needs {SCREEN_MIN_SAMPLES}); every \
                 candidate is fitted at trajectory level"
            ));
        }
        if let Some(s) = &self.scout {
            notes.push(format!(
                "scouted: each candidate's values are searched on {} pieces of the record \
                 ({} samples of {n}), then fitted on the whole record from there",
                s.pieces(),
                s.samples
            ));
        }
        notes
    }

    /// Whole held-out cycles, paired on the log of their mean squares ([`cycle_gain_z`]).
    fn measured<T>(
        &self,
        _: &Trial,
        base_excess: f64,
        then: impl FnOnce(&Yardstick) -> T,
    ) -> Result<T, DiscoveryError> {
        let test = |reference: &[f64], new: &[f64]| (cycle_gain_z(reference, new), reference.len());
        Ok(then(&Yardstick {
            gain_z: &test,
            tie_z: &cycle_gain_z,
            units: &|h: &[f64]| h.to_vec(),
            base_excess,
            floor: NoiseFloor::displacement(self.floor),
            floor_band: 0.0,
            block_samples: None,
            reach: reach_of(self.data, self.setup),
        }))
    }

    fn score_step(
        &self,
        step: usize,
        tried: &[&Candidate],
        current: &Trial,
        yardstick: &Yardstick,
    ) -> Result<Vec<(CandidateScore, Option<Trial>)>, DiscoveryError> {
        let trials = Trials {
            rig: &self.rig,
            setup: self.setup,
            split: &self.split,
            osc_start: &self.osc_start,
            yardstick,
            settings: self.settings,
            screen: self.screen,
            scout: self.scout.as_ref(),
        };
        Ok(trials.step(step, tried, current))
    }

    /// From the candidate's defaults, at most `TRIAL_ITERS` iterations.
    fn replacement_trial(
        &self,
        c: &Candidate,
        rest: &SearchModel,
        part: usize,
        _: &[f64],
    ) -> Result<Trial, DiscoveryError> {
        let defaults: Vec<f64> = c.model.params().iter().map(|s| s.default).collect();
        let stage = rest.inserting(part, self.n_before(), &c.model, &defaults);
        self.trial(&stage, &trial_settings(self.settings))
    }

    fn polishes(&self) -> bool {
        true
    }

    fn warns_unresolved(&self) -> bool {
        true
    }

    /// Levenberg–Marquardt alone, from the training fit (near the optimum).
    fn final_settings(&self, settings: &DiscoverySettings) -> DiscoverySettings {
        settings.levenberg_marquardt(None)
    }

    fn closing_notes(
        &self,
        [gap_before, gap_after]: [f64; 2],
        _: &NoiseFloor,
        final_name: &str,
        where_after: &str,
    ) -> Vec<String> {
        vec![format!(
            "x gap {:.4} mm → {:.4} mm RMS, S {:.4} → {:.4} mm² (noise floor {:.4} mm); final \
             `{final_name}`: {where_after}",
            gap_before * 1e3,
            gap_after * 1e3,
            s_mm2(gap_before),
            s_mm2(gap_after),
            self.floor * 1e3,
        )]
    }

    fn part(
        &self,
        [(before, r_before), (after, r_after)]: [(&SearchModel, &[f64]); 2],
    ) -> Result<Option<TrajectoryPart>, DiscoveryError> {
        let initial = |stage: &SearchModel| -> Result<[f64; 2], DiscoveryError> {
            self.rig
                .start(&stage.model()?, &stage.values)
                .map_err(DiscoveryError::BadData)
        };
        Ok(Some(TrajectoryPart {
            system_before: self.rig.system_of(&before.values),
            system_after: self.rig.system_of(&after.values),
            s_before_mm2: s_mm2(rms(r_before)),
            s_after_mm2: s_mm2(rms(r_after)),
            initial_before: initial(before)?,
            initial_after: initial(after)?,
        }))
    }
}

/// A displacement RMS `g` (m) as a mean square S in mm².
fn s_mm2(g: f64) -> f64 {
    g * g * 1e6
}

/// Levenberg–Marquardt alone, at most `TRIAL_ITERS` iterations: a candidate whose fit does
/// not settle by then (a stiff relaxation wandering through thousands of simulations) is
/// scored where it stopped, not chased by Nelder–Mead.
fn trial_settings(settings: &DiscoverySettings) -> DiscoverySettings {
    settings.levenberg_marquardt(Some(TRIAL_ITERS))
}
/// How far the record goes: its largest |x|, and the largest |v| of the force hint's
/// filtered velocity or, without one, of central differences of x.
fn reach_of(data: &TrajectoryData, setup: &TrajectorySetup) -> Reach {
    match &setup.force_hint {
        Some(h) => Reach::of(data.x, &h.v),
        None => {
            let v: Vec<f64> = (1..data.x.len().saturating_sub(1))
                .map(|i| (data.x[i + 1] - data.x[i - 1]) / (data.t[i + 1] - data.t[i - 1]))
                .collect();
            Reach::of(data.x, &v)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::interpolate::Linear;
    use crate::physics::excitation::Excitation;
    use crate::physics::force_model::{ModelError, ModelState};
    use crate::physics::model_sum::ModelSum;
    use crate::physics::oscillator::Oscillator;
    use crate::physics::param_spec::ParamSpec;
    use crate::regimes::cycles_from_x;
    use crate::simulate::synthetic::{sample_record, SensorNoise};
    use crate::simulate::Simulation;

    #[test]
    fn the_cycle_gain_counts_ratios_not_differences() {
        // Cycles of very different size, each halved: a perfectly consistent gain.
        assert_eq!(
            cycle_gain_z(&[1.0, 10.0, 0.1], &[0.5, 5.0, 0.05]),
            f64::INFINITY
        );
        // Better on some, worse on others: no evidence.
        let z = cycle_gain_z(&[1.0, 1.0, 1.0, 1.0], &[0.9, 1.1, 0.95, 1.05]);
        assert!(z.abs() < 1.0, "{z}");
        assert_eq!(cycle_gain_z(&[1.0], &[0.1]), 0.0);
    }

    #[test]
    fn held_out_cycles_are_the_runs_of_consecutive_samples() {
        let r = [3.0, 1.0, 1.0, 9.0, 9.0, 2.0, 2.0, 2.0, 4.0];
        let rms = cycle_rms(&r, &[1, 2, 5, 6, 7]);
        assert_eq!(rms, vec![1.0, 2.0]);
        assert_eq!(cycle_rms(&r, &[0, 8]), vec![3.0, 4.0]);
        assert!(cycle_rms(&r, &[]).is_empty());
    }

    /// A one-parameter force `p·g(x, v)`.
    struct Term(&'static str, Vec<ParamSpec>, fn(&ModelState) -> f64);
    impl ForceModel for Term {
        fn name(&self) -> &str {
            self.0
        }
        fn params(&self) -> &[ParamSpec] {
            &self.1
        }
        fn force(&self, p: &[f64], s: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
            Ok(p[0] * (self.2)(s))
        }
    }

    fn viscous() -> Arc<dyn ForceModel> {
        let spec = vec![ParamSpec::new("c_s", "N·s/m", 1.0, 0.0, 100.0, "")];
        Arc::new(Term("viscous", spec, |s| s.v))
    }
    fn cubic() -> Arc<dyn ForceModel> {
        let spec = vec![ParamSpec::new("k3", "N/m³", 1e5, 0.0, 1e9, "")];
        Arc::new(Term("cubic_stiffness", spec, |s| s.x.powi(3)))
    }
    fn quadratic() -> Arc<dyn ForceModel> {
        let spec = vec![ParamSpec::new("K2", "N·s²/m²", 1.0, 0.0, 1e4, "")];
        Arc::new(Term("quadratic_damping", spec, |s| s.v * s.v.abs()))
    }

    fn stiffening() -> Arc<dyn ForceModel> {
        let spec = vec![ParamSpec::new("k2", "N/m²", 1e3, 0.0, 1e7, "")];
        Arc::new(Term("quadratic_stiffness", spec, |s| s.x * s.x.abs()))
    }
    fn cubic_damping() -> Arc<dyn ForceModel> {
        let spec = vec![ParamSpec::new("c3", "N·s³/m³", 1.0, 0.0, 1e4, "")];
        Arc::new(Term("cubic_damping", spec, |s| s.v.powi(3)))
    }

    /// The trolley without friction, driven by a chirp force 0.5 → 1.5 Hz over 20 s at
    /// 200 Hz through the rig's displacement sensor; STF = 1.0·v (+ k3·x³).
    fn record(k3: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>, OscillatorParams) {
        record_of(k3, 20.0, 200.0)
    }

    /// A record of `seconds` at `rate` Hz: a sweep from 0.5 Hz at 0.05 Hz/s.
    fn record_of(
        k3: f64,
        seconds: f64,
        rate: f64,
    ) -> (Vec<f64>, Vec<f64>, Vec<f64>, OscillatorParams) {
        let system = OscillatorParams {
            t_friction: 0.0,
            delta_t: 0.0,
            ..OscillatorParams::FORCED
        };
        let n = (seconds * rate).round() as usize + 1;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / rate).collect();
        let sweep = 0.5 / seconds;
        let u: Vec<f64> = t
            .iter()
            .map(|&t| 2.0 * (std::f64::consts::TAU * (0.5 * t + sweep * t * t)).sin())
            .collect();
        let drive = Arc::new(Excitation::Force(Linear::new(t.clone(), u)));
        let mut parts = vec![viscous()];
        let mut values = vec![1.0];
        if k3 > 0.0 {
            parts.push(cubic());
            values.push(k3);
        }
        let truth: Arc<dyn ForceModel> = Arc::new(ModelSum::new(parts).unwrap());
        let osc = Oscillator::with_shared_excitation(system, drive)
            .with_model(truth, values)
            .unwrap();
        let run = Simulation::new(&osc).run_at(&t).unwrap();
        let rec = sample_record(&run, &SensorNoise::RIG, 7, false);
        (rec.t, rec.x, rec.u.unwrap(), system)
    }

    /// A trajectory-level discovery and its own part.
    struct Found {
        discovery: Discovery,
        part: TrajectoryPart,
    }

    fn discover(k3: f64) -> Found {
        discover_on(record(k3), &DiscoverySettings::default())
    }

    fn discover_on(
        record: (Vec<f64>, Vec<f64>, Vec<f64>, OscillatorParams),
        settings: &DiscoverySettings,
    ) -> Found {
        let candidates = [
            Candidate::new("cubic_stiffness", cubic()),
            Candidate::new("quadratic_damping", quadratic()),
        ];
        discover_among(record, &candidates, settings)
    }

    fn discover_among(
        (t, x, u, system): (Vec<f64>, Vec<f64>, Vec<f64>, OscillatorParams),
        candidates: &[Candidate],
        settings: &DiscoverySettings,
    ) -> Found {
        let cycles = cycles_from_x(&t, &x, 1.5e-4).unwrap();
        // Start the oscillator 2 % off.
        let start = |name: &str| {
            let v = system.get(name).unwrap() * 1.02;
            FitParam::new(name, v).bounds(v / 5.0, v * 5.0)
        };
        let setup = TrajectorySetup::new(
            TrajectoryFit::new(
                system,
                Arc::new(Excitation::Force(Linear::new(t.clone(), u))),
            )
            .free(start("m"))
            .free(start("k"))
            .free(start("c")),
        );
        let discovery = discover_trajectory(
            viscous(),
            candidates,
            &TrajectoryData { t: &t, x: &x },
            &cycles,
            &setup,
            settings,
        )
        .unwrap();
        let part = discovery.trajectory.clone().unwrap();
        Found { discovery, part }
    }

    #[test]
    fn a_scouted_long_record_names_the_effect_and_its_values_as_the_whole_record_does() {
        // 200 s at 50 Hz: 400 cycles, enough for pieces of six cycles at one sample in eight.
        let rec = record_of(1e4, 200.0, 50.0);
        let whole = discover_on(rec.clone(), &DiscoverySettings::default().scout_from(0));
        let scouted = discover_on(rec, &DiscoverySettings::default().scout_from(1));
        let (w, s) = (&whole.discovery, &scouted.discovery);
        eprintln!(
            "whole {:?} k3 {:?} S {}; scouted {:?} k3 {:?} S {}; {:?}",
            w.effects,
            w.value("k3"),
            whole.part.s_after_mm2,
            s.effects,
            s.value("k3"),
            scouted.part.s_after_mm2,
            s.notes
        );
        assert!(s.notes.iter().any(|n| n.starts_with("scouted")));
        assert!(!w.notes.iter().any(|n| n.starts_with("scouted")));
        assert_eq!(s.effects, ["cubic_stiffness"]);
        assert_eq!(w.effects, s.effects);
        let (kw, ks) = (w.value("k3").unwrap(), s.value("k3").unwrap());
        assert!((ks / 1e4 - 1.0).abs() < 0.2, "k3 = {ks}");
        assert!((ks / kw - 1.0).abs() < 0.01, "k3 {ks} scouted, {kw} whole");
        assert!(scouted.part.s_after_mm2 < 1.01 * whole.part.s_after_mm2);
    }

    #[test]
    fn the_scout_ranks_out_all_but_three_candidates_and_keeps_the_true_one() {
        let candidates = [
            Candidate::new("quadratic_damping", quadratic()),
            Candidate::new("cubic_damping", cubic_damping()),
            Candidate::new("quadratic_stiffness", stiffening()),
            Candidate::new("cubic_stiffness", cubic()),
        ];
        let rec = record_of(1e4, 200.0, 50.0);
        let found = discover_among(
            rec,
            &candidates,
            &DiscoverySettings::default().scout_from(1),
        );
        let d = &found.discovery;
        let first = &d.steps[0];
        let left_out = |why: &str| -> Vec<&str> {
            first
                .candidates
                .iter()
                .filter(|c| c.failure.as_deref().is_some_and(|f| f.contains(why)))
                .map(|c| c.name.as_str())
                .collect()
        };
        let ranked_out = left_out("the scout ranks it");
        let shared_out = left_out("of the best candidate's");
        eprintln!(
            "{:?}; ranked out {ranked_out:?}, under the share {shared_out:?}",
            d.effects
        );
        // Four searched, three kept by rank; the share rule may leave out more of those.
        assert_eq!(ranked_out.len(), 1, "{:?}", first.candidates);
        assert!(!ranked_out.contains(&"cubic_stiffness"));
        assert!(!shared_out.contains(&"cubic_stiffness"));
        let fitted = first
            .candidates
            .iter()
            .filter(|c| c.evaluations > 0)
            .count();
        assert_eq!(
            fitted + ranked_out.len() + shared_out.len(),
            4 - left_out("its scout fit").len()
        );
        assert_eq!(d.effects[0], "cubic_stiffness");
        let k3 = d.value("k3").unwrap();
        assert!((k3 / 1e4 - 1.0).abs() < 0.2, "k3 = {k3}");
    }

    #[test]
    fn a_scouted_candidate_is_left_out_by_rank_by_share_or_by_a_failed_search() {
        let best = 4e-8;
        let kept = left_out(Some((1, 5, 0.5 * best)), best, 1e-3, 2e-3);
        assert_eq!(kept, None);
        let ranked = left_out(Some((SCOUT_KEEP, 5, 0.9 * best)), best, 1e-3, 2e-3).unwrap();
        assert!(ranked.contains("ranks it 4 of 5"), "{ranked}");
        let share = left_out(Some((2, 5, 0.1 * best)), best, 1e-3, 2e-3).unwrap();
        assert!(share.contains("less than 20 % of the best"), "{share}");
        // No positive gain anywhere: the share rule has nothing to measure against.
        assert_eq!(left_out(Some((2, 5, -1e-9)), -1e-10, 1e-3, 2e-3), None);
        let failed = left_out(None, best, 2e-3, 2e-3).unwrap();
        assert!(
            failed.contains("not below the current model's 2.0000 mm"),
            "{failed}"
        );
    }

    #[test]
    fn a_hidden_cubic_stiffness_is_named_from_x_only_and_the_gap_shrinks() {
        let found = discover(1e4);
        let d = &found.discovery;
        eprintln!(
            "S {} → {} mm²; {:?}",
            found.part.s_before_mm2, found.part.s_after_mm2, d.notes
        );
        assert_eq!(d.effects, ["cubic_stiffness"]);
        assert!(found.part.s_after_mm2 < 0.5 * found.part.s_before_mm2);
        let k3 = d.value("k3").unwrap();
        assert!((k3 / 1e4 - 1.0).abs() < 0.2, "k3 = {k3}");
        assert!((found.part.system_after.k / 269.9346 - 1.0).abs() < 0.02);
    }

    #[test]
    fn without_the_cubic_term_nothing_is_named() {
        let found = discover(0.0);
        let d = &found.discovery;
        eprintln!(
            "S {} → {} mm²",
            found.part.s_before_mm2, found.part.s_after_mm2
        );
        assert!(d.effects.is_empty(), "{:?}", d.steps);
        assert!(d.gap_before < 2.0 * d.noise_floor);
    }
}
