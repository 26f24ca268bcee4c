//! A report's results section, right under its verdict: every fitted value with its standard
//! error, relative error and unit (the value rounded to its error, held and bound-limited
//! values marked), read from the rows `params.csv` is written from, and one table of the
//! parameter pairs that correlate above 0.5 instead of a warning line per pair.

use stf_core::fit::FitResult;
use stf_study::digits::{fixed, rounded, with_error};
use stf_study::param_table::ParamRow;

use crate::report::{Section, Table};

/// Correlations at or above this size (in absolute value) are listed.
pub const SHOWN_CORRELATION: f64 = 0.5;

/// The section "Results": each model's force as an equation (`equations`: a label and the
/// equation, as the JSON holds it), `rows` (every model's, in order) and the correlations of
/// each of `fits` (a label and its result).
pub fn results_section(
    title: &str,
    equations: &[(&str, String)],
    rows: &[ParamRow],
    fits: &[(&str, &FitResult)],
) -> Section {
    let mut s = Section::new(title);
    s.paragraphs.extend(equation_lines(equations));
    s.tables.push(values_table(rows));
    let pairs = correlated_pairs(fits);
    if !pairs.is_empty() {
        let caption = format!(
            "Parameter pairs whose estimates correlate at |r| ≥ {SHOWN_CORRELATION}: near ±1 \
             the data tell them apart poorly (fix one, or fit a record with a wider range)."
        );
        let table = Table::new(caption, &["model", "parameters", "correlation r"]);
        s.tables.push(table.with_rows(pairs));
    }
    s
}

/// The equations as paragraphs: one for a single model (`The force: F_STF = …`), one per
/// model otherwise (`` `power_law`: F_STF = … ``); values rounded to their standard errors.
fn equation_lines(equations: &[(&str, String)]) -> Vec<String> {
    match equations {
        [] => Vec::new(),
        [(_, eq)] => vec![format!(
            "The force, values rounded to their standard errors: {eq}"
        )],
        _ => std::iter::once(
            "Each model's force, values rounded to their standard errors:".to_string(),
        )
        .chain(
            equations
                .iter()
                .map(|(label, eq)| format!("`{label}`: {eq}")),
        )
        .collect(),
    }
}

/// Model, parameter, value ± standard error, relative error, unit, note.
fn values_table(rows: &[ParamRow]) -> Table {
    let caption = "Final values with their standard errors (SI units; the value rounded to its \
                   error); the relative error is the standard error over |value|.";
    let columns = [
        "model",
        "parameter",
        "value ± standard error",
        "relative error",
        "unit",
        "note",
    ];
    let body = rows.iter().map(|r| {
        let (value, relative) = match (r.fixed, r.std_error) {
            (true, _) => (rounded(r.value, f64::NAN), "—".to_string()),
            (false, Some(se)) => (with_error(r.value, se), relative_error(r.value, se)),
            (false, None) => (
                format!("{} ± not determined", rounded(r.value, f64::NAN)),
                "—".into(),
            ),
        };
        let note = match (r.fixed, r.at_bound) {
            (true, _) => "held",
            (false, true) => "on a bound",
            _ => "",
        };
        vec![
            r.model.clone(),
            r.parameter.clone(),
            value,
            relative,
            r.unit.clone(),
            note.to_string(),
        ]
    });
    Table::new(caption, &columns).with_rows(body.collect())
}

/// `se / |value|` in percent, two significant digits.
fn relative_error(value: f64, se: f64) -> String {
    if value == 0.0 || !se.is_finite() {
        return "—".into();
    }
    let pct = 100.0 * se / value.abs();
    let decimals = if pct >= 10.0 {
        0
    } else if pct >= 1.0 {
        1
    } else {
        2
    };
    format!("{} %", fixed(pct, decimals))
}

/// Each fit's pairs of free parameters correlating at or above [`SHOWN_CORRELATION`].
fn correlated_pairs(fits: &[(&str, &FitResult)]) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for (label, result) in fits {
        let free: Vec<&str> = result
            .params
            .iter()
            .filter(|p| !p.fixed)
            .map(|p| p.name.as_str())
            .collect();
        for (i, row) in result.correlation.iter().enumerate() {
            for (j, &r) in row.iter().enumerate().skip(i + 1) {
                if r.abs() >= SHOWN_CORRELATION && i < free.len() && j < free.len() {
                    let pair = format!("{} · {}", free[i], free[j]);
                    out.push(vec![label.to_string(), pair, fixed(r, 3)]);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_errors_carry_two_significant_digits() {
        assert_eq!(relative_error(4.074, 0.047), "1.2 %");
        assert_eq!(relative_error(-2.0, 0.5), "25 %");
        assert_eq!(relative_error(10004.0, 8.1), "0.08 %");
        assert_eq!(relative_error(0.0, 1.0), "—");
    }
}
