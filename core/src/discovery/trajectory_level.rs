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

mod scout_ranking;
mod screen;
mod trials;

use std::sync::Arc;

use self::scout_ranking::scouted;
use self::screen::SCREEN_MIN_SAMPLES;
use self::trials::trial_settings;
use super::acceptance::cycle_gain_z;
use super::candidate::Candidate;
use super::choice::{self, Said, Trial, Yardstick};
use super::error::DiscoveryError;
use super::findings::{Discovery, TrajectoryPart};
use super::force_gap::GapLocation;
use super::holdout::{cycle_rms, rms, HoldoutSplit};
use super::level::Level;
use super::score::CandidateScore;
use super::scout::Scout;
use super::search;
use super::search_model::SearchModel;
use super::settings::DiscoverySettings;
use super::trajectory_gap::locate_x_gap;
use super::trajectory_setup::TrajectorySetup;
use super::trajectory_subset_fit::Rig;
use crate::fit::{check_same_terms, FitResult, NoiseFloor, TrajectoryData};
use crate::physics::force_model::{ForceModel, Reach};
use crate::physics::oscillator_params::{OscParam, OscillatorParams};
use crate::physics::param_spec::ParamSpec;
use crate::regimes::Cycle;

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
    settings.check()?;
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
    pub(super) data: &'a TrajectoryData<'a>,
    pub(super) cycles: &'a [Cycle],
    pub(super) setup: &'a TrajectorySetup,
    pub(super) rig: Rig<'a>,
    pub(super) split: HoldoutSplit,
    /// The displacement noise σ, m.
    pub(super) floor: f64,
    /// The refitted oscillator parameters' start values.
    pub(super) osc_start: Vec<f64>,
    /// Whether the force-level screen may rank candidates.
    pub(super) screen: bool,
    /// The scout of a long record, its pieces at the record's tolerance
    /// ([`Scout::searching`]).
    pub(super) scout: Option<Scout<'a>>,
    pub(super) settings: &'a DiscoverySettings,
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
        // A scout only on a record of at least `scout_from` samples (none when 0), and when
        // the record makes one.
        let scouts = settings.scout_from > 0 && n >= settings.scout_from;
        let scout = scouts
            .then(|| Scout::new(&rig, cycles, &split.train))
            .flatten();
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
    const SAID: &'static Said = &choice::DISPLACEMENT;
    /// From the base's whole-record fit: from the defaults it can end in a basin of its
    /// own, and every candidate would then be scored against that.
    const FIRST_FROM_FIT: bool = true;
    const POLISH: bool = true;
    const WARNS_UNRESOLVED: bool = true;

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
        let mut notes = Vec::new();
        let kept = candidates.iter().filter(|c| {
            let mut params = c.model.params().iter();
            let same =
                params.find_map(|s| s.same_as.filter(|o| refitted.contains(o)).map(|o| (s, o)));
            if let Some((spec, osc)) = same {
                notes.push(format!(
                    "`{}` not tried: its `{}` is the same term as the refitted oscillator's \
                     `{osc}`",
                    c.name, spec.name
                ));
            }
            same.is_none()
        });
        (kept.cloned().collect(), notes)
    }

    /// The oscillator's start, the base's defaults: fitted at force level to the force hint
    /// if any, then on the scout if any.
    fn start(&self, base: &Arc<dyn ForceModel>) -> SearchModel {
        let start = SearchModel::at_defaults(base, &self.osc_start, self.settings.fit_offset);
        let all: Vec<usize> = (0..self.samples()).collect();
        let hint = self.setup.force_hint.as_ref();
        let hinted = hint.and_then(|h| start.force_started(&self.rig, h, &all));
        let start = hinted.map_or(start, |(s, _)| s);
        let Some(scout) = &self.scout else {
            return start;
        };
        let lm = self.settings.levenberg_marquardt(None);
        scouted(start, scout, (&self.rig, self.setup, &all), &lm).0
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

    /// Each held-out cycle's RMS: the cycle is the unit of evidence.
    fn held_out(&self, r: &[f64]) -> Vec<f64> {
        cycle_rms(r, &self.split.holdout)
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
        let location = locate_x_gap(&run, self.cycles, floor.sigma, self.settings.x_unit);
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
                s.pieces.len(),
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
        Ok(then(&Yardstick {
            gain_z: &|a: &[f64], b: &[f64]| (cycle_gain_z(a, b), a.len()),
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
        Ok(self.scores(step, tried, current, yardstick))
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
        let u = self.settings.x_unit;
        vec![format!(
            "x gap {:.4} {u} → {:.4} {u} RMS, S {:.4} → {:.4} {u}² (noise floor {:.4} {u}); final \
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
