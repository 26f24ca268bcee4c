//! What the campaign table takes from a unit's results: the parts of `fit.json`,
//! `compare.json` and `discovery.json` it needs, deserialized (unknown keys ignored; the keys
//! are the contracts of `crate::outputs`, docs/ARCHITECTURE.md §6), turned into one
//! [`ModelResult`] per fitted model; of a `fit` unit also `params.csv`'s `unit` column (each
//! parameter's unit, from its model's `ParamSpec` or the oscillator's), for the figures' axes.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result};
use serde::de::DeserializeOwned;
use serde::Deserialize;

use super::file::CommandName;

/// One model of `fit.json` (and of each `compare.json` model's `fit`).
#[derive(Debug, Deserialize)]
struct ModelFit {
    label: String,
    params: BTreeMap<String, f64>,
    #[serde(default)]
    std_errors: BTreeMap<String, Option<f64>>,
    #[serde(default)]
    fixed: Vec<String>,
    rms: f64,
    rms_unit: String,
    #[serde(default)]
    param_units: BTreeMap<String, String>,
    aic: Option<f64>,
    bic: Option<f64>,
    n_free: usize,
    converged: bool,
    #[serde(default)]
    warnings: Vec<Warning>,
    validation_rms: Option<f64>,
}

/// A fit's warning: its kind is enough for the table.
#[derive(Debug, Deserialize)]
struct Warning {
    kind: String,
}

/// `fit.json`.
#[derive(Debug, Deserialize)]
struct FitFile {
    models: Vec<ModelFit>,
}

/// `compare.json`.
#[derive(Debug, Deserialize)]
struct CompareFile {
    models: Vec<CompareModel>,
    best: CompareBest,
}

#[derive(Debug, Deserialize)]
struct CompareModel {
    fit: ModelFit,
}

#[derive(Debug, Deserialize)]
struct CompareBest {
    overall: Option<String>,
}

/// `discovery.json`.
#[derive(Debug, Deserialize)]
struct DiscoveryFile {
    effects: Vec<String>,
    gap_before: f64,
    gap_after: f64,
    gap_unit: String,
    final_model: FinalModel,
}

#[derive(Debug, Deserialize)]
struct FinalModel {
    name: String,
    params: BTreeMap<String, f64>,
    #[serde(default)]
    std_errors: BTreeMap<String, Option<f64>>,
}

/// One fitted parameter: value and standard error (SI units).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ParamValue {
    /// The fitted (or held) value.
    pub value: f64,
    /// Its block-robust standard error; null where not determined or held.
    pub std_error: Option<f64>,
    /// Its unit as `params.csv` gives it (SI, lengths and forces in the record's own units;
    /// empty: dimensionless); null where unknown (`compare`, `discover`).
    pub unit: Option<String>,
}

/// A model's results in one unit, what a row of the table shows (all empty for a failed
/// unit's row).
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct ModelResult {
    /// The model's label (or the discovered model's name); null for a failed unit.
    pub model: Option<String>,
    /// The model's parameters.
    pub params: BTreeMap<String, ParamValue>,
    /// RMS residual (`fit`, `compare`) or held-out gap after discovery.
    pub rms: Option<f64>,
    /// Unit of `rms`.
    pub rms_unit: Option<String>,
    /// AIC, BIC.
    pub aic: Option<f64>,
    /// BIC.
    pub bic: Option<f64>,
    /// Whether the fit converged.
    pub converged: Option<bool>,
    /// The verdict: the best model of the unit (by AIC for `fit`, overall for `compare`).
    pub best: Option<bool>,
    /// The kinds of the fit's warnings.
    pub warnings: Vec<String>,
    /// Error on the `[validate]` record.
    pub validation_rms: Option<f64>,
    /// Effects named (`discover`).
    pub effects: Option<Vec<String>>,
    /// The base's held-out gap (`discover`).
    pub gap_before: Option<f64>,
}

/// The file of `command`'s results in a unit's folder, which the campaign table reads.
pub fn results_file(command: CommandName) -> &'static str {
    match command {
        CommandName::Fit => "fit.json",
        CommandName::Compare => "compare.json",
        CommandName::Discover => "discovery.json",
    }
}

/// The results of a unit that ran `command` into `dir`, one per model.
pub fn read(command: CommandName, dir: &Path) -> Result<Vec<ModelResult>> {
    let json = dir.join(results_file(command));
    match command {
        CommandName::Fit => {
            let file: FitFile = read_json(&json)?;
            let units = param_units(&dir.join("params.csv"));
            let mut models = with_best_by_aic(file.models);
            for m in &mut models {
                for (name, p) in &mut m.params {
                    let key = (m.model.clone().unwrap_or_default(), name.clone());
                    if let Some(unit) = units.get(&key) {
                        p.unit = Some(unit.clone());
                    }
                }
            }
            Ok(models)
        }
        CommandName::Compare => {
            let file: CompareFile = read_json(&json)?;
            let best = file.best.overall;
            Ok(file
                .models
                .into_iter()
                .map(|m| {
                    let mut r = of_fit(m.fit);
                    r.best = Some(best.is_some() && best == r.model);
                    r
                })
                .collect())
        }
        CommandName::Discover => {
            let d: DiscoveryFile = read_json(&json)?;
            Ok(vec![ModelResult {
                model: Some(d.final_model.name),
                params: params(&d.final_model.params, &d.final_model.std_errors, &[]),
                rms: Some(d.gap_after),
                rms_unit: Some(d.gap_unit),
                gap_before: Some(d.gap_before),
                effects: Some(d.effects),
                ..ModelResult::default()
            }])
        }
    }
}

/// A row of `params.csv`: the parts the figures need.
#[derive(Debug, Deserialize)]
struct ParamUnitRow {
    model: String,
    parameter: String,
    unit: String,
}

/// Each (model, parameter)'s unit in `params.csv`; none if the file is missing or unreadable
/// (the figures then show names alone).
fn param_units(path: &Path) -> BTreeMap<(String, String), String> {
    let Ok(mut reader) = csv::Reader::from_path(path) else {
        return BTreeMap::new();
    };
    reader
        .deserialize::<ParamUnitRow>()
        .filter_map(Result::ok)
        .map(|r| ((r.model, r.parameter), r.unit))
        .collect()
}

/// A JSON file of a unit, read into the parts the table needs.
fn read_json<T: DeserializeOwned>(path: &Path) -> Result<T> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{}: unexpected contents", path.display()))
}

/// Each fit as a result, the best by AIC marked ([`crate::verdict::best_by_aic`], the rule of
/// the fit's own verdict).
fn with_best_by_aic(models: Vec<ModelFit>) -> Vec<ModelResult> {
    let scored: Vec<(f64, usize)> = models
        .iter()
        .map(|m| (m.aic.unwrap_or(f64::NAN), m.n_free))
        .collect();
    let best = crate::verdict::best_by_aic(&scored);
    models
        .into_iter()
        .enumerate()
        .map(|(i, m)| {
            let mut r = of_fit(m);
            r.best = Some(best == Some(i));
            r
        })
        .collect()
}

fn of_fit(m: ModelFit) -> ModelResult {
    let mut values = params(&m.params, &m.std_errors, &m.fixed);
    for (name, p) in &mut values {
        p.unit = m.param_units.get(name).filter(|u| !u.is_empty()).cloned();
    }
    ModelResult {
        params: values,
        model: Some(m.label),
        rms: Some(m.rms),
        rms_unit: Some(m.rms_unit),
        aic: m.aic,
        bic: m.bic,
        converged: Some(m.converged),
        warnings: m.warnings.into_iter().map(|w| w.kind).collect(),
        validation_rms: m.validation_rms,
        ..ModelResult::default()
    }
}

/// Values with their standard errors; a held parameter has none.
fn params(
    values: &BTreeMap<String, f64>,
    errors: &BTreeMap<String, Option<f64>>,
    fixed: &[String],
) -> BTreeMap<String, ParamValue> {
    values
        .iter()
        .map(|(name, &value)| {
            let std_error = if fixed.contains(name) {
                None
            } else {
                errors.get(name).copied().flatten()
            };
            let unit = None;
            (
                name.clone(),
                ParamValue {
                    value,
                    std_error,
                    unit,
                },
            )
        })
        .collect()
}
