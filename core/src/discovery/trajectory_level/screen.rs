//! The force-level screen of a trajectory-level step: every candidate fitted at force level to
//! the force recovered from the record's kinematics ([`SearchModel::force_started`], also the
//! start of its trajectory fit), ranked by how much it lowers that force's mean square; when
//! the recovered force asks for something, only the best [`SCREEN_KEEP`] are fitted at
//! trajectory level ([`TrajectoryLevel::force_screen`]).

use rayon::prelude::*;

use super::TrajectoryLevel;
use crate::data::force_data::ForceData;
use crate::discovery::choice::Trial;
use crate::discovery::force_level::started_fit;
use crate::discovery::search_model::SearchModel;
use crate::discovery::trajectory_setup::ForceHint;
use crate::discovery::trajectory_subset_fit::Rig;
use crate::fit::{FitSettings, Solver};

impl SearchModel {
    /// This stage with its model's parameters fitted at force level to the recovered force of
    /// `hint` on (every k-th of) the `train` samples — from its values, from them with the
    /// last part's amplitude near zero, and from the models' defaults, the best kept — and
    /// that fit's RMS residual; the oscillator's values are kept. `None` if no fit succeeds.
    pub(in crate::discovery) fn force_started(
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
            .tol(1e-6)
            .errors(false);
        // Every k-th sample, at most `HINT_SAMPLES`: the recovered force is filtered, so a
        // thinned record holds the same information for a start. The model is evaluated at
        // those samples only — a model with internal state too, its state stepped across the
        // wider spacing (a few ms at most on a rig record; a relaxation faster than that makes
        // a poorer start, and the screened start remains).
        let stride = train.len().div_ceil(HINT_SAMPLES).max(1);
        let kept: Vec<usize> = train.iter().copied().step_by(stride).collect();
        let [t, x, v, a, f] = [rig.t, rig.x, &hint.v, &hint.a, &hint.f]
            .map(|s| kept.iter().map(|&i| s[i]).collect::<Vec<f64>>());
        let data = ForceData::new(&t, &x, &v, &a, &f);
        let subset: Vec<usize> = (0..kept.len()).collect();
        let mut best: Option<(f64, Vec<f64>)> = None;
        // Also from the current values with the last part's amplitude near zero: the model
        // without the new effect, nested — a fit from there does no worse than the current
        // model's own, so the screen's gains are not lost to a poor start.
        let mut nested = current.to_vec();
        if let Some((i, spec)) = self.amplitude(n_osc) {
            nested[i - n_osc] = (1e-3 * spec.default).clamp(spec.min, spec.max);
        }
        for start in [current, nested.as_slice(), defaults.as_slice()] {
            let fit = started_fit(&model, start);
            let Ok(r) = fit.fit_rows(&data, Some(&subset), &settings, None) else {
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
pub(in crate::discovery) const HINT_SAMPLES: usize = 20_000;

/// Candidates fitted at trajectory level in a step, at most: the others are ranked out by the
/// screen of [`TrajectoryLevel::scores`].
pub(in crate::discovery) const SCREEN_KEEP: usize = 3;

/// The least gain, as a share of the current model's mean square at force level, for the
/// screen of [`TrajectoryLevel::scores`] to rank.
pub(in crate::discovery) const SCREEN_MIN_GAIN: f64 = 0.01;

/// Fewest samples a cycle for the force-level screen of [`TrajectoryLevel::scores`] to rank: below it the
/// derivative filter's ẍ, and with it the recovered force, is mostly bias (on an electronic
/// oscillator at 9 samples a period the screen ranked the true cubic spring 5th of 6).
pub(in crate::discovery) const SCREEN_MIN_SAMPLES: usize = 20;

/// The force-level screen of a step's candidates ([`TrajectoryLevel::force_screen`]): each
/// candidate's force-level start and that fit's RMS (N), its gain over the current model's
/// mean square (N²), its rank by the gain (0 the best), and whether the screen ranks out all
/// but [`SCREEN_KEEP`].
pub(in crate::discovery) type ForceScreen = (
    Vec<Option<(SearchModel, f64)>>,
    Vec<Option<f64>>,
    Vec<usize>,
    bool,
);

impl TrajectoryLevel<'_> {
    /// The force-level screen of the candidates `withs` (each added to `current`): each one's
    /// force-level start and its RMS, its gain over `current` (N²), its rank by the gain, and
    /// whether the screen ranks out all but [`SCREEN_KEEP`].
    pub(in crate::discovery) fn force_screen(
        &self,
        withs: &[SearchModel],
        current: &Trial,
    ) -> ForceScreen {
        let train = &self.split.train;
        let hint = self.setup.force_hint.as_ref();
        // The current model's own fit, the reference, runs beside the candidates'.
        let (hinted, reference) = rayon::join(
            || -> Vec<Option<(SearchModel, f64)>> {
                withs
                    .par_iter()
                    .map(|w| hint.and_then(|h| w.force_started(&self.rig, h, train)))
                    .collect()
            },
            || {
                hint.and_then(|h| current.stage.force_started(&self.rig, h, train))
                    .map(|(_, rms)| rms)
            },
        );
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
        (hinted, gains, rank, screened)
    }
}
