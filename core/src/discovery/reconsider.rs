//! The re-check of earlier effects, at any level that runs it ([`Level::reconsiders`]).
//!
//! After an effect is accepted, the earlier ones are tried again in its light: each is
//! replaced in turn by every candidate not in the model (refitted on the training cycles). An
//! effect chosen first can have won only because the one found later was missing (an added
//! mass hidden under a cubic spring made `wall_impact`, whose gap and exponent bend to mimic
//! both, beat `cubic_stiffness`). A replacement is made when the held-out evidence demands it
//! (the acceptance rule of [`super::acceptance`] against the current model), or when the
//! held-out evidence cannot separate the two (the current model is not better by the paired
//! test) and the replacement has fewer parameters and a lower BIC: the simpler is kept and the
//! tie named. At most one replacement per call; it is reported as a step of its own.

use rayon::prelude::*;

use super::acceptance;
use super::candidate::Candidate;
use super::choice::{self, Trial, Yardstick};
use super::error::DiscoveryError;
use super::level::Level;
use super::score::{CandidateScore, Step};
use super::search_model::SearchModel;
use super::settings::DiscoverySettings;

/// What the re-check tries and measures against: the candidates, the base's parts' names
/// and the base's held-out excess.
pub(super) type Vocabulary<'a> = (&'a [Candidate], &'a [String], f64);

/// Re-check the earlier of `effects` in the light of the last one accepted into `current`
/// (see the module's doc); the replacement step, if one was made (`current` and `effects`
/// then hold it).
pub(super) fn reconsider<L: Level>(
    level: &L,
    current: &mut Trial,
    effects: &mut [String],
    (candidates, in_base, base_excess): Vocabulary,
) -> Result<Option<Step>, DiscoveryError> {
    let measured_on = current.clone();
    level.measured(&measured_on, base_excess, |yardstick| {
        let recheck = Recheck {
            level,
            candidates,
            in_base,
            yardstick,
        };
        recheck.replace_one(current, effects)
    })?
}

/// One re-check: the level, the vocabulary and the step's yardstick.
struct Recheck<'a, L> {
    level: &'a L,
    candidates: &'a [Candidate],
    in_base: &'a [String],
    yardstick: &'a Yardstick<'a>,
}

/// A model with one of its effects taken out, for a replacement to be inserted in its place:
/// the model without the effect, its residual at every sample, the index of the part taken
/// out and how many parameters it had.
type Replaced<'a> = (&'a SearchModel, &'a [f64], usize, usize);

/// A replacement tried: its score, its trial, the effect index, the candidate, and whether it
/// is a tie rather than a win.
type Tried<'a> = (CandidateScore, Option<Trial>, usize, &'a Candidate, bool);

impl<L: Level> Recheck<'_, L> {
    /// Try every candidate in the place of every earlier effect; make the best replacement
    /// the evidence allows.
    fn replace_one(
        &self,
        current: &mut Trial,
        effects: &mut [String],
    ) -> Result<Option<Step>, DiscoveryError> {
        let n_base = current.stage.parts.len().saturating_sub(effects.len());
        let mut tried: Vec<Tried> = Vec::new();
        let earlier = effects.len().saturating_sub(1);
        for (j, effect) in effects.iter().enumerate().take(earlier) {
            let part = n_base + j;
            let Some(old) = current.stage.parts.get(part).cloned() else {
                continue;
            };
            let rest = current.stage.without(part, self.level.n_before());
            let rest_residual = self.level.residual(&rest)?;
            let replaced = (&rest, rest_residual.as_slice(), part, old.params().len());
            let to_try = current.stage.to_try(self.candidates, self.in_base, &[]);
            // Independent trials against the same current model: fitted in parallel, kept in
            // their order.
            let current = &*current;
            tried.par_extend(to_try.par_iter().map(|&c| {
                let label = format!("{} for {effect}", c.name);
                let (score, trial, tie) = self.replacement(c, &label, current, replaced);
                (score, trial, j, c, tie)
            }));
        }
        if tried.is_empty() {
            return Ok(None);
        }
        tried.sort_by(|a, b| a.0.holdout_rms.total_cmp(&b.0.holdout_rms));
        let Some(i) = pick(&tried) else {
            return Ok(None);
        };
        let scores = tried.iter().map(|t| t.0.clone()).collect();
        let mut step = choice::step_on(current, scores, self.yardstick);
        let (score, trial, j, c, tie) = tried.swap_remove(i);
        let Some(trial) = trial else {
            return Ok(None);
        };
        let old_name = effects[j].clone();
        let new_name = c.name.clone();
        let with = effects.last().map_or("", String::as_str);
        let names = [old_name.as_str(), &new_name, with];
        let settings = self.level.settings();
        step.verdict = replaced_verdict(
            &step,
            names,
            (&score, tie),
            &L::SAID.of_record(settings),
            settings,
        );
        step.accepted = Some(new_name.clone());
        if tie {
            step.tie_with = vec![old_name];
        }
        effects[j] = new_name;
        *current = trial;
        Ok(Some(step))
    }

    /// The candidate `c` put in the place of `replaced`, fitted and scored against `current`
    /// as `label`: its score (significant when it wins, or ties with fewer parameters and a
    /// lower BIC), its trial, and whether it is a tie rather than a win.
    fn replacement(
        &self,
        c: &Candidate,
        label: &str,
        current: &Trial,
        (rest, residual, part, old_len): Replaced,
    ) -> (CandidateScore, Option<Trial>, bool) {
        let settings = self.level.settings();
        let trial = match self.level.replacement_trial(c, rest, part, residual) {
            Ok(trial) => trial,
            Err(e) => return (choice::failed(label, e.to_string()), None, false),
        };
        // Its own parameters are not last here: take them by position.
        let from = rest.start_of(part, self.level.n_before());
        let n_own = c.model.params().len();
        let mut score = choice::score(label, 0, &trial, current, self.yardstick, settings);
        score.params = trial
            .train
            .params
            .get(from..from + n_own)
            .map(<[_]>::to_vec)
            .unwrap_or_default();
        let wins = score.significant;
        let tie = !wins
            && score.failure.is_none()
            && score.gain_z >= -acceptance::TIE_SIGMA
            && n_own < old_len
            && score.delta_bic < 0.0;
        score.significant = wins || tie;
        (score, Some(trial), tie)
    }
}

/// The replacement made, of those `tried` (sorted by held-out RMS): a win (lowest held-out
/// RMS) before a tie (lowest BIC).
fn pick(tried: &[Tried]) -> Option<usize> {
    tried
        .iter()
        .position(|t| t.0.significant && !t.4)
        .or_else(|| {
            (0..tried.len())
                .filter(|&i| tried[i].0.significant)
                .min_by(|&a, &b| tried[a].0.bic.total_cmp(&tried[b].0.bic))
        })
}

/// The verdict of a replacement step on `step`: `names` are the effect replaced, its
/// replacement and the effect whose acceptance called for it; the replacement's score and
/// whether it is a tie; said as `said`.
fn replaced_verdict(
    step: &Step,
    names: [&str; 3],
    (score, tie): (&CandidateScore, bool),
    said: &choice::Said,
    settings: &DiscoverySettings,
) -> String {
    let [old_name, new_name, with] = names;
    let (q, u) = (said.quantity, said.unit);
    let current_h = step.current_holdout_rms * said.scale;
    let h = score.holdout_rms * said.scale;
    if tie {
        format!(
            "replace `{old_name}` by `{new_name}`: with `{with}` in the model they explain the \
             data equally well ({q} {current_h:.4} → {h:.4} {u}, paired z {:.1} over {} \
             blocks, not beyond ±{}), and `{new_name}` is simpler (ΔBIC {:.1})",
            score.gain_z, score.effective_n, settings.min_gain_sigma, score.delta_bic
        )
    } else {
        format!(
            "replace `{old_name}` by `{new_name}`: with `{with}` in the model the held-out \
             evidence demands it ({q} {current_h:.4} → {h:.4} {u}, paired z {:.1} over {} \
             blocks, ΔBIC {:.1}, {:.0} % of the excess over the floor)",
            score.gain_z,
            score.effective_n,
            score.delta_bic,
            100.0 * score.explained_share
        )
    }
}
