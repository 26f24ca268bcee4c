//! The campaign table: one row per record × model, built from the units' `unit.json` and
//! their command's JSON ([`super::unit_results`]), written as `campaign.json`
//! ([`CampaignJson`]) and `campaign.csv` (the same rows flattened: a column per condition,
//! and a value and a `_std_error` column per parameter name met in any row). A unit that
//! failed, or never wrote its `unit.json`, is a row with its error, not a missing row.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result};
use indexmap::IndexMap;
use serde::Serialize;

use super::csv_columns::{LEADING_COLUMNS, MODEL_COLUMN, STD_ERROR_SUFFIX, TRAILING_COLUMNS};
use super::file::{Campaign, CommandName, Unit};
use super::unit::{read_unit_json, unit_dir, UnitStatus};
use super::unit_results::{self, ModelResult};
use crate::digits::carried;

/// One row: a model fitted to one record (or a failed unit).
#[derive(Clone, Debug, Serialize)]
pub struct CampaignRow {
    /// The unit's number.
    pub unit: usize,
    /// The record, as written in the campaign file.
    pub record: String,
    /// The command the unit ran.
    pub command: CommandName,
    /// The record's conditions, by name, in the campaign's order.
    pub conditions: IndexMap<String, f64>,
    /// `ok` or `failed`.
    pub status: &'static str,
    /// Why the unit failed.
    pub error: Option<String>,
    /// The model's results (empty for a failed unit), flattened into the row.
    #[serde(flatten)]
    pub result: ModelResult,
    /// Wall time of the unit's command, s.
    pub wall_seconds: Option<f64>,
}

/// `campaign.json`.
#[derive(Debug, Serialize)]
pub struct CampaignJson {
    /// The campaign file, as given.
    pub campaign: String,
    /// Condition names.
    pub conditions: Vec<String>,
    /// A condition's unit, where `campaign.units` gives one.
    pub condition_units: BTreeMap<String, String>,
    /// Units in the campaign.
    pub units: usize,
    /// Units that failed.
    pub failed: usize,
    /// The rows.
    pub rows: Vec<CampaignRow>,
    /// Folders under `units/` that no unit of the campaign writes (records removed from the
    /// campaign since an earlier run): listed, never deleted.
    pub stale_units: Vec<String>,
}

/// The table of `campaign` from its output folder `out`; `errors` holds, by unit number, why
/// a unit the runner ran has no results (used when its folder says nothing).
pub fn collect(campaign: &Campaign, out: &Path, errors: &BTreeMap<usize, String>) -> CampaignJson {
    let mut rows = Vec::new();
    let mut failed = 0;
    for unit in &campaign.units {
        let dir = unit_dir(out, unit);
        let json = read_unit_json(&dir);
        let base = CampaignRow {
            unit: unit.number,
            record: unit.record_given.clone(),
            command: unit.command,
            conditions: unit.conditions.iter().cloned().collect(),
            status: "ok",
            error: None,
            result: ModelResult::default(),
            wall_seconds: json.as_ref().map(|u| u.wall_seconds),
        };
        let results = match (&json, errors.get(&unit.number)) {
            (_, Some(e)) => Err(e.clone()),
            (None, None) => Err(format!(
                "no {} in {}",
                super::unit::UNIT_JSON,
                dir.display()
            )),
            (Some(u), None) if u.status == UnitStatus::Failed => {
                Err(u.error.clone().unwrap_or_else(|| "failed".into()))
            }
            (Some(_), None) => unit_results::read(unit.command, &dir).map_err(|e| format!("{e:#}")),
        };
        match results {
            Ok(models) => rows.extend(models.into_iter().map(|result| CampaignRow {
                result,
                ..base.clone()
            })),
            Err(e) => {
                failed += 1;
                rows.push(CampaignRow {
                    status: "failed",
                    error: Some(e),
                    ..base
                });
            }
        }
    }
    CampaignJson {
        campaign: campaign.path.display().to_string(),
        conditions: campaign.conditions.clone(),
        condition_units: campaign.condition_units.clone(),
        units: campaign.units.len(),
        failed,
        rows,
        stale_units: stale_unit_folders(campaign, out),
    }
}

/// The folders under `DIR/units/` that are no unit's of `campaign` (sorted; the program's
/// temporaries aside).
pub fn stale_unit_folders(campaign: &Campaign, out: &Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(out.join(super::unit::UNITS)) else {
        return Vec::new();
    };
    let current: Vec<String> = campaign.units.iter().map(Unit::folder_name).collect();
    let mut stale: Vec<String> = entries
        .filter_map(|e| e.ok())
        .filter(|e| e.file_type().is_ok_and(|t| t.is_dir()))
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !n.starts_with('.') && !current.contains(n))
        .collect();
    stale.sort();
    stale
}

/// Every parameter name of the table, in order of first appearance.
pub fn param_names(rows: &[CampaignRow]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for r in rows {
        for name in r.result.params.keys() {
            if !names.contains(name) {
                names.push(name.clone());
            }
        }
    }
    names
}

/// `campaign.csv`: `unit, record, command, status, <conditions…>, model, <param>,
/// <param>_std_error …, rms, rms_unit, aic, bic, converged, best, warnings, validation_rms,
/// effects, gap_before, wall_seconds, error` (lists joined with `;`).
pub fn write_csv(path: &Path, table: &CampaignJson) -> Result<()> {
    let names = param_names(&table.rows);
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<String> = LEADING_COLUMNS.map(String::from).to_vec();
    header.extend(table.conditions.iter().cloned());
    header.push(MODEL_COLUMN.into());
    for n in &names {
        header.push(n.clone());
        header.push(format!("{n}{STD_ERROR_SUFFIX}"));
    }
    header.extend(TRAILING_COLUMNS.map(String::from));
    w.write_record(&header)?;
    for r in &table.rows {
        w.write_record(csv_row(r, &table.conditions, &names))?;
    }
    let bytes = w.into_inner().context("cannot build campaign.csv")?;
    crate::writing::write_atomic(path, &bytes)?;
    Ok(())
}

/// One row's fields in the order of the header.
fn csv_row(r: &CampaignRow, conditions: &[String], names: &[String]) -> Vec<String> {
    let num = |x: Option<f64>| x.map(|x| carried(x).to_string()).unwrap_or_default();
    let flag = |b: Option<bool>| b.map(|b| b.to_string()).unwrap_or_default();
    let mut f = vec![
        r.unit.to_string(),
        r.record.clone(),
        r.command.name().to_string(),
        r.status.to_string(),
    ];
    f.extend(conditions.iter().map(|c| num(r.conditions.get(c).copied())));
    let m = &r.result;
    f.push(m.model.clone().unwrap_or_default());
    for n in names {
        let p = m.params.get(n);
        f.push(num(p.map(|p| p.value)));
        f.push(num(p.and_then(|p| p.std_error)));
    }
    f.extend([
        num(m.rms),
        m.rms_unit.clone().unwrap_or_default(),
        num(m.aic),
        num(m.bic),
        flag(m.converged),
        flag(m.best),
        m.warnings.join(";"),
        num(m.validation_rms),
        m.effects.as_ref().map(|e| e.join(";")).unwrap_or_default(),
        num(m.gap_before),
        num(r.wall_seconds),
        r.error.clone().unwrap_or_default(),
    ]);
    f
}
