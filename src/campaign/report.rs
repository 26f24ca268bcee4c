//! The campaign's report: `report.md` and `report.html` (the house's report module,
//! `crate::report`) with, for each model's fitted parameter, a figure of its value against
//! each condition with ±1 standard error bars — one series per combination of the other
//! conditions, aggregated for large campaigns ([`super::figure_series`]) — and the campaign
//! table (its first [`TABLE_ROWS`] rows and the failed ones). Figures go to `figures/` as SVG, PNG and CSV; an
//! earlier run's figures that this one does not draw are removed from there (figures only:
//! an SVG, PNG and CSV of one name), and unit folders of records no longer in the campaign
//! are named in a note (never deleted: they are the user's results). `report.md` and
//! `report.html` are staged with the tables and put in place with them.

use std::path::Path;

use anyhow::{Context, Result};

use super::figure_series::series_of;
use super::global::GlobalJson;
use super::labels::axis_label;
use super::table::{param_names, CampaignJson, CampaignRow};
use crate::digits::{carried, with_error};
use crate::report::{self, FigureRef, Report, Section, Table};
use crate::writing::results_dir::is_figure;
use crate::writing::staged_files::StagedFiles;

/// Draw `figures/` of `table` into `out` and stage `report.md` and `report.html` in
/// `staged`, the global fit's section first when there is one. The figure files drawn.
pub fn write(
    table: &CampaignJson,
    global: Option<&GlobalJson>,
    out: &Path,
    staged: &mut StagedFiles,
) -> Result<Vec<std::ffi::OsString>> {
    let mut doc = Report::new(format!("Campaign {}", table.campaign));
    let ok_units = table.units - table.failed;
    doc.intro.push(format!(
        "stf-lab ran the {} unit(s) of {}: {ok_units} wrote results, {} failed. A row per \
         record and model; parameters in SI units (lengths and forces in V on a record in \
         volts, as its params.csv gives them), ± one standard error (block-robust).",
        table.units, table.campaign, table.failed
    ));
    if !table.stale_units.is_empty() {
        doc.intro.push(format!(
            "Note: units/ holds {} folder(s) that no unit of this campaign writes (records \
             removed from it since an earlier run), left as they were and not in the table: {}.",
            table.stale_units.len(),
            table.stale_units.join(", ")
        ));
    }
    if let Some(g) = global {
        doc.sections
            .push(super::global_report::section(g, &out.join("figures"))?);
    }
    let figures = parameter_figures(table, &out.join("figures"))?;
    if !figures.is_empty() {
        let mut section = Section::new("Parameters against the conditions");
        section.paragraphs.push(
            "Each fitted parameter against each condition, one marker per record with its ± one \
             standard error bar; one colour per value of the other conditions (markers that \
             share a condition are set slightly apart)."
                .into(),
        );
        section.figures = figures;
        doc.sections.push(section);
    }
    let mut section = Section::new("Table");
    section.tables.push(table_of(table));
    doc.sections.push(section);
    report::write_markdown(&doc, &staged.stage(&out.join("report.md"))?)?;
    report::write_html(&doc, &staged.stage(&out.join("report.html"))?)?;
    Ok(doc
        .sections
        .iter()
        .flat_map(|s| &s.figures)
        .flat_map(|f| [&f.files.svg, &f.files.png, &f.files.csv])
        .filter_map(|p| p.file_name().map(|n| n.to_os_string()))
        .collect())
}

/// Remove the figures of `dir` (the campaign's own `figures/`) that this report does not draw
/// (`drawn`): an earlier run's figures of a parameter, condition or law the campaign no
/// longer has. Only figures (an SVG, PNG and CSV of one name) are removed; the program's
/// temporaries and anything else are left alone.
pub fn remove_stale_figures(drawn: &[std::ffi::OsString], dir: &Path) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    let entries: Vec<_> = entries.filter_map(|e| e.ok()).collect();
    let files: Vec<String> = entries
        .iter()
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    let files: Vec<&str> = files.iter().map(String::as_str).collect();
    for entry in &entries {
        let name = entry.file_name();
        let figure = files.contains(&name.to_string_lossy().as_ref())
            && is_figure(&name.to_string_lossy(), &files);
        if figure && !drawn.contains(&name) {
            std::fs::remove_file(entry.path()).with_context(|| {
                format!("cannot remove the stale figure {}", entry.path().display())
            })?;
        }
    }
    Ok(())
}

/// The rows that carry results.
fn ok_rows(table: &CampaignJson) -> impl Iterator<Item = &CampaignRow> {
    table.rows.iter().filter(|r| r.status == "ok")
}

/// A figure per model, fitted parameter and condition that varies.
fn parameter_figures(table: &CampaignJson, dir: &Path) -> Result<Vec<FigureRef>> {
    let mut models: Vec<&str> = Vec::new();
    for r in ok_rows(table) {
        if let Some(m) = r.result.model.as_deref().filter(|m| !models.contains(m)) {
            models.push(m);
        }
    }
    let mut figures = Vec::new();
    for model in models {
        let rows: Vec<&CampaignRow> = ok_rows(table)
            .filter(|r| r.result.model.as_deref() == Some(model))
            .collect();
        let owned: Vec<CampaignRow> = rows.iter().map(|r| (*r).clone()).collect();
        for param in param_names(&owned) {
            // A parameter held on every record (no standard error anywhere) has nothing to show.
            let fitted = rows.iter().any(|r| {
                r.result
                    .params
                    .get(&param)
                    .is_some_and(|p| p.std_error.is_some())
            });
            if !fitted {
                continue;
            }
            for condition in &table.conditions {
                let distinct = distinct_values(&rows, condition);
                if distinct < 2 {
                    continue;
                }
                let drawn = series_of(&rows, &param, condition, table);
                let name = file_name(&format!("{model}_{param}_vs_{condition}"));
                let title = format!("{model}: {param} against {condition}");
                let unit = rows
                    .iter()
                    .find_map(|r| r.result.params.get(&param)?.unit.as_deref());
                let x = axis_label(
                    condition,
                    table.condition_units.get(condition).map(String::as_str),
                );
                let y = axis_label(&param, unit);
                let files = report::error_bars(dir, &name, &title, (&x, &y), &drawn.series)?;
                let caption = match drawn.aggregated {
                    false => format!(
                        "`{model}`'s fitted {param} (± one standard error) against {condition}, \
                         over {} record(s).",
                        rows.len()
                    ),
                    true => format!(
                        "`{model}`'s fitted {param} against {condition}, over {} records: each \
                         marker is the mean of the records at that {condition}, its bar ± their \
                         standard deviation (the spread between records, not an error).",
                        rows.len()
                    ),
                };
                figures.push(FigureRef::new(files, caption));
            }
        }
    }
    Ok(figures)
}

/// How many different values `condition` takes over `rows`.
fn distinct_values(rows: &[&CampaignRow], condition: &str) -> usize {
    let mut values: Vec<f64> = rows
        .iter()
        .filter_map(|r| r.conditions.get(condition).copied())
        .collect();
    values.sort_by(f64::total_cmp);
    values.dedup();
    values.len()
}

/// A figure's file name: letters, digits, `-` and `_`.
fn file_name(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Rows of the report's table, at most (failed units' rows are shown all the same).
pub const TABLE_ROWS: usize = 200;

/// The table for a person: conditions, model, parameters ± errors, RMS, verdicts; the first
/// [`TABLE_ROWS`] rows and every failed one (a campaign of thousands of records would make a
/// page no one reads; `campaign.csv` has them all).
fn table_of(table: &CampaignJson) -> Table {
    let mut columns: Vec<String> = vec!["unit".into(), "record".into()];
    columns.extend(table.conditions.iter().cloned());
    columns.extend(
        [
            "model",
            "parameters (± standard error)",
            "RMS",
            "best",
            "warnings",
            "status",
        ]
        .map(String::from),
    );
    let shown: Vec<&CampaignRow> = table
        .rows
        .iter()
        .enumerate()
        .filter(|(i, r)| *i < TABLE_ROWS || r.status != "ok")
        .map(|(_, r)| r)
        .collect();
    let caption = match shown.len() < table.rows.len() {
        true => format!(
            "The first {TABLE_ROWS} of {} rows, and every failed unit's; campaign.csv and \
             campaign.json hold them all.",
            table.rows.len()
        ),
        false => String::new(),
    };
    let rows = shown
        .into_iter()
        .map(|r| {
            let mut cells = vec![r.unit.to_string(), r.record.clone()];
            cells.extend(table.conditions.iter().map(|c| {
                r.conditions
                    .get(c)
                    .map_or(String::new(), |v| carried(*v).to_string())
            }));
            let params: Vec<String> = r
                .result
                .params
                .iter()
                .map(|(n, p)| match p.std_error {
                    Some(e) => format!("{n} = {}", with_error(p.value, e)),
                    None => format!("{n} = {}", carried(p.value)),
                })
                .collect();
            let rms = match (r.result.rms, &r.result.rms_unit) {
                (Some(v), Some(u)) => shown_rms(v, u),
                _ => String::new(),
            };
            cells.extend([
                r.result.model.clone().unwrap_or_default(),
                params.join(", "),
                rms,
                r.result.best.map_or(
                    String::new(),
                    |b| if b { "yes".into() } else { String::new() },
                ),
                r.result.warnings.join(", "),
                match &r.error {
                    Some(e) => format!("failed: {e}"),
                    None => r.status.to_string(),
                },
            ]);
            cells
        })
        .collect();
    Table {
        caption,
        columns,
        rows,
    }
}

/// An RMS `value` in its record's SI `unit` as the lab shows it: a displacement in mm (m), a
/// voltage in mV (V), a force in N.
fn shown_rms(value: f64, unit: &str) -> String {
    match unit {
        "m" => format!("{:.4} mm", value * 1e3),
        "V" => format!("{:.4} mV", value * 1e3),
        u => format!("{value:.4} {u}"),
    }
}
