//! `compare.csv` of `stf-lab compare`: one row per model and regime the record has cycles in,
//! the errors of `compare.json`'s `regimes` in a table. Rows are [`CompareRow`]s serialized by
//! the csv crate; numbers are written with the digits they carry, in Rust's shortest form
//! (`1`, `0.0029`, `0.000155` and never `0.00015500000000000003`: [`crate::digits::csv_number`]).

use std::path::Path;

use anyhow::Result;
use serde::Serialize;
use stf_core::regimes::{Comparison, Regime, RegimeMetrics};

use super::csv_rows;
use crate::digits::csv_number;

/// One row: a model's errors in one regime.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CompareRow<'a> {
    /// The model's label.
    pub model: &'a str,
    /// `pre_resonance`, `resonance` or `post_resonance`.
    pub regime: &'static str,
    /// Measured cycles in the regime.
    pub cycles: usize,
    /// RMS of the force error (model − measured), N.
    #[serde(rename = "force_rms_error_N", serialize_with = "csv_number")]
    pub force_rms_error: f64,
    /// `force_rms_error_N` over the measured force's RMS (at least the on-threshold).
    #[serde(serialize_with = "csv_number")]
    pub relative_rms_error: f64,
    /// Mean |Δ∮F dx| per cycle, J.
    #[serde(rename = "energy_error_J", serialize_with = "csv_number")]
    pub energy_error: f64,
    /// Mean |Δduty| (on-fraction) per cycle.
    #[serde(serialize_with = "csv_number")]
    pub duty_error: f64,
    /// Mean |Δ peak |F|| per cycle, N.
    #[serde(rename = "peak_force_error_N", serialize_with = "csv_number")]
    pub peak_force_error: f64,
    /// Fraction of cycles whose model label equals the measured label.
    #[serde(serialize_with = "csv_number")]
    pub label_agreement: f64,
    /// Mean measured ∮F dx per cycle, J.
    #[serde(rename = "measured_energy_J", serialize_with = "csv_number")]
    pub measured_energy: f64,
    /// The same of the model's force, J.
    #[serde(rename = "model_energy_J", serialize_with = "csv_number")]
    pub model_energy: f64,
    /// Mean measured equivalent viscous damping, N·s/m.
    #[serde(rename = "measured_c_eq_Ns_m", serialize_with = "csv_number")]
    pub measured_c_eq: f64,
    /// The same of the model's force, N·s/m.
    #[serde(rename = "model_c_eq_Ns_m", serialize_with = "csv_number")]
    pub model_c_eq: f64,
    /// Mean |Δphase against x| per cycle, degrees.
    #[serde(serialize_with = "csv_number")]
    pub phase_x_error_deg: f64,
    /// Mean |Δphase against v| per cycle, degrees.
    #[serde(serialize_with = "csv_number")]
    pub phase_v_error_deg: f64,
}

impl<'a> CompareRow<'a> {
    /// The row of `model` in `regime`.
    pub fn new(model: &'a str, regime: Regime, m: &RegimeMetrics) -> Self {
        CompareRow {
            model,
            regime: regime.name(),
            cycles: m.cycles,
            force_rms_error: m.force_rms_error,
            relative_rms_error: m.relative_rms_error,
            energy_error: m.energy_error,
            duty_error: m.duty_error,
            peak_force_error: m.peak_force_error,
            label_agreement: m.label_agreement,
            measured_energy: m.measured_energy,
            model_energy: m.model_energy,
            measured_c_eq: m.measured_c_eq,
            model_c_eq: m.model_c_eq,
            phase_x_error_deg: m.phase_x_error,
            phase_v_error_deg: m.phase_v_error,
        }
    }
}

/// The rows of every model (`labels`, in order) in every regime it was scored in.
pub fn rows<'a>(labels: &[&'a str], comparisons: &[Comparison]) -> Vec<CompareRow<'a>> {
    labels
        .iter()
        .zip(comparisons)
        .flat_map(|(&label, c)| {
            Regime::ALL
                .into_iter()
                .filter_map(move |r| c.per_regime.get(r).map(|m| CompareRow::new(label, r, m)))
        })
        .collect()
}

/// The text of `compare.csv` (`path`, for messages): `rows` under their header (the header
/// alone when no model was scored in any regime).
pub fn csv_text(path: &Path, rows: &[CompareRow]) -> Result<Vec<u8>> {
    if !rows.is_empty() {
        return csv_rows(path, rows);
    }
    // The header line alone, as the csv crate derives it from the fields of [`CompareRow`]
    // (it writes a header with the first row only).
    let text = csv_rows(path, &[CompareRow::default()])?;
    let end = text
        .iter()
        .position(|b| *b == b'\n')
        .map_or(text.len(), |i| i + 1);
    Ok(text[..end].to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_keep_their_shortest_form_and_no_rows_still_give_the_header() {
        let path = std::path::Path::new("compare.csv");
        let row = CompareRow {
            model: "power_law",
            regime: "resonance",
            cycles: 3,
            label_agreement: 1.0,
            energy_error: 0.000025,
            ..CompareRow::default()
        };
        let text = String::from_utf8(csv_text(path, &[row]).unwrap()).unwrap();
        let mut lines = text.lines();
        let header = lines.next().unwrap();
        assert!(
            header.starts_with("model,regime,cycles,force_rms_error_N,"),
            "{header}"
        );
        assert_eq!(
            lines.next().unwrap(),
            "power_law,resonance,3,0,0,0.000025,0,0,1,0,0,0,0,0,0"
        );
        assert_eq!(
            String::from_utf8(csv_text(path, &[]).unwrap()).unwrap(),
            format!("{header}\n")
        );
    }
}
