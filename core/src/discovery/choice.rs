//! One step of the search at either level: a candidate's score against the current model,
//! the choice among the scored candidates ([`acceptance::choose`]) and the verdict in words,
//! in the level's unit (N at force level, mm at trajectory level).
//!
//! What differs between the levels stays with them: how a trial is fitted (force fits
//! against simulations), the paired test's units (blocks of held-out samples against held-out
//! cycles) and the noise floor (the force sensor's with the kinematics' noise propagated
//! through the current model, or the position noise), passed here as the trial's `holdout`
//! and the [`Yardstick`].

use super::acceptance;
use super::error::DiscoveryError;
use super::score::{CandidateScore, Step};
use super::search_model::SearchModel;
use super::settings::DiscoverySettings;
use crate::fit::{Convergence, FitResult, NoiseFloor};
use crate::physics::force_model::Reach;

/// A model fitted on the training samples and scored on the held-out ones.
#[derive(Clone)]
pub(super) struct Trial {
    /// The model with its fitted values.
    pub stage: SearchModel,
    /// The fit on the training samples.
    pub train: FitResult,
    /// What the paired test reads: the residual at the held-out samples (force level, cut
    /// into blocks by the test, [`super::blocks`]) or the RMS residual of each held-out cycle
    /// (trajectory level).
    pub holdout: Vec<f64>,
    /// Mean square residual over the held-out samples.
    pub holdout_mse: f64,
}

/// How a level says its residuals: the quantity and the unit of the verdicts.
#[derive(Clone, Copy)]
pub(super) struct Said {
    /// What the held-out residual is called (`held-out RMS`, `held-out x RMS`).
    pub quantity: &'static str,
    /// Its unit in words (`N`, `mm`).
    pub unit: &'static str,
    /// The factor from the residual's SI value to `unit`.
    pub scale: f64,
    /// What the held-out pieces are called (`cycles`, `periods`).
    pub pieces: &'static str,
}

impl Said {
    /// Said of the record `settings` describe: a displacement in its `x_unit`, the held-out
    /// pieces by its `pieces`.
    pub fn of_record(self, settings: &DiscoverySettings) -> Said {
        Said {
            unit: if self.unit == "mm" {
                settings.x_unit
            } else {
                self.unit
            },
            pieces: settings.pieces,
            ..self
        }
    }
}

/// Force level: held-out RMS in N.
pub(super) const FORCE: Said = Said {
    quantity: "held-out RMS",
    unit: "N",
    scale: 1.0,
    pieces: "cycles",
};

/// Trajectory level: held-out x RMS in mm.
pub(super) const DISPLACEMENT: Said = Said {
    quantity: "held-out x RMS",
    unit: "mm",
    scale: 1e3,
    pieces: "cycles",
};

/// The level's paired test of two trials' `holdout`, the candidate (second) against the
/// current model (first): the z and the independent units it is over.
pub(super) type GainTest<'a> = &'a (dyn Fn(&[f64], &[f64]) -> (f64, usize) + Sync);

/// The RMS residual of each independent unit of a trial's `holdout`.
pub(super) type Units<'a> = &'a (dyn Fn(&[f64]) -> Vec<f64> + Sync);

/// What a step measures a candidate's held-out gain with and against.
pub(super) struct Yardstick<'a> {
    /// The paired test; its z also decides whether the best candidate beats another (a tie
    /// when not).
    pub gain_z: GainTest<'a>,
    /// The units of a trial's `holdout`.
    pub units: Units<'a>,
    /// The base's held-out mean square above the noise floor (at least what is resolved).
    pub base_excess: f64,
    /// The current model's noise floor.
    pub floor: NoiseFloor,
    /// The width of the floor's uncertainty in mean square (N² or m²): a gain is measured
    /// against at least this much excess ([`excess`]).
    pub floor_band: f64,
    /// The length of the test's blocks, samples (`None`: whole cycles).
    pub block_samples: Option<usize>,
    /// How far the record goes, to judge whether a fitted gap or threshold is nothing
    /// ([`crate::physics::force_model::ForceModel::reduces_to`]).
    pub reach: Reach,
}

/// The held-out mean square `mse` of a trial above the floor `sigma`², counted as at least
/// the floor's own uncertainty `band` (mean square) and at least what the held-out units
/// resolve: `min_gain_sigma` standard errors of the mean of the mean squares of the `units`
/// (their RMS residuals) at the floor (below [`acceptance::EXCESS_UNIT`]·σ², whose spread is
/// the noise's, not the misfit's). A model at the floor, or one whose floor is misestimated,
/// would otherwise divide a gain by nothing, and any consistent gain would explain "all" of
/// it. 0 with fewer than two units at the floor, no band and no excess.
pub(super) fn excess(
    units: &[f64],
    mse: f64,
    sigma: f64,
    band: f64,
    settings: &DiscoverySettings,
) -> f64 {
    let bar = acceptance::EXCESS_UNIT * sigma * sigma;
    let ms: Vec<f64> = units.iter().map(|r| r * r).filter(|&m| m < bar).collect();
    let resolved = acceptance::mean_se(&ms).map_or(0.0, |(_, se)| settings.min_gain_sigma * se);
    (mse - sigma * sigma).max(band).max(resolved).max(0.0)
}

/// `gain` over `excess`, 0 when there is no excess to explain.
fn share(gain: f64, excess: f64) -> f64 {
    if excess > 0.0 {
        gain / excess
    } else {
        0.0
    }
}

/// How `trial` (a model with the candidate `name`, whose own parameters are its `n_own`
/// before the offset) scores against `current`, measured by `yardstick`.
pub(super) fn score(
    name: &str,
    n_own: usize,
    trial: &Trial,
    current: &Trial,
    yardstick: &Yardstick,
    settings: &DiscoverySettings,
) -> CandidateScore {
    let h = trial.holdout_mse.sqrt();
    let offset_len = usize::from(settings.fit_offset);
    let np = trial.train.params.len();
    let own = trial
        .train
        .params
        .get(np.saturating_sub(offset_len + n_own)..np.saturating_sub(offset_len))
        .map(<[_]>::to_vec)
        .unwrap_or_default();
    let failure = matches!(trial.train.convergence, Convergence::Failed { .. })
        .then(|| format!("{:?}", trial.train.convergence));
    let (gain_z, effective_n) = (yardstick.gain_z)(&current.holdout, &trial.holdout);
    let gain = current.holdout_mse - trial.holdout_mse;
    let mut score = CandidateScore {
        name: name.to_string(),
        holdout_rms: h,
        train_rms: trial.train.rms,
        aic: trial.train.aic,
        bic: trial.train.bic,
        delta_aic: trial.train.aic - current.train.aic,
        delta_bic: trial.train.bic - current.train.bic,
        holdout_gain: current.holdout_mse.sqrt() - h,
        gain_z,
        effective_n,
        explained_fraction: share(gain, yardstick.base_excess),
        explained_share: share(
            gain,
            excess(
                &(yardstick.units)(&current.holdout),
                current.holdout_mse,
                yardstick.floor.sigma,
                yardstick.floor_band,
                settings,
            ),
        ),
        params: own,
        significant: false,
        failure,
        evaluations: trial.train.evaluations,
        wall_seconds: trial.train.wall_seconds,
    };
    score.significant = acceptance::is_significant(&score, settings);
    score
}

/// The score of the candidate `name` (`n_own` parameters of its own) and its trial, if
/// that ran (scored as [`score`]), or its failure ([`failed`]).
pub(super) fn scored(
    name: &str,
    n_own: usize,
    trial: Result<Trial, DiscoveryError>,
    current: &Trial,
    yardstick: &Yardstick,
    settings: &DiscoverySettings,
) -> (CandidateScore, Option<Trial>) {
    match trial {
        Ok(trial) => (
            score(name, n_own, &trial, current, yardstick, settings),
            Some(trial),
        ),
        Err(e) => (failed(name, e.to_string()), None),
    }
}

/// The score of a candidate whose fit could not run, and why.
pub(super) fn failed(name: &str, why: String) -> CandidateScore {
    CandidateScore {
        name: name.to_string(),
        holdout_rms: f64::NAN,
        train_rms: f64::NAN,
        aic: f64::NAN,
        bic: f64::NAN,
        delta_aic: f64::NAN,
        delta_bic: f64::NAN,
        holdout_gain: f64::NAN,
        gain_z: f64::NAN,
        explained_fraction: f64::NAN,
        explained_share: f64::NAN,
        failure: Some(why),
        ..CandidateScore::default()
    }
}

/// The step that adds one of the candidates `scored` (each with its trial when its fit ran)
/// to `current`: the candidates best held-out RMS first, the one accepted by
/// [`acceptance::choose`] (and its ties) or none, and the verdict said as `said`, with the
/// units and the floor of `yardstick`. Returns the step and the accepted candidate's trial
/// (`None` when nothing is accepted).
pub(super) fn decide(
    current: &Trial,
    mut scored: Vec<(CandidateScore, Option<Trial>)>,
    said: &Said,
    yardstick: &Yardstick,
    settings: &DiscoverySettings,
) -> (Step, Option<Trial>) {
    scored.sort_by(|a, b| a.0.holdout_rms.total_cmp(&b.0.holdout_rms));
    let scores: Vec<CandidateScore> = scored.iter().map(|s| s.0.clone()).collect();
    let holdout: Vec<&[f64]> = scored
        .iter()
        .map(|s| s.1.as_ref().map_or(&[][..], |t| t.holdout.as_slice()))
        .collect();
    let choice = acceptance::choose(&scores, &holdout, &|a, b| (yardstick.gain_z)(a, b).0);
    let mut step = step_on(current, scores, yardstick);
    let Some((winner, ties)) = choice else {
        step.verdict = rejected(&step, said, settings);
        return (step, None);
    };
    let tie_names: Vec<String> = ties
        .iter()
        .map(|&i| step.candidates[i].name.clone())
        .collect();
    step.verdict = accepted(&step, winner, said);
    if !tie_names.is_empty() {
        step.verdict.push_str(&format!(
            "; `{}` explain the data equally well (the best's held-out gain over them is \
             within one standard error of the paired test), `{}` is chosen as the simplest \
             (fewest parameters, then lowest BIC)",
            tie_names.join("`, `"),
            step.candidates[winner].name
        ));
    }
    let mut w_name = step.candidates[winner].name.clone();
    if let Some((simpler, why)) = reduced(&scored, &w_name, yardstick.reach) {
        step.verdict.push_str(&why);
        w_name = simpler;
    }
    step.accepted = Some(w_name.clone());
    step.tie_with = tie_names;
    let trial = scored
        .iter()
        .position(|s| s.0.name == w_name)
        .and_then(|pos| scored.swap_remove(pos).1);
    (step, trial)
}

/// The simpler candidate that the trial of `winner` is in effect (its model's
/// [`crate::physics::force_model::ForceModel::reduces_to`] at its fitted values), if that candidate was fitted in this step
/// too, with a sentence saying so: the step names it instead. Without a fit of it, the
/// sentence alone says what the winner amounts to.
fn reduced(
    scored: &[(CandidateScore, Option<Trial>)],
    winner: &str,
    reach: Reach,
) -> Option<(String, String)> {
    let (score, trial) = scored.iter().find(|s| s.0.name == winner)?;
    let model = trial.as_ref()?.stage.parts.last()?;
    let values: Vec<f64> = score.params.iter().map(|p| p.value).collect();
    let (simpler, _) = model.reduces_to(&values, reach)?;
    let shown: Vec<String> = score
        .params
        .iter()
        .map(|p| format!("{} = {:.3e}", p.name, p.value))
        .collect();
    let fitted = scored
        .iter()
        .any(|s| s.0.name == simpler && s.1.is_some() && s.0.failure.is_none());
    let what = format!(
        "; the fitted `{winner}` ({}) is in effect `{simpler}` where this record goes (|x| ≤ \
         {:.3e} m, |v| ≤ {:.3e} m/s)",
        shown.join(", "),
        reach.x,
        reach.v
    );
    Some(if fitted {
        (simpler.clone(), format!("{what}: `{simpler}` is named"))
    } else {
        (winner.to_string(), what)
    })
}

/// A step on `current` with the `candidates` scored against it and nothing decided yet.
pub(super) fn step_on(
    current: &Trial,
    candidates: Vec<CandidateScore>,
    yardstick: &Yardstick,
) -> Step {
    Step {
        current: current.stage.name(),
        current_holdout_rms: current.holdout_mse.sqrt(),
        effective_n: (yardstick.units)(&current.holdout).len(),
        block_samples: yardstick.block_samples,
        floor: yardstick.floor,
        candidates,
        accepted: None,
        tie_with: Vec::new(),
        verdict: String::new(),
    }
}

/// The units of `step` in words: `48 blocks of ≥ 38 held-out samples` or `16 held-out cycles`
/// (`said.pieces`).
fn units(step: &Step, said: &Said) -> String {
    match step.block_samples {
        Some(l) => format!("{} blocks of ≥ {l} held-out samples", step.effective_n),
        None => format!("{} held-out {}", step.effective_n, said.pieces),
    }
}

/// The verdict of a step that accepts its candidate `winner`.
fn accepted(step: &Step, winner: usize, said: &Said) -> String {
    let w = &step.candidates[winner];
    let params: Vec<String> = w
        .params
        .iter()
        .map(|p| {
            format!(
                "{} = {}",
                p.name,
                crate::digits::with_error(p.value, p.std_error)
            )
        })
        .collect();
    format!(
        "add `{}`: {} {:.4} → {:.4} {} (paired z {:.1} over {}), ΔBIC {:.1}, explains \
         {:.0} % of the current model's held-out excess over its noise floor ({:.4} {}) and \
         {:.0} % of the base's held-out gap; {}",
        w.name,
        said.quantity,
        step.current_holdout_rms * said.scale,
        w.holdout_rms * said.scale,
        said.unit,
        w.gain_z,
        units(step, said),
        w.delta_bic,
        100.0 * w.explained_share,
        step.floor.sigma * said.scale,
        said.unit,
        100.0 * w.explained_fraction,
        params.join(", ")
    )
}

/// The verdict of a step that accepts nothing: the rule, and the candidates that passed both
/// tests but explain too little of the excess over the floor.
fn rejected(step: &Step, said: &Said, settings: &DiscoverySettings) -> String {
    let mut verdict = format!(
        "no candidate lowers the {} ({:.4} {}) with a paired z above {} over {}, a BIC drop \
         above {} and at least {:.0} % of the held-out excess over the noise floor ({:.4} {}): \
         nothing is missing that the data demand",
        said.quantity,
        step.current_holdout_rms * said.scale,
        said.unit,
        settings.min_gain_sigma,
        units(step, said),
        settings.min_bic_drop,
        100.0 * settings.min_explained,
        step.floor.sigma * said.scale,
        said.unit,
    );
    let small: Vec<String> = step
        .candidates
        .iter()
        .filter(|c| acceptance::passes_tests(c, settings))
        .map(|c| {
            format!(
                "`{}` ({:.4} {}, paired z {:.1} over {} units, ΔBIC {:.1}) explains only {:.1} %",
                c.name,
                c.holdout_rms * said.scale,
                said.unit,
                c.gain_z,
                c.effective_n,
                c.delta_bic,
                100.0 * c.explained_share
            )
        })
        .collect();
    if !small.is_empty() {
        verdict.push_str(&format!(
            "; significant but explaining too little of the excess: {}",
            small.join(", ")
        ));
    }
    verdict
}

/// When nothing was accepted although the current model's held-out RMS stands above 1.2× the
/// noise floor: a warning that the verdict "nothing is missing" is not to be trusted, with
/// the candidate that came closest (the lowest held-out RMS below the current one), its z,
/// the units it is over and the share of the excess it explains. An effect that acts in a
/// few cycles only (a yield force near the breakaway) can explain the whole excess and still
/// fall short of the paired test on few held-out cycles; a longer record, or one that dwells
/// where the effect acts, tells.
pub(super) fn unresolved(step: &Step, said: &Said) -> Option<String> {
    let floor = step.floor.sigma;
    if step.accepted.is_some() || !(step.current_holdout_rms > 1.2 * floor) {
        return None;
    }
    let excess = step.current_holdout_rms.powi(2) - floor * floor;
    let closest = step
        .candidates
        .iter()
        .filter(|c| c.failure.is_none() && c.holdout_rms < step.current_holdout_rms)
        .min_by(|a, b| a.holdout_rms.total_cmp(&b.holdout_rms));
    let lead = format!(
        "not to be trusted: the held-out RMS ({:.4} {}) is {:.1}× the noise floor, so \
         something is missing",
        step.current_holdout_rms * said.scale,
        said.unit,
        step.current_holdout_rms / floor
    );
    Some(match closest {
        Some(c) => format!(
            "{lead}; `{}` comes closest ({:.4} {}, {:.0} % of the excess over the floor) but \
             its paired z is {:.1} over {} — a longer record, or one that dwells where the gap \
             is, would tell",
            c.name,
            c.holdout_rms * said.scale,
            said.unit,
            100.0 * (step.current_holdout_rms.powi(2) - c.holdout_rms.powi(2)) / excess,
            c.gain_z,
            units(step, said)
        ),
        None => format!("{lead} that no candidate of the vocabulary explains"),
    })
}
