//! The series of a campaign's parameter figure (`super::report`): a parameter against one
//! condition, one series per combination of the other conditions. Up to
//! [`MARKERS_PER_RECORD_UP_TO`] records each is a marker with its ± one standard error bar;
//! a larger campaign (thousands of records, repeats at each condition) would draw thousands
//! of overlapping markers, so its records are aggregated: one marker per series and value of
//! the condition, at the mean of the records there, its bar ± their standard deviation
//! (their spread, not a standard error); beyond [`MAX_SERIES`] series they are pooled into
//! one, "all records".

use std::collections::BTreeMap;

use super::labels::value_label;
use super::table::{CampaignJson, CampaignRow};
use crate::report::{ErrorPoint, ErrorSeries};

/// Records drawn one marker each, at most; above, markers are aggregated.
pub const MARKERS_PER_RECORD_UP_TO: usize = 60;

/// Series (legend entries) drawn at most; above, all records are one series.
pub const MAX_SERIES: usize = 8;

/// The figure's series and whether they are aggregated (means ± standard deviations).
pub struct FigureSeries {
    /// The series.
    pub series: Vec<ErrorSeries>,
    /// `true`: each marker is the mean of the records at its value, its bar their spread.
    pub aggregated: bool,
}

/// `param` against `condition` over `rows`, one series per combination of the other
/// conditions (aggregated above [`MARKERS_PER_RECORD_UP_TO`] records).
pub fn series_of(
    rows: &[&CampaignRow],
    param: &str,
    condition: &str,
    table: &CampaignJson,
) -> FigureSeries {
    let mut groups: BTreeMap<String, Vec<ErrorPoint>> = BTreeMap::new();
    let mut order: Vec<String> = Vec::new();
    for r in rows {
        let (Some(x), Some(p)) = (r.conditions.get(condition), r.result.params.get(param)) else {
            continue;
        };
        let label: Vec<String> = table
            .conditions
            .iter()
            .filter(|c| *c != condition)
            .filter_map(|c| {
                let v = r.conditions.get(c)?;
                Some(value_label(c, *v, table.condition_units.get(c)))
            })
            .collect();
        let label = if label.is_empty() {
            "records".to_string()
        } else {
            label.join(", ")
        };
        if !order.contains(&label) {
            order.push(label.clone());
        }
        groups
            .entry(label)
            .or_default()
            .push((*x, p.value, p.std_error.unwrap_or(f64::NAN)));
    }
    let mut series: Vec<ErrorSeries> = order
        .into_iter()
        .map(|label| ErrorSeries {
            points: groups.remove(&label).unwrap_or_default(),
            label,
        })
        .collect();
    let records: usize = series.iter().map(|s| s.points.len()).sum();
    if records <= MARKERS_PER_RECORD_UP_TO {
        return FigureSeries {
            series,
            aggregated: false,
        };
    }
    if series.len() > MAX_SERIES {
        let points = series.into_iter().flat_map(|s| s.points).collect();
        series = vec![ErrorSeries {
            label: "all records".into(),
            points,
        }];
    }
    for s in &mut series {
        s.points = means_by_x(&s.points);
        s.label = format!("{}: mean ± s.d.", s.label);
    }
    FigureSeries {
        series,
        aggregated: true,
    }
}

/// One point per distinct x of `points`: the mean of their finite y, ± their standard
/// deviation (NaN for a single value), in ascending x.
fn means_by_x(points: &[ErrorPoint]) -> Vec<ErrorPoint> {
    let mut by_x: BTreeMap<u64, (f64, Vec<f64>)> = BTreeMap::new();
    for &(x, y, _) in points.iter().filter(|p| p.0.is_finite() && p.1.is_finite()) {
        // Ordered by x: the bits of a float map to an order only for x ≥ 0, so shift.
        let key = (x + 0.0).to_bits() ^ if x < 0.0 { u64::MAX } else { 1 << 63 };
        by_x.entry(key).or_insert((x, Vec::new())).1.push(y);
    }
    by_x.into_values()
        .map(|(x, ys)| {
            let n = ys.len() as f64;
            let mean = ys.iter().sum::<f64>() / n;
            let sd = match ys.len() {
                1 => f64::NAN,
                _ => (ys.iter().map(|y| (y - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt(),
            };
            (x, mean, sd)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn means_are_taken_per_value_in_ascending_order() {
        let points = [
            (0.4, 2.0, 0.1),
            (-1.0, 5.0, 0.1),
            (0.4, 4.0, 0.1),
            (0.36, 1.0, 0.1),
            (0.4, f64::NAN, 0.1),
        ];
        let m = means_by_x(&points);
        assert_eq!(m.len(), 3);
        assert_eq!((m[0].0, m[0].1), (-1.0, 5.0));
        assert!(m[0].2.is_nan());
        assert_eq!((m[1].0, m[1].1), (0.36, 1.0));
        assert_eq!((m[2].0, m[2].1), (0.4, 3.0));
        assert!((m[2].2 - 2f64.sqrt()).abs() < 1e-12);
    }
}
