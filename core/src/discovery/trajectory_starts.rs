//! Where a candidate's trajectory fit starts: the force-level start, and a screen of the new
//! effect's amplitude on three bases, the best after a short fit
//! ([`SearchModel::starts`], [`SearchModel::started`]).

use super::holdout::rms_over;
use super::search_model::SearchModel;
use super::settings::DiscoverySettings;
use super::trajectory_setup::TrajectorySetup;
use super::trajectory_subset_fit::Track;
use crate::physics::model_sum::neutral_amplitude;
use crate::physics::param_spec::ParamSpec;

/// Factors of the new effect's first parameter tried before its fit (see
/// [`SearchModel::starts`]).
pub(super) const SCREEN: [f64; 6] = [1.0, 3.0, 0.3, 0.1, 0.03, 0.01];

/// How near the current model's training RMS a neutral start must begin, relative
/// ([`SearchModel::neutral_on`]).
pub(super) const NEUTRAL_RMS_TOL: f64 = 1e-6;

/// The factor a neutral start's amplitude is made smaller by, and the most times.
const NEUTRAL_SHRINK: f64 = 1e-3;
const NEUTRAL_SHRINKS: usize = 4;

/// Iterations of the short Levenberg–Marquardt fit that ranks a candidate's starts (see
/// [`SearchModel::started`]).
pub(super) const START_ITERS: u64 = 6;

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
    pub(super) fn starts(
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
        let mut best = (f64::INFINITY, self.values.clone());
        if let Some(((i, spec), model)) = self.amplitude(osc_start.len()).zip(self.model().ok()) {
            for mut values in self.bases(osc_start) {
                for f in SCREEN {
                    values[i] = (spec.default * f).clamp(spec.min, spec.max);
                    if let Ok(residual) = track.residual(&model, &values) {
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

    /// This stage with its new effect neutral: its amplitude at
    /// [`crate::physics::model_sum::NEUTRAL_AMPLITUDE`] × its default, every other value as
    /// it is (the current model's optimum), so that it starts at the current model's residual;
    /// `None` when the effect's amplitude cannot start neutral.
    pub(super) fn neutral(&self, n_osc: usize) -> Option<SearchModel> {
        let extra = self.parts.last()?;
        let amp = neutral_amplitude(extra.as_ref())?;
        let i = self.start_of(self.parts.len() - 1, n_osc);
        let mut values = self.values.clone();
        *values.get_mut(i)? = amp;
        Some(SearchModel {
            parts: self.parts.clone(),
            values,
        })
    }

    /// [`SearchModel::neutral`], its amplitude made smaller ([`NEUTRAL_SHRINK`] at a time, at
    /// most [`NEUTRAL_SHRINKS`] times, never below its lower bound) until its RMS at `train`
    /// on `track` is within [`NEUTRAL_RMS_TOL`] of the current model's there (the effect at
    /// zero). A millionth of the default is nothing at the trolley's scale but not on every
    /// record: on a shaker record in volts (v ≈ 20 V/s) a `power_law` at that amplitude
    /// added about 1 % of the spring's force, its start sat at 170 times the current model's
    /// RMS, and its search, re-run from it, ended above the current model, which the neutral
    /// start is there to prevent. One simulation on `track` for the current model and one a
    /// try.
    pub(super) fn neutral_on(
        &self,
        n_osc: usize,
        track: &dyn Track,
        train: &[usize],
    ) -> Option<SearchModel> {
        let mut stage = self.neutral(n_osc)?;
        let (i, spec) = self.amplitude(n_osc)?;
        let model = stage.model().ok()?;
        let rms_at = |values: &[f64]| {
            let r = track.residual(&model, values).ok()?;
            Some(rms_over(&r, train)).filter(|v| v.is_finite())
        };
        let mut off = stage.values.clone();
        off[i] = 0.0;
        let Some(current) = rms_at(&off) else {
            return Some(stage);
        };
        for _ in 0..NEUTRAL_SHRINKS {
            let at = rms_at(&stage.values);
            if at.is_some_and(|at| at <= current * (1.0 + NEUTRAL_RMS_TOL)) {
                break;
            }
            let smaller = stage.values[i] * NEUTRAL_SHRINK;
            if smaller < spec.min {
                break;
            }
            stage.values[i] = smaller;
        }
        Some(stage)
    }

    /// The current values; the current model on the oscillator `osc_start`; every parameter
    /// at its default on `osc_start` (the offset, if any, as it is).
    pub(super) fn bases(&self, osc_start: &[f64]) -> [Vec<f64>; 3] {
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
    pub(super) fn on_oscillator(&self, osc: &[f64]) -> Vec<f64> {
        let n = osc.len().min(self.values.len());
        [&osc[..n], &self.values[n..]].concat()
    }

    /// The last part's first parameter and its index in `values` (after `n_osc` oscillator
    /// values), if it can be screened: a non-negative lower bound and a positive default.
    pub(super) fn amplitude(&self, n_osc: usize) -> Option<(usize, ParamSpec)> {
        let extra = self.parts.last()?;
        let spec = extra.params().first()?;
        let i = self.start_of(self.parts.len() - 1, n_osc);
        (spec.min >= 0.0 && spec.default > 0.0 && i < self.values.len()).then(|| (i, spec.clone()))
    }

    /// The best of `starts` after a short fit of each (`START_ITERS` Levenberg–Marquardt
    /// iterations on the training samples of `tracks.0`), ranked by their RMS at `train` on
    /// `tracks.1` (the same samples, at the tolerance the search is ranked at; the fit's own
    /// RMS when both integrate to one tolerance): the stage a full fit continues from, and
    /// its index among `starts`. One start is returned as it is.
    pub(super) fn started(
        starts: Vec<SearchModel>,
        tracks: (&dyn Track, &dyn Track),
        setup: &TrajectorySetup,
        train: &[usize],
        settings: &DiscoverySettings,
    ) -> Option<(usize, SearchModel)> {
        if starts.len() < 2 {
            return starts.into_iter().next().map(|s| (0, s));
        }
        let (fitted_on, ranked_on) = tracks;
        // Tracks integrated alike give the fit's own RMS again: no second simulation.
        let same = fitted_on.rtol() == ranked_on.rtol();
        let mut short = settings.levenberg_marquardt(None);
        // Ranked by their RMS alone: no standard errors (a tight simulation and a difference
        // column a parameter each).
        short.fit = short.fit.max_iters(START_ITERS).errors(false);
        let mut best: Option<(f64, usize, SearchModel)> = None;
        for (k, start) in starts.iter().enumerate() {
            let Ok((stage, fit)) = start.fit_simulated(fitted_on, setup, train, &short) else {
                continue;
            };
            let rms = if same {
                fit.rms
            } else {
                let Ok(r) = stage.model().map(|m| ranked_on.residual(&m, &stage.values)) else {
                    continue;
                };
                r.map_or(f64::INFINITY, |r| rms_over(&r, train))
            };
            if best.as_ref().is_none_or(|(b, _, _)| rms < *b) {
                best = Some((rms, k, stage));
            }
        }
        best.map(|(_, k, s)| (k, s))
            .or_else(|| starts.into_iter().next().map(|s| (0, s)))
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::physics::force_model::{ForceModel, ModelError, ModelState};
    use crate::physics::model_sum::NEUTRAL_AMPLITUDE;

    /// A force of one parameter named `name`, bounded below by `min`.
    struct Term(&'static str, Vec<ParamSpec>);
    impl ForceModel for Term {
        fn name(&self) -> &str {
            self.0
        }
        fn params(&self) -> &[ParamSpec] {
            &self.1
        }
        fn force(&self, p: &[f64], s: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
            Ok(p[0] * s.v)
        }
    }

    fn term(name: &'static str, min: f64) -> Arc<dyn ForceModel> {
        Arc::new(Term(
            name,
            vec![ParamSpec::new("a", "", 1.0, min, 10.0, "")],
        ))
    }

    /// A record whose residual is 0.01 at every sample plus `gain` times the added term's
    /// amplitude (the last value): how far the term moves the simulation.
    struct Sensitive(f64);
    impl Track for Sensitive {
        fn residual(&self, _: &Arc<dyn ForceModel>, values: &[f64]) -> Result<Vec<f64>, String> {
            Ok(vec![0.01 + self.0 * values[values.len() - 1]; 50])
        }
        fn rtol(&self) -> f64 {
            1e-7
        }
        fn fixes_start(&self) -> bool {
            false
        }
    }

    #[test]
    fn a_neutral_start_is_made_smaller_until_the_record_hardly_sees_it() {
        let train: Vec<usize> = (0..50).step_by(2).collect();
        let stage = |min: f64| SearchModel {
            parts: vec![term("base", 0.0), term("extra", min)],
            values: vec![2.0, 1.0],
        };
        let amplitude = |track: &Sensitive, min: f64| {
            stage(min).neutral_on(0, track, &train).unwrap().values[1]
        };
        // Hardly seen at a millionth of the default (1e-7 of the RMS): kept as it is.
        assert_eq!(amplitude(&Sensitive(1e-3), 0.0), NEUTRAL_AMPLITUDE);
        // Seen at twice the RMS: a thousandth at a time until within 1e-6 of it
        // (2e-3, 2e-6, then 2e-9 of the RMS).
        let small = amplitude(&Sensitive(2e4), 0.0);
        assert!(
            (small / (NEUTRAL_AMPLITUDE * 1e-9) - 1.0).abs() < 1e-9,
            "{small}"
        );
        // Never below the lower bound.
        assert_eq!(amplitude(&Sensitive(2e4), 1e-10), NEUTRAL_AMPLITUDE * 1e-3);
        // The other values are the current model's.
        assert_eq!(
            stage(0.0)
                .neutral_on(0, &Sensitive(2e4), &train)
                .unwrap()
                .values[0],
            2.0
        );
    }
}
