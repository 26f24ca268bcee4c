//! A trajectory-level step's trials: a stage simulated and fitted on a [`Track`] (the whole
//! record or the scout), and every candidate of a step searched, screened and scored
//! ([`TrajectoryLevel::scores`]); the trial itself is the one of [`Level::trial`].

use std::sync::Arc;

use rayon::prelude::*;

use super::scout_ranking::{left_out, scouted, unfitted};
use super::screen::SCREEN_KEEP;
use super::TrajectoryLevel;
use crate::discovery::candidate::Candidate;
use crate::discovery::choice::{self, Trial, Yardstick};
use crate::discovery::error::DiscoveryError;
use crate::discovery::level::Level;
use crate::discovery::score::CandidateScore;
use crate::discovery::scout::Scout;
use crate::discovery::search_model::SearchModel;
use crate::discovery::settings::DiscoverySettings;
use crate::discovery::trajectory_setup::TrajectorySetup;
use crate::discovery::trajectory_subset_fit::{fit_on, Rig, Run, Track};
use crate::fit::{FitParam, FitResult, DISPLACEMENT_OFFSET};
use crate::physics::force_model::ForceModel;

impl SearchModel {
    /// Every parameter of the fit, starting from this stage's values.
    pub(in crate::discovery) fn params(
        &self,
        setup: &TrajectorySetup,
        model: &Arc<dyn ForceModel>,
    ) -> Vec<FitParam> {
        let mut out: Vec<FitParam> = Vec::with_capacity(self.values.len());
        let mut values = self.values.iter().copied();
        for p in &setup.fit.free {
            let v = values.next().unwrap_or(p.value);
            out.push(p.clone().value(v.clamp(p.min, p.max)));
        }
        for spec in model.params() {
            let v = values.next().unwrap_or(spec.default);
            out.push(FitParam::from_spec(spec).value(v.clamp(spec.min, spec.max)));
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
    pub(in crate::discovery) fn fit_simulated(
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
    pub(in crate::discovery) fn run(&self, rig: &Rig) -> Result<Run, DiscoveryError> {
        let model = self.model()?;
        rig.run(&model, &self.values)
            .map_err(|e| DiscoveryError::BadData(format!("simulating `{}`: {e}", self.name())))
    }

    /// The displacement residual of this stage at its values (the integration alone).
    pub(in crate::discovery) fn residual(&self, rig: &Rig) -> Result<Vec<f64>, DiscoveryError> {
        let model = self.model()?;
        rig.residual(&model, &self.values)
            .map_err(|e| DiscoveryError::BadData(format!("simulating `{}`: {e}", self.name())))
    }
}

/// Most Levenberg–Marquardt iterations of a candidate's trial at trajectory level.
pub(in crate::discovery) const TRIAL_ITERS: u64 = 60;

/// Most Levenberg–Marquardt iterations of a candidate's trial on the whole record after its
/// scout (see [`crate::discovery::scout`]).
pub(in crate::discovery) const SCOUTED_TRIAL_ITERS: u64 = 15;

impl TrajectoryLevel<'_> {
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
    /// [`SCOUT_KEEP`] by their scout fit's gain are tried on the whole record; of those, one
    /// whose gain is under [`super::scout_ranking::SCOUT_SHARE`] of the best one's is not
    /// (however few were searched: [`left_out`]).
    pub(in crate::discovery) fn scores(
        &self,
        step: usize,
        tried: &[&Candidate],
        current: &Trial,
        yardstick: &Yardstick,
    ) -> Vec<(CandidateScore, Option<Trial>)> {
        let n_osc = self.rig.oscillator.len();
        let withs: Vec<SearchModel> = tried
            .iter()
            .map(|c| {
                let defaults: Vec<f64> = c.model.params().iter().map(|s| s.default).collect();
                current.stage.with(&c.model, &defaults, n_osc)
            })
            .collect();
        let (hinted, gains, rank, screened) = self.force_screen(&withs, current);
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
                Some(self.searched(withs[i].clone(), h, current.train.rms))
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
                    (*start_rms, current.train.rms),
                    self.settings.x_unit,
                ) {
                    return (choice::failed(&c.name, why), None);
                }
                let s = self.scored(c, stage.clone(), current, yardstick);
                self.settings.observer.scored(step, &s.0);
                s
            })
            .collect()
    }

    /// Where candidate `with`'s trial starts (`with`: the current model with it added at its
    /// defaults; `hinted`: its force-level start): the best of its starts (their short fits
    /// on the scout at [`crate::discovery::scout::SCOUT_RTOL`], when there is a scout),
    /// fitted on the scout when there is one; its mean square on the scout's training samples (m²;
    /// infinite without a scout) and its RMS on the whole record's training samples (m; NaN
    /// without a scout). Among the starts is the neutral one (the current model's optimum,
    /// the effect at next to nothing: [`SearchModel::neutral_on`]). Where the search on the
    /// scout still ends above the current model's training RMS `current_rms` on the whole
    /// record, the neutral start is put in its place, and the better of the two kept: a
    /// candidate never ends worse than the model it extends. The neutral start is scouted
    /// again when another start had won the short fits; when it had won them itself, the
    /// search just run was its own, and it is taken as it is (the fallback of [`scouted`]):
    /// on the Silverbox-layout bench record every second-step candidate's neutral start won
    /// and its second scout fit (1.0–6.7 s each) ended at that fallback.
    pub(in crate::discovery) fn searched(
        &self,
        with: SearchModel,
        hinted: Option<&SearchModel>,
        current_rms: f64,
    ) -> (SearchModel, f64, f64) {
        let searching = self.scout.as_ref().map(Scout::searching);
        let (track, loose, train): (&dyn Track, &dyn Track, &[usize]) =
            match (self.scout.as_ref(), searching.as_ref()) {
                (Some(scout), Some(loose)) => (scout, loose, &scout.train),
                _ => (&self.rig, &self.rig, &self.split.train),
            };
        let mut starts = with.starts(track, train, &self.osc_start, hinted);
        let neutral = with.neutral_on(self.osc_start.len(), track, train);
        starts.extend(neutral.clone());
        let n_starts = starts.len();
        let (k, stage) =
            SearchModel::started(starts, (loose, track), self.setup, train, self.settings)
                .unwrap_or_else(|| (0, with.clone()));
        let Some(scout) = self.scout.as_ref() else {
            return (stage, f64::INFINITY, f64::NAN);
        };
        let on = (&self.rig, self.setup, self.split.train.as_slice());
        let found = scouted(stage, scout, on, &trial_settings(self.settings));
        let from_neutral = neutral.is_some() && k + 1 == n_starts;
        if found.2 < current_rms {
            return found;
        }
        let Some(neutral) = neutral else {
            return found;
        };
        let alt = if from_neutral {
            unfitted(neutral, scout, on)
        } else {
            scouted(neutral, scout, on, &trial_settings(self.settings))
        };
        if alt.2 < found.2 {
            alt
        } else {
            found
        }
    }

    /// The trial of candidate `c` from `stage` on the whole record, scored against
    /// `current`. Scouted, the search is done: the trial polishes, at most
    /// `SCOUTED_TRIAL_ITERS` iterations (a candidate still wandering then is scored where it
    /// stopped, as one wandering on the whole record is after `TRIAL_ITERS`).
    pub(in crate::discovery) fn scored(
        &self,
        c: &Candidate,
        stage: SearchModel,
        current: &Trial,
        yardstick: &Yardstick,
    ) -> (CandidateScore, Option<Trial>) {
        let iters = match self.scout {
            Some(_) => SCOUTED_TRIAL_ITERS,
            None => TRIAL_ITERS,
        };
        let settings = self.settings.levenberg_marquardt(Some(iters));
        choice::scored(
            &c.name,
            c.model.params().len(),
            self.trial(&stage, &settings),
            current,
            yardstick,
            self.settings,
        )
    }
}

/// Levenberg–Marquardt alone, at most `TRIAL_ITERS` iterations: a candidate whose fit does
/// not settle by then (a stiff relaxation wandering through thousands of simulations) is
/// scored where it stopped, not chased by Nelder–Mead.
pub(in crate::discovery) fn trial_settings(settings: &DiscoverySettings) -> DiscoverySettings {
    settings.levenberg_marquardt(Some(TRIAL_ITERS))
}
