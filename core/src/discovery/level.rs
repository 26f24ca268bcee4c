//! The fit level a discovery runs at: what differs between fitting forces along the measured
//! kinematics ([`super::force_level::ForceLevel`]) and simulating the oscillator against the
//! measured displacement ([`super::trajectory_level::TrajectoryLevel`]).
//!
//! A level holds its record and split, and says how a [`SearchModel`] is fitted on a subset
//! and on the whole record, its residual and where that lives, its noise floor (the evidence
//! a gain is measured against), the unit its gap is said in, and how the candidates of a step
//! are started and fitted. The search itself — base fit, steps, acceptance, re-check of
//! earlier effects, polish, final refit — is written once, in [`super::search`], over this
//! trait, and so is the trial of a stage ([`Level::trial`]: fit on the training samples,
//! score on the held-out ones). The re-check and the polish run at either level, as the
//! settings say, each level having its default ([`Level::RECHECK`], [`Level::POLISH`]). Where one level has nothing of its own (notes, admitted
//! candidates, parameters, a part of the result) the trait's default serves.

use std::sync::Arc;

use super::candidate::Candidate;
use super::choice::{Said, Trial, Yardstick};
use super::error::DiscoveryError;
use super::findings::TrajectoryPart;
use super::force_gap::GapLocation;
use super::holdout::{rms_over, HoldoutSplit};
use super::score::CandidateScore;
use super::search_model::SearchModel;
use super::settings::DiscoverySettings;
use crate::fit::{FitResult, NoiseFloor};
use crate::physics::force_model::ForceModel;

/// A fit level: its data, fits, residuals, unit and evidence.
pub(super) trait Level: Sync {
    /// How the level's verdicts say its residual (quantity, unit, scale from SI).
    const SAID: &'static Said;

    /// Whether the trial every candidate of the first step is measured against is that of
    /// the base from its whole-record fit (else from its defaults, the level's `start`).
    const FIRST_FROM_FIT: bool;

    /// Whether earlier effects are re-checked after each acceptance when the settings do not
    /// say ([`DiscoverySettings::recheck`]; not by default).
    const RECHECK: bool = false;

    /// Whether an accepted trial is polished when the settings do not say
    /// ([`DiscoverySettings::polish`]; not by default).
    const POLISH: bool = false;

    /// Whether a step that accepts nothing above 1.2× the floor says it is not to be trusted
    /// (not by default).
    const WARNS_UNRESOLVED: bool = false;

    /// The level's own parameters, fitted before the model's (the refitted oscillator's at
    /// trajectory level; none by default).
    fn n_before(&self) -> usize {
        0
    }

    /// The settings of the run.
    fn settings(&self) -> &DiscoverySettings;

    /// The record's held-out split.
    fn split(&self) -> &HoldoutSplit;

    /// Samples in the record: those the split trains on and those it holds out.
    fn samples(&self) -> usize {
        let split = self.split();
        split.train.len() + split.holdout.len()
    }

    /// The candidates the search may try, of those given, and notes on any left out (by
    /// default all, no note).
    fn admitted(&self, candidates: &[Candidate]) -> (Vec<Candidate>, Vec<String>) {
        (candidates.to_vec(), Vec::new())
    }

    /// Where the base's whole-record fit starts from: the level's own start values, the
    /// base's defaults and the offset (0) if fitted, improved as far as the level can before
    /// the fit (by default the base's defaults and the offset, nothing improved).
    fn start(&self, base: &Arc<dyn ForceModel>) -> SearchModel {
        SearchModel::at_defaults(base, &[], self.settings().fit_offset)
    }

    /// Fit `stage` on the samples `subset`: the stage with the fitted values, and the fit.
    fn fit(
        &self,
        stage: &SearchModel,
        subset: &[usize],
        settings: &DiscoverySettings,
    ) -> Result<(SearchModel, FitResult), DiscoveryError>;

    /// Measured minus modelled signal at every sample, for `stage` at its values.
    fn residual(&self, stage: &SearchModel) -> Result<Vec<f64>, DiscoveryError>;

    /// The held-out residual by the level's unit of evidence, from `r` (every sample): the
    /// held-out samples at force level, each held-out cycle's RMS at trajectory level.
    fn held_out(&self, r: &[f64]) -> Vec<f64>;

    /// Fit `stage` on the training samples and score it on the held-out ones: the one trial
    /// step of both levels (`fit` on the split's training samples, `residual` at every
    /// sample, `held_out` of it).
    fn trial(
        &self,
        stage: &SearchModel,
        settings: &DiscoverySettings,
    ) -> Result<Trial, DiscoveryError> {
        let (stage, train) = self.fit(stage, &self.split().train, settings)?;
        let r = self.residual(&stage)?;
        let h = rms_over(&r, &self.split().holdout);
        Ok(Trial {
            stage,
            train,
            holdout: self.held_out(&r),
            holdout_mse: h * h,
        })
    }

    /// The noise floor of `stage` at its values.
    fn floor(&self, stage: &SearchModel) -> Result<NoiseFloor, DiscoveryError>;

    /// The residual of `stage` at every sample and where it lives against `floor`.
    fn gap(
        &self,
        stage: &SearchModel,
        floor: &NoiseFloor,
    ) -> Result<(Vec<f64>, GapLocation), DiscoveryError>;

    /// The base's held-out mean square above its floor `floor` (at least what is resolved):
    /// the denominator of every step's explained fraction.
    fn base_excess(&self, current: &Trial, floor: &NoiseFloor) -> Result<f64, DiscoveryError>;

    /// Notes on how the search runs at this level (said once, before the steps; none by
    /// default).
    fn search_notes(&self) -> Vec<String> {
        Vec::new()
    }

    /// `then` called with the yardstick of a step on `current`.
    fn measured<T>(
        &self,
        current: &Trial,
        base_excess: f64,
        then: impl FnOnce(&Yardstick) -> T,
    ) -> Result<T, DiscoveryError>;

    /// The scores of the candidates `tried`, each added to `current`, in their order, with
    /// their trials where they ran.
    fn score_step(
        &self,
        step: usize,
        tried: &[&Candidate],
        current: &Trial,
        yardstick: &Yardstick,
    ) -> Result<Vec<(CandidateScore, Option<Trial>)>, DiscoveryError>;

    /// The trial of candidate `c` put in `rest` as its part `part` (for the re-check of an
    /// earlier effect); `residual` is `rest`'s at every sample.
    fn replacement_trial(
        &self,
        c: &Candidate,
        rest: &SearchModel,
        part: usize,
        residual: &[f64],
    ) -> Result<Trial, DiscoveryError>;

    /// Whether earlier effects are re-checked after each acceptance ([`super::reconsider`]):
    /// as the settings say, else the level's default.
    fn reconsiders(&self) -> bool {
        self.settings().recheck.unwrap_or(Self::RECHECK)
    }

    /// Whether an accepted trial is polished at the final fit's tolerance before the next
    /// step ([`super::search`]): as the settings say, else the level's default.
    fn polishes(&self) -> bool {
        self.settings().polish.unwrap_or(Self::POLISH)
    }

    /// The settings of the final whole-record refit, from the training fit's values, which
    /// are near the optimum: by default [`DiscoverySettings::refined`] (the fallback of the
    /// default solver was seen to wander off and end far worse).
    fn final_settings(&self, settings: &DiscoverySettings) -> DiscoverySettings {
        settings.refined()
    }

    /// The notes that close a run: the gap before and after, against the final floor.
    fn closing_notes(
        &self,
        gaps: [f64; 2],
        floor: &NoiseFloor,
        final_name: &str,
        where_after: &str,
    ) -> Vec<String>;

    /// The level's own part of the result (none by default): what the base's and the final
    /// model's whole-record fits `fits` (each with its residual) say beyond the shared
    /// report.
    fn part(
        &self,
        fits: [(&SearchModel, &[f64]); 2],
    ) -> Result<Option<TrajectoryPart>, DiscoveryError> {
        let _ = fits;
        Ok(None)
    }
}

#[cfg(test)]
mod tests {
    use super::super::force_level::ForceLevel;
    use super::super::trajectory_level::TrajectoryLevel;
    use super::super::trajectory_setup::TrajectorySetup;
    use super::*;
    use crate::data::force_data::ForceData;
    use crate::fit::{TrajectoryData, TrajectoryFit};
    use crate::physics::excitation::Excitation;
    use crate::physics::oscillator_params::OscillatorParams;
    use crate::regimes::cycles_from_phase;

    /// (re-check, polish) of each level with the settings `s`.
    fn choices(s: &DiscoverySettings) -> [(bool, bool); 2] {
        let t: Vec<f64> = (0..2000).map(|i| i as f64 / 100.0).collect();
        let phi: Vec<f64> = t.iter().map(|t| 6.0 * t).collect();
        let x: Vec<f64> = phi
            .iter()
            .map(|p| 0.01 * p.sin() + 1e-4 * (7.0 * p).cos())
            .collect();
        let cycles = cycles_from_phase(&t, &phi).unwrap();
        let data = ForceData::new(&t, &x, &x, &x, &x);
        let force = ForceLevel::new(&data, &cycles, s).unwrap();
        let setup = TrajectorySetup::new(TrajectoryFit::new(
            OscillatorParams::FREE,
            Arc::new(Excitation::None),
        ));
        let xs = TrajectoryData { t: &t, x: &x };
        let trajectory = TrajectoryLevel::new(&xs, &cycles, &setup, s).unwrap();
        [
            (force.reconsiders(), force.polishes()),
            (trajectory.reconsiders(), trajectory.polishes()),
        ]
    }

    #[test]
    fn recheck_and_polish_follow_the_settings_else_each_level_s_default() {
        let s = DiscoverySettings::default();
        assert_eq!(choices(&s), [(true, false), (false, true)]);
        let swapped = s.clone().recheck(Some(false)).polish(Some(true));
        assert_eq!(choices(&swapped), [(false, true), (false, true)]);
        let other = s.recheck(Some(true)).polish(Some(false));
        assert_eq!(choices(&other), [(true, false), (true, false)]);
    }
}
