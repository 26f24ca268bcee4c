//! The parameter table a paper's methods section quotes, written as `params.csv` beside
//! `fit.json`: one row per fitted (or held) parameter with its model, value, standard error,
//! unit and whether it ended on a bound. Rows are [`ParamRow`]s serialized by the csv crate;
//! numbers carry their own digits ([`crate::digits`]).
//!
//! ```text
//! model,parameter,value,std_error,unit,fixed,at_bound
//! power_law,K,4.07392,0.0469,N·(s/m)^n,false,false
//! ```

use std::path::Path;

use anyhow::Result;
use serde::Serialize;
use stf_core::fit::{FitResult, FitWarning};
use stf_core::physics::force_model::ForceModel;

use crate::digits::carried;
use crate::fitting::ModelFit;
use crate::param_units::in_record_units;
use crate::shown_units::ShownUnits;

/// One row of the table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParamRow {
    /// The model's label (unique in the experiment), or the identification stage.
    pub model: String,
    /// The parameter's name as in `fit.json`.
    pub parameter: String,
    /// Fitted value (SI units).
    pub value: f64,
    /// Standard error; empty when the data do not determine it (or when held).
    pub std_error: Option<f64>,
    /// Unit: SI, with lengths and forces in the record's own units ([`in_record_units`]: V
    /// for a length on a record whose x is in volts); empty for a plain number.
    pub unit: String,
    /// Held at its value, not fitted.
    pub fixed: bool,
    /// The fit ended on one of its bounds (a `on_bound` warning).
    pub at_bound: bool,
}

/// The unit of an oscillator parameter, an offset or an initial state.
fn system_unit(name: &str) -> Option<&'static str> {
    Some(match name {
        "m" => "kg",
        "k" => "N/m",
        "c" => "N·s/m",
        "T" | "delta_T" | "f_off" | "u_off" => "N",
        "F0" => "kg·m",
        "eta" => "s/m",
        "phi_off" => "rad",
        "x_off" | "x0" => "m",
        "v0" => "m/s",
        _ => return None,
    })
}

/// The rows of one fit: `result`'s parameters, units from `model`'s specs or the oscillator's
/// on a record shown in `units`.
pub fn rows_of(
    label: &str,
    result: &FitResult,
    model: Option<&dyn ForceModel>,
    warnings: &[FitWarning],
    units: &ShownUnits,
) -> Vec<ParamRow> {
    result
        .params
        .iter()
        .map(|p| {
            let spec_unit = model
                .and_then(|m| m.params().iter().find(|s| s.name == p.name))
                .map(|s| s.unit.clone());
            let unit = spec_unit
                .or_else(|| system_unit(&p.name).map(str::to_string))
                .map(|u| in_record_units(&u, units))
                .unwrap_or_default();
            let at_bound = warnings
                .iter()
                .any(|w| matches!(w, FitWarning::OnBound { param, .. } if *param == p.name));
            ParamRow {
                model: label.to_string(),
                parameter: p.name.clone(),
                value: carried(p.value),
                std_error: (!p.fixed && p.std_error.is_finite()).then(|| carried(p.std_error)),
                unit,
                fixed: p.fixed,
                at_bound,
            }
        })
        .collect()
}

/// The rows of every model fit, in order, on a record shown in `units`.
pub fn rows_of_fits(fits: &[ModelFit], units: &ShownUnits) -> Vec<ParamRow> {
    fits.iter()
        .flat_map(|f| {
            let model = f.configured.as_ref().map(|c| c.model.as_ref());
            rows_of(&f.label, &f.result, model, &f.warnings, units)
        })
        .collect()
}

/// The text of `params.csv` (`path`, for messages): `rows` under their header.
pub fn params_csv(path: &Path, rows: &[ParamRow]) -> Result<Vec<u8>> {
    crate::outputs::csv_rows(path, rows)
}
