//! The joint fit of a campaign's `[global]` section: each record read and fitted alone with
//! the global model at the global fit's level ([`records`]: the per-record alternative, as
//! `fit` would fit it), then all training records fitted jointly ([`fit`]), and the two
//! compared ([`GlobalJson`], written to `DIR/global.json`; RMS values in N at force level,
//! at trajectory level in mm, or mV for records whose x is in volts, `rms_unit`; parameters'
//! units in the records' own units, as `params.csv` gives them):
//!
//! - over the training records: total RSS, parameters, AIC and BIC of each (the per-record
//!   side sums the records' RSS, samples and free parameters; both use
//!   `N·ln(RSS/N) + 2p` and `N·ln(RSS/N) + p·ln N`, as every fit does);
//! - on the held-out record: the RMS of the force (or displacement) predicted by the global
//!   fit (laws evaluated at its condition, shared values, per-record parameters at their mean
//!   over the training records) against the per-record alternative: the mean of the
//!   per-record parameter values of the training records nearest the held-out record in the
//!   laws' conditions (all of them when there is no law). At trajectory level both simulate
//!   the held-out record's own oscillator from its own initial state as estimated from the
//!   record (never fitted to it).
//!
//! "Sharing supported" needs the global fit's BIC lower and its held-out RMS at most the
//! alternative's; the caveats say when not to trust the verdict.

use std::path::Path;

use anyhow::{bail, Context, Result};
use indexmap::IndexMap;
use rayon::prelude::*;
use serde::Serialize;
use stf_core::fit::{FitResult, INITIAL_STATE};

use crate::experiment::{Experiment, FitLevel};
use crate::param_units::in_record_units;
use crate::shown_units::ShownUnits;

pub mod fit;
pub mod prediction_cache;
pub mod records;
pub mod spec;

use fit::{self as global_fit, JointRecord, Source};
use records::{self as global_records, load_one, rebound, union_scales, Loaded};
use spec::GlobalSpec;

/// One record of a joint fit: a campaign unit as the joint fit sees it.
#[derive(Clone, Debug)]
pub struct Unit {
    /// 1-based number of the unit.
    pub number: usize,
    /// The record as written in the campaign file.
    pub record_given: String,
    /// The record, resolved.
    pub record: std::path::PathBuf,
    /// The unit's experiment, resolved: its `[data]` layout reads the record.
    pub experiment: std::path::PathBuf,
    /// Each condition's value, in the campaign's order.
    pub conditions: Vec<(String, f64)>,
}

/// What a joint fit runs on: the campaign file (for messages), its units, each condition's
/// unit (for the JSON) and its `[global]` section.
pub struct JointInputs<'a> {
    /// The campaign file.
    pub path: &'a Path,
    /// The records, in the campaign's order.
    pub units: Vec<Unit>,
    /// Each condition's unit, where the campaign gives one.
    pub condition_units: std::collections::BTreeMap<String, String>,
    /// The `[global]` section.
    pub global: Option<&'a GlobalSpec>,
}

/// A parameter of the global fit.
#[derive(Clone, Debug, Serialize)]
pub struct GlobalParam {
    /// `n`, `K0`, `K_p`, `f_off@3` (unit 3's own).
    pub name: String,
    /// `shared`, `law coefficient`, `law exponent` or `per record`.
    pub role: String,
    /// Best value.
    pub value: f64,
    /// Block-robust standard error (as every fit's).
    pub std_error: f64,
    /// Its unit on the records (the model's parameter's, a law coefficient's as in `laws`;
    /// empty for a plain number such as an exponent).
    pub unit: String,
}

/// A fitted law: `param = coefficient·(condition/reference)^exponent`, or with a form
/// (`law`) the form's `coefficients`.
#[derive(Clone, Debug, Serialize)]
pub struct LawJson {
    /// The model's parameter.
    pub param: String,
    /// The condition.
    pub condition: String,
    /// The condition's reference value.
    pub reference: f64,
    /// The parameter's SI unit, from its model's `ParamSpec` (empty: dimensionless).
    pub unit: String,
    /// The condition's unit, where `campaign.units` gives one.
    pub condition_unit: Option<String>,
    /// The parameter at the reference (the power law without offset; absent for a law with a
    /// form).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coefficient: Option<f64>,
    /// Standard error of the coefficient.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coefficient_std_error: Option<f64>,
    /// The exponent (the power law without offset).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exponent: Option<f64>,
    /// Standard error of the exponent.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exponent_std_error: Option<f64>,
    /// The law's form (`linear`, `affine`, `power`: with `coefficients`), absent for the power
    /// law without offset.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub law: Option<String>,
    /// A law with a form: its coefficients (`P_base`, `P_gain`, `P_exp`) with their errors.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coefficients: Option<Vec<LawCoefficient>>,
    /// The parameter's lower bound, which the law's value is clamped to (absent where
    /// unbounded), as in the fit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    /// Its upper bound, likewise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
}

/// A coefficient of a law with a form.
#[derive(Clone, Debug, Serialize)]
pub struct LawCoefficient {
    /// `F_y_base`, `F_y_gain`, `F_y_exp`.
    pub name: String,
    /// Best value.
    pub value: f64,
    /// Block-robust standard error.
    pub std_error: f64,
    /// Its SI unit: the parameter's (base), the parameter's per unit of x (gain), none
    /// (exponent).
    pub unit: String,
}

/// Fit statistics of one side of the comparison, over the training records.
#[derive(Clone, Debug, Serialize)]
pub struct Criteria {
    /// Residual sum of squares, SI: N² (force level) or m² (trajectory level).
    pub rss: f64,
    /// Samples.
    pub n_points: usize,
    /// Free parameters.
    pub n_params: usize,
    /// RMS residual, in `rms_unit` (N, or mm or mV).
    pub rms: f64,
    /// N·ln(RSS/N) + 2p.
    pub aic: f64,
    /// N·ln(RSS/N) + p·ln N.
    pub bic: f64,
    /// Whether every fit behind it converged.
    pub converged: bool,
}

impl Criteria {
    /// The criteria of a fit with residual sum of squares `rss` (SI) over `n_points`
    /// samples and `n_params` free parameters; its RMS shown ×`shown` (1 in N, 1e3 in mm).
    fn of(rss: f64, n_points: usize, n_params: usize, converged: bool, shown: f64) -> Criteria {
        let n = n_points as f64;
        let p = n_params as f64;
        let base = n * (rss / n).ln();
        Criteria {
            rss,
            n_points,
            n_params,
            rms: shown * (rss / n).sqrt(),
            aic: base + 2.0 * p,
            bic: base + p * n.ln(),
            converged,
        }
    }
}

/// One record's own fit of the global model.
#[derive(Clone, Debug, Serialize)]
pub struct PerRecord {
    /// Unit number.
    pub unit: usize,
    /// The record as written.
    pub record: String,
    /// Its conditions.
    pub conditions: IndexMap<String, f64>,
    /// Parameter values and standard errors, by name (force level: the model's, then
    /// `f_off`; trajectory level: the fit's free parameters).
    pub params: IndexMap<String, (f64, f64)>,
    /// RMS residual, in `rms_unit`.
    pub rms: f64,
    /// Whether it was the held-out record (not in either side's totals).
    pub held_out: bool,
}

/// The held-out record's RMS predicted both ways, in `rms_unit`.
#[derive(Clone, Debug, Serialize)]
pub struct HoldoutJson {
    /// The record as written.
    pub record: String,
    /// RMS of the global fit's prediction.
    pub global_rms: f64,
    /// RMS of the per-record alternative's prediction.
    pub per_record_rms: f64,
    /// The records whose own parameters were averaged for the alternative.
    pub per_record_from: Vec<String>,
    /// RMS of the record's own fit (the best either could do).
    pub own_fit_rms: f64,
}

/// `global.json`.
#[derive(Clone, Debug, Serialize)]
pub struct GlobalJson {
    /// The model as written in `[global]`.
    pub model: String,
    /// `force` or `trajectory`: what the fits aim at.
    pub level: String,
    /// A condition's unit, where `campaign.units` gives one.
    pub condition_units: std::collections::BTreeMap<String, String>,
    /// The unit of every RMS: `N` (force level) or `mm` (trajectory level; `mV` for records
    /// whose x is in volts).
    pub rms_unit: String,
    /// Parameters shared by every record.
    pub shared: Vec<String>,
    /// The records fitted (as written).
    pub records: Vec<String>,
    /// θ: every parameter of the joint fit.
    pub params: Vec<GlobalParam>,
    /// The fitted laws.
    pub laws: Vec<LawJson>,
    /// The joint fit.
    pub global: Criteria,
    /// The per-record fits, taken together.
    pub per_record: Criteria,
    /// Global BIC − per-record BIC (negative: the global fit is preferred).
    pub delta_bic: f64,
    /// The held-out record, if any.
    pub holdout: Option<HoldoutJson>,
    /// Whether sharing is supported (BIC lower and held-out RMS no worse).
    pub supported: bool,
    /// The verdict in words.
    pub verdict: String,
    /// When not to trust the verdict.
    pub caveats: Vec<String>,
    /// Each record's own fit.
    pub each_record: Vec<PerRecord>,
    /// The joint fit's convergence and log.
    pub log: Vec<String>,
    /// Wall time of the whole global step (reading, per-record and joint fits), s.
    pub wall_seconds: f64,
    /// Wall time of the joint fit alone, s.
    pub joint_fit_seconds: f64,
    /// Evaluations of the joint residuals (each a prediction of every training record,
    /// those cached apart: a Jacobian column of a per-record parameter predicts one record).
    pub joint_fit_evaluations: u64,
}

/// Run the joint fit of `campaign` (which must have a `[global]` section).
pub fn run(campaign: &JointInputs) -> Result<GlobalJson> {
    let started = std::time::Instant::now();
    let mut json = joint_fit(campaign)?;
    json.wall_seconds = started.elapsed().as_secs_f64();
    Ok(json)
}

/// [`run`] without its timing.
fn joint_fit(campaign: &JointInputs) -> Result<GlobalJson> {
    let Some(spec) = campaign.global else {
        bail!("{}: no [global] section", campaign.path.display());
    };
    let gexp = Experiment::load(&spec.experiment)?;
    let at = |u: &Unit| format!("{}: record {}", campaign.path.display(), u.record_given);
    let mut loaded: Vec<Loaded> = campaign
        .units
        .par_iter()
        .map(|u| load_one(spec, &gexp, u).with_context(|| at(u)))
        .collect::<Result<_>>()?;
    same_units(campaign, &loaded)?;
    let is_training = |i: usize| Some(i) != spec.holdout;
    let scales = union_scales(
        loaded
            .iter()
            .enumerate()
            .filter(|(i, _)| is_training(*i))
            .map(|(_, l)| &l.joint),
    );
    let configured = global_records::configure(spec, &gexp, &scales)?;
    for l in &mut loaded {
        rebound(&mut l.joint, &configured);
    }
    let training: Vec<&Loaded> = loaded
        .iter()
        .enumerate()
        .filter(|(i, _)| is_training(*i))
        .map(|(_, l)| l)
        .collect();
    let records: Vec<(usize, &JointRecord)> =
        training.iter().map(|l| (l.unit.number, &l.joint)).collect();
    let starts: Vec<Vec<f64>> = training.iter().map(|l| l.own.values.clone()).collect();
    let layout = global_fit::layout(&spec.shared, &spec.laws, &records, &starts);
    let joint: Vec<&JointRecord> = training.iter().map(|l| &l.joint).collect();
    let settings = match spec.level {
        FitLevel::Trajectory => gexp
            .fit
            .settings
            .clone()
            .for_simulation(gexp.integrator.rtol),
        FitLevel::Force => gexp.fit.settings.clone(),
    };
    let result = global_fit::fit(&layout, &joint, &settings, spec.level)?;
    let units = Units {
        model: configured.model.clone(),
        conditions: campaign.condition_units.clone(),
        record: loaded.first().map_or_else(ShownUnits::default, |l| l.units),
    };
    let shown = units.record.at_level(spec.level).1;
    let holdout = spec
        .holdout
        .map(|h| holdout_json(spec, &loaded[h], &training, &layout, &result, shown))
        .transpose()?;
    Ok(assemble(
        spec, &units, &loaded, &training, &layout, result, holdout,
    ))
}

/// Every record of a joint fit in the same units: one law's coefficients cannot be read in
/// metres for one record and in volts for another (the joint fit would take the first
/// record's units for all and report a mixture as one number).
fn same_units(campaign: &JointInputs, loaded: &[Loaded]) -> Result<()> {
    let Some(first) = loaded.first() else {
        return Ok(());
    };
    let units = |l: &Loaded| (l.units.x_si, l.units.force_si);
    match loaded.iter().find(|l| units(l) != units(first)) {
        None => Ok(()),
        Some(other) => bail!(
            "{}: `[global]` fits one law over every record, but record {} is in {} and {} \
             while record {} is in {} and {} (x and force); read them in the same units \
             (`[data] units` in their experiments)",
            campaign.path.display(),
            first.unit.record_given,
            first.units.x_si,
            first.units.force_si,
            other.unit.record_given,
            other.units.x_si,
            other.units.force_si,
        ),
    }
}

/// The held-out record predicted by the global fit and by the per-record alternative, RMS
/// values times `shown` (from the record's values to the shown ones).
fn holdout_json(
    spec: &GlobalSpec,
    held: &Loaded,
    training: &[&Loaded],
    layout: &global_fit::Layout,
    result: &FitResult,
    shown: f64,
) -> Result<HoldoutJson> {
    let theta: Vec<f64> = result.params.iter().map(|p| p.value).collect();
    let columns = layout.sources.first().map_or(0, Vec::len);
    let global_values: Vec<f64> = (0..columns)
        .map(|k| match &layout.sources[0][k] {
            Source::Law {
                coefficient,
                exponent,
                law,
                bounds,
                ..
            } => {
                let law = &spec.laws[*law];
                let ratio = held.joint.condition(&law.condition) / law.reference;
                global_fit::power_value(theta[*coefficient], theta[*exponent], ratio, *bounds)
            }
            Source::Form {
                form,
                first,
                law,
                bounds,
                ..
            } => {
                let x = spec.laws[*law].ratio(held.joint.condition(&spec.laws[*law].condition));
                global_fit::form_value(*form, &theta, *first, x, *bounds)
            }
            _ => own_state(held, k)
                .unwrap_or_else(|| mean(layout.sources.iter().map(|s| s[k].value(&theta)))),
        })
        .collect();
    let nearest = nearest_records(spec, held, training);
    let alternative: Vec<f64> = (0..held.own.values.len())
        .map(|k| {
            own_state(held, k).unwrap_or_else(|| mean(nearest.iter().map(|l| l.own.values[k])))
        })
        .collect();
    Ok(HoldoutJson {
        record: held.unit.record_given.clone(),
        global_rms: shown * global_fit::rms_of(&held.joint, &global_values)?,
        per_record_rms: shown * global_fit::rms_of(&held.joint, &alternative)?,
        per_record_from: nearest
            .iter()
            .map(|l| l.unit.record_given.clone())
            .collect(),
        own_fit_rms: shown * held.own.result.rms,
    })
}

/// The held-out record's own estimate of its `k`-th parameter if it is its initial state
/// (`x0`, `v0`: the start its own fit takes, from the record, never fitted to it): another
/// record's initial state says nothing about this one's.
fn own_state(held: &Loaded, k: usize) -> Option<f64> {
    let p = held.joint.params.get(k)?;
    INITIAL_STATE.contains(&p.name.as_str()).then_some(p.value)
}

/// The mean of `values`.
fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    sum / n.max(1) as f64
}

/// The training records nearest `held` in the laws' conditions (distance: the sum of
/// |Δc|/reference; ties within 1e-9 all kept); all of them without a law.
fn nearest_records<'a, 'c>(
    spec: &GlobalSpec,
    held: &Loaded,
    training: &'a [&'a Loaded<'c>],
) -> Vec<&'a Loaded<'c>> {
    let distance = |l: &Loaded| -> f64 {
        spec.laws
            .iter()
            .map(|law| {
                (l.joint.condition(&law.condition) - held.joint.condition(&law.condition)).abs()
                    / law.reference
            })
            .sum()
    };
    let best = training
        .iter()
        .map(|l| distance(l))
        .fold(f64::INFINITY, f64::min);
    training
        .iter()
        .filter(|l| distance(l) <= best + 1e-9)
        .copied()
        .collect()
}

/// Put the pieces into `global.json`'s shape, with the verdict and its caveats.
fn assemble(
    spec: &GlobalSpec,
    units: &Units,
    loaded: &[Loaded],
    training: &[&Loaded],
    layout: &global_fit::Layout,
    result: FitResult,
    holdout: Option<HoldoutJson>,
) -> GlobalJson {
    let shown = units.record.at_level(spec.level);
    let global = Criteria::of(
        result.rss,
        result.n_points,
        result.n_free,
        result.convergence.converged(),
        shown.1,
    );
    let per_record = per_record_criteria(training, shown.1);
    let delta_bic = global.bic - per_record.bic;
    let better_held = holdout
        .as_ref()
        .is_none_or(|h| h.global_rms <= h.per_record_rms);
    let supported = delta_bic < 0.0 && better_held;
    let verdict = verdict_text(supported, delta_bic, holdout.as_ref(), spec.level, shown.0);
    let caveats = all_caveats(spec, training, &global, &per_record, holdout.as_ref());
    let laws = laws_json(spec, &result, units, layout);
    GlobalJson {
        model: spec.model.clone(),
        level: spec.level.name().into(),
        condition_units: units.conditions.clone(),
        rms_unit: shown.0.into(),
        shared: spec.shared.clone(),
        records: training
            .iter()
            .map(|l| l.unit.record_given.clone())
            .collect(),
        params: theta_json(&result, layout, units, &laws),
        laws,
        global,
        per_record,
        delta_bic,
        holdout,
        supported,
        verdict,
        caveats,
        each_record: loaded
            .iter()
            .enumerate()
            .map(|(i, l)| per_record_json(l, spec.holdout == Some(i), shown.1))
            .collect(),
        joint_fit_seconds: result.wall_seconds,
        joint_fit_evaluations: result.evaluations,
        log: result.log,
        wall_seconds: 0.0,
    }
}

/// Where the laws' units come from.
struct Units {
    /// The global model (its parameters' `ParamSpec`s).
    model: std::sync::Arc<dyn stf_core::physics::force_model::ForceModel>,
    /// `campaign.units`.
    conditions: std::collections::BTreeMap<String, String>,
    /// The records' units (the first record's).
    record: ShownUnits,
}

impl Units {
    /// The unit of the model's parameter `name` on the records (empty if it has none or is
    /// not the model's).
    fn param(&self, name: &str) -> String {
        self.model
            .params()
            .iter()
            .find(|s| s.name == name)
            .map_or_else(String::new, |s| in_record_units(&s.unit, &self.record))
    }
}

/// θ with its roles and standard errors.
fn theta_json(
    result: &FitResult,
    layout: &global_fit::Layout,
    units: &Units,
    laws: &[LawJson],
) -> Vec<GlobalParam> {
    result
        .params
        .iter()
        .zip(&layout.roles)
        .map(|(p, role)| GlobalParam {
            name: p.name.clone(),
            role: role.to_string(),
            value: p.value,
            std_error: p.std_error,
            unit: theta_unit(&p.name, role, units, laws),
        })
        .collect()
}

/// The unit of θ's entry `name` in `role`: a law's coefficient as `laws` give it, an
/// exponent none, a shared or per-record parameter (`K@3`) its model parameter's, a force
/// offset the records' force.
fn theta_unit(name: &str, role: &str, units: &Units, laws: &[LawJson]) -> String {
    match role {
        "law exponent" => String::new(),
        "law coefficient" => laws
            .iter()
            .find_map(|l| {
                let plain = global_fit::coefficient_name(&l.param) == name;
                let form = l.coefficients.iter().flatten().find(|c| c.name == name);
                form.map(|c| c.unit.clone())
                    .or_else(|| plain.then(|| l.unit.clone()))
            })
            .unwrap_or_default(),
        _ => {
            let base = name.split('@').next().unwrap_or(name);
            if base == stf_core::fit::FORCE_OFFSET {
                in_record_units("N", &units.record)
            } else {
                units.param(base)
            }
        }
    }
}

/// Each law's coefficients with their errors.
fn laws_json(
    spec: &GlobalSpec,
    result: &FitResult,
    units: &Units,
    layout: &global_fit::Layout,
) -> Vec<LawJson> {
    spec.laws
        .iter()
        .enumerate()
        .filter_map(|(index, l)| {
            let unit = units.param(&l.param);
            let mut json = LawJson {
                param: l.param.clone(),
                condition: l.condition.clone(),
                reference: l.reference,
                condition_unit: units.conditions.get(&l.condition).cloned(),
                coefficient: None,
                coefficient_std_error: None,
                exponent: None,
                exponent_std_error: None,
                law: None,
                coefficients: None,
                min: None,
                max: None,
                unit: unit.clone(),
            };
            if let Some((lo, hi)) = layout.law_bounds(index) {
                json.min = lo.is_finite().then_some(lo);
                json.max = hi.is_finite().then_some(hi);
            }
            let Some(form) = l.form else {
                let c = result.param(&global_fit::coefficient_name(&l.param))?;
                let e = result.param(&global_fit::exponent_name(&l.param))?;
                json.coefficient = Some(c.value);
                json.coefficient_std_error = Some(c.std_error);
                json.exponent = Some(e.value);
                json.exponent_std_error = Some(e.std_error);
                return Some(json);
            };
            let x_unit = match (&json.condition_unit, l.reference == 1.0) {
                (Some(u), true) => u.clone(),
                _ => String::new(),
            };
            let coefficients = form
                .coefficients()
                .iter()
                .zip(global_fit::form_names(form, &l.param))
                .map(|(suffix, name)| {
                    let p = result.param(&name)?;
                    let unit = match *suffix {
                        "base" => unit.clone(),
                        "gain" if x_unit.is_empty() => unit.clone(),
                        "gain" => format!("{unit}/{x_unit}"),
                        _ => String::new(),
                    };
                    Some(LawCoefficient {
                        value: p.value,
                        std_error: p.std_error,
                        name,
                        unit,
                    })
                })
                .collect::<Option<Vec<_>>>()?;
            json.law = Some(form.name().to_string());
            json.coefficients = Some(coefficients);
            Some(json)
        })
        .collect()
}

/// The per-record fits of the training records taken together: their RSS, samples and free
/// parameters summed.
fn per_record_criteria(training: &[&Loaded], shown: f64) -> Criteria {
    Criteria::of(
        training.iter().map(|l| l.own.result.rss).sum(),
        training.iter().map(|l| l.own.result.n_points).sum(),
        training.iter().map(|l| l.own.result.n_free).sum(),
        training
            .iter()
            .all(|l| l.own.result.convergence.converged()),
        shown,
    )
}

/// [`caveats`], and a held-out record that cannot tell the fits apart.
fn all_caveats(
    spec: &GlobalSpec,
    training: &[&Loaded],
    global: &Criteria,
    per_record: &Criteria,
    holdout: Option<&HoldoutJson>,
) -> Vec<String> {
    let mut out = caveats(spec, training, global, per_record, holdout.is_some());
    if holdout.is_some_and(HoldoutJson::is_tie) {
        out.push(format!(
            "the held-out record does not tell the two fits apart (their RMS differ by under \
             {:.0} %): hold out a record at a level of the law's condition that no other record \
             shares to test what the law predicts",
            TIE * 100.0
        ));
    }
    out
}

/// Held-out RMS values closer than this (relative) are a tie: the record cannot tell the
/// two fits apart.
const TIE: f64 = 0.01;

impl HoldoutJson {
    /// Whether the two fits predict the held-out record equally well, within [`TIE`].
    fn is_tie(&self) -> bool {
        (self.global_rms - self.per_record_rms).abs() <= TIE * self.per_record_rms
    }
}

/// The verdict in a sentence, RMS values in `unit`.
fn verdict_text(
    supported: bool,
    delta_bic: f64,
    holdout: Option<&HoldoutJson>,
    level: FitLevel,
    unit: &str,
) -> String {
    let (signal, digits) = match level {
        FitLevel::Force => ("force", 5),
        FitLevel::Trajectory => ("displacement", 4),
    };
    let bic = if delta_bic < 0.0 {
        format!("the global fit's BIC is lower by {:.1}", -delta_bic)
    } else {
        format!("the per-record fits' BIC is lower by {delta_bic:.1}")
    };
    let held = holdout.map_or_else(
        || "no record was held out".to_string(),
        |h| {
            let tie = if h.is_tie() {
                format!(" (a tie: within {:.0} %)", TIE * 100.0)
            } else {
                String::new()
            };
            format!(
                "on the held-out record {} the global fit predicts the {signal} with RMS \
                 {:.digits$} {unit} against {:.digits$} {unit} for the per-record \
                 alternative{tie}",
                h.record, h.global_rms, h.per_record_rms
            )
        },
    );
    let head = if supported {
        "sharing supported"
    } else {
        "sharing not supported"
    };
    format!("{head}: {bic}; {held}.")
}

/// When not to trust the verdict.
fn caveats(
    spec: &GlobalSpec,
    training: &[&Loaded],
    global: &Criteria,
    per_record: &Criteria,
    held_out: bool,
) -> Vec<String> {
    let mut out = Vec::new();
    for law in &spec.laws {
        let mut levels: Vec<f64> = training
            .iter()
            .map(|l| l.joint.condition(&law.condition))
            .collect();
        levels.sort_by(f64::total_cmp);
        levels.dedup();
        if levels.len() < 3 {
            out.push(format!(
                "the law of {} has {} level(s) of {} to fit: fewer than 3 cannot test its shape",
                law.param,
                levels.len(),
                law.condition
            ));
        }
    }
    if training.len() < 3 {
        out.push(format!(
            "only {} records are fitted: too few to judge sharing",
            training.len()
        ));
    }
    if !global.converged {
        out.push("the global fit did not converge".into());
    }
    if !per_record.converged {
        out.push("some per-record fit did not converge".into());
    }
    if !held_out {
        out.push("no record is held out: the verdict rests on the BIC alone".into());
    }
    out
}

/// A record's own fit, for the JSON and the figure.
fn per_record_json(l: &Loaded, held_out: bool, shown: f64) -> PerRecord {
    PerRecord {
        unit: l.unit.number,
        record: l.unit.record_given.clone(),
        conditions: l.unit.conditions.iter().cloned().collect(),
        params: l
            .own
            .result
            .params
            .iter()
            .map(|p| (p.name.clone(), (p.value, p.std_error)))
            .collect(),
        rms: shown * l.own.result.rms,
        held_out,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn holdout(global_rms: f64, per_record_rms: f64) -> HoldoutJson {
        HoldoutJson {
            record: "r.csv".into(),
            global_rms,
            per_record_rms,
            per_record_from: Vec::new(),
            own_fit_rms: global_rms,
        }
    }

    #[test]
    fn a_held_out_record_that_cannot_tell_the_fits_apart_is_called_a_tie() {
        assert!(holdout(0.019757, 0.019767).is_tie());
        assert!(!holdout(0.02038, 0.04556).is_tie());
        let said = verdict_text(
            true,
            -117.6,
            Some(&holdout(0.019757, 0.019767)),
            FitLevel::Force,
            "N",
        );
        assert!(said.contains("(a tie: within 1 %)"), "{said}");
        let said = verdict_text(
            true,
            -137.7,
            Some(&holdout(0.02038, 0.04556)),
            FitLevel::Force,
            "N",
        );
        assert!(!said.contains("tie"), "{said}");
    }
}
