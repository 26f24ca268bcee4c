//! One step of the search at either level: a candidate's score against the current model,
//! the choice among the scored candidates ([`acceptance::choose`]) and the verdict in words,
//! in the level's unit (N at force level, mm at trajectory level).
//!
//! What differs between the levels stays with them: how a trial is fitted (force fits
//! against simulations) and the paired test's units (held-out samples against held-out
//! cycles), passed here as the trial's `holdout` and the `gain_z` function.

use super::acceptance;
use super::error::DiscoveryError;
use super::score::{CandidateScore, Step};
use super::settings::DiscoverySettings;
use super::stage::Stage;
use crate::fit::{Convergence, FitResult};

/// A model fitted on the training samples and scored on the held-out ones.
pub(super) struct Trial {
    /// The model with its fitted values.
    pub stage: Stage,
    /// The fit on the training samples.
    pub train: FitResult,
    /// The units of the paired test: residuals at the held-out samples (force level) or RMS
    /// residuals of the held-out cycles (trajectory level).
    pub holdout: Vec<f64>,
    /// Mean square residual over the held-out samples.
    pub holdout_mse: f64,
}

/// How a level says its residuals: the quantity and the unit of the verdicts.
pub(super) struct Said {
    /// What the held-out residual is called (`held-out RMS`, `held-out x RMS`).
    pub quantity: &'static str,
    /// Its unit in words (`N`, `mm`).
    pub unit: &'static str,
    /// The factor from the residual's SI value to `unit`.
    pub scale: f64,
    /// The paired test of the level's held-out units (samples or cycles): the z of the gain
    /// of the second over the first.
    pub gain_z: fn(&[f64], &[f64]) -> f64,
}

/// Force level: held-out RMS in N.
pub(super) const FORCE: Said = Said {
    quantity: "held-out RMS",
    unit: "N",
    scale: 1.0,
    gain_z: acceptance::paired_z,
};

/// Trajectory level: held-out x RMS in mm.
pub(super) const DISPLACEMENT: Said = Said {
    quantity: "held-out x RMS",
    unit: "mm",
    scale: 1e3,
    gain_z: super::trajectory::cycle_gain_z,
};

/// How `trial` (a model with the candidate `name`, whose own parameters are its `n_own`
/// before the offset) scores against `current`; `gain_z` is the level's paired test of
/// `trial.holdout` against `current.holdout`, `base_excess` the base's held-out mean square
/// above the noise floor.
pub(super) fn score(
    name: &str,
    n_own: usize,
    trial: &Trial,
    current: &Trial,
    gain_z: fn(&[f64], &[f64]) -> f64,
    base_excess: f64,
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
    let mut score = CandidateScore {
        name: name.to_string(),
        holdout_rms: h,
        train_rms: trial.train.rms,
        aic: trial.train.aic,
        bic: trial.train.bic,
        delta_aic: trial.train.aic - current.train.aic,
        delta_bic: trial.train.bic - current.train.bic,
        holdout_gain: current.holdout_mse.sqrt() - h,
        gain_z: gain_z(&current.holdout, &trial.holdout),
        explained_fraction: (current.holdout_mse - trial.holdout_mse) / base_excess,
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
    gain_z: fn(&[f64], &[f64]) -> f64,
    base_excess: f64,
    settings: &DiscoverySettings,
) -> (CandidateScore, Option<Trial>) {
    match trial {
        Ok(trial) => (
            score(name, n_own, &trial, current, gain_z, base_excess, settings),
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
        params: Vec::new(),
        significant: false,
        failure: Some(why),
        evaluations: 0,
        wall_seconds: 0.0,
    }
}

/// The step that adds one of the candidates `scored` (each with its trial when its fit ran)
/// to `current`: the candidates best held-out RMS first, the one accepted by
/// [`acceptance::choose`] (and its ties) or none, and the verdict said as `said`. Returns the
/// step and the accepted candidate's trial (`None` when nothing is accepted).
pub(super) fn decide(
    current: &Trial,
    mut scored: Vec<(CandidateScore, Option<Trial>)>,
    said: &Said,
    settings: &DiscoverySettings,
) -> (Step, Option<Trial>) {
    let current_h = current.holdout_mse.sqrt();
    scored.sort_by(|a, b| a.0.holdout_rms.total_cmp(&b.0.holdout_rms));
    let scores: Vec<CandidateScore> = scored.iter().map(|s| s.0.clone()).collect();
    let holdout: Vec<&[f64]> = scored
        .iter()
        .map(|s| s.1.as_ref().map_or(&[][..], |t| t.holdout.as_slice()))
        .collect();
    let choice = acceptance::choose(&scores, &holdout, said.gain_z, settings);
    let mut step = Step {
        current: current.stage.name(),
        current_holdout_rms: current_h,
        candidates: scores,
        accepted: None,
        tie_with: Vec::new(),
        verdict: String::new(),
    };
    let Some((winner, ties)) = choice else {
        step.verdict = format!(
            "no candidate lowers the {} ({:.4} {}) with a paired z above {} and a BIC drop \
             above {}: nothing is missing that the data demand",
            said.quantity,
            current_h * said.scale,
            said.unit,
            settings.min_gain_sigma,
            settings.min_bic_drop
        );
        return (step, None);
    };
    let tie_names: Vec<String> = ties
        .iter()
        .map(|&i| step.candidates[i].name.clone())
        .collect();
    let w = &step.candidates[winner];
    let params: Vec<String> = w
        .params
        .iter()
        .map(|p| format!("{} = {:.4e} ± {:.1e}", p.name, p.value, p.std_error))
        .collect();
    step.verdict = format!(
        "add `{}`: {} {:.4} → {:.4} {} (paired z {:.1}), ΔBIC {:.1}, explains {:.0} % of the \
         base's held-out gap; {}",
        w.name,
        said.quantity,
        current_h * said.scale,
        w.holdout_rms * said.scale,
        said.unit,
        w.gain_z,
        w.delta_bic,
        100.0 * w.explained_fraction,
        params.join(", ")
    );
    if !tie_names.is_empty() {
        step.verdict.push_str(&format!(
            "; `{}` explain the data equally well (the best is not better by the held-out \
             test), `{}` is chosen as the simplest (fewest parameters, then lowest BIC)",
            tie_names.join("`, `"),
            w.name
        ));
    }
    let w_name = w.name.clone();
    step.accepted = Some(w_name.clone());
    step.tie_with = tie_names;
    let trial = scored
        .iter()
        .position(|s| s.0.name == w_name)
        .and_then(|pos| scored.swap_remove(pos).1);
    (step, trial)
}

/// When nothing was accepted although the current model's held-out RMS stands above 1.2× the
/// noise `floor`: a warning that the verdict "nothing is missing" is not to be trusted, with
/// the candidate that came closest (the lowest held-out RMS below the current one), its z and
/// the share of the excess it explains; `units` says what the paired test counted (`15
/// held-out cycles`). An effect that acts in a few cycles only (a yield
/// force near the breakaway) can explain the whole excess and still fall short of the paired
/// test on few held-out cycles; a longer record, or one that dwells where the effect acts,
/// tells.
pub(super) fn unresolved(step: &Step, units: &str, floor: f64, said: &Said) -> Option<String> {
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
             its paired z is {:.1} on {units} — a longer record, or one that \
             dwells where the gap is, would tell",
            c.name,
            c.holdout_rms * said.scale,
            said.unit,
            100.0 * (step.current_holdout_rms.powi(2) - c.holdout_rms.powi(2)) / excess,
            c.gain_z
        ),
        None => format!("{lead} that no candidate of the vocabulary explains"),
    })
}
