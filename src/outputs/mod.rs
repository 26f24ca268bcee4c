//! The results files, one type each: what a command writes is a value of one of these
//! `Serialize` types, built from the command's results and then written — JSON through
//! [`crate::output::write_json`] (numbers tidied by [`crate::digits`]), CSV through the `csv`
//! crate, the experiment entry through `toml_edit`. A type's fields *are* the file's
//! contract (docs/ARCHITECTURE.md §6): each carries its unit in its doc comment.
//!
//! | file | type |
//! |---|---|
//! | `fit.json` | [`fit_json::FitJson`] (each model [`fit_json::ModelFitJson`]) |
//! | `fit.json` of `[[identify]]` | [`identification_json::IdentificationJson`] |
//! | `compare.json` | [`compare_json::CompareJson`] |
//! | `compare.csv` | [`compare_csv::CompareRow`] |
//! | `discovery.json` | [`discovery_json::DiscoveryJson`] |
//! | the `[[models]]` / `[system]` entries | [`models_entry::ModelsEntry`], [`models_entry::SystemEntry`] |
//! | `simulate`'s sidecar `.json` | [`simulate_json::SimulateJson`] |
//! | `fitted.csv`, `discovered.csv` | [`columns_csv::Columns`] |
//!
//! `params.csv` and `cycles.csv` are [`crate::param_table::ParamRow`] and
//! [`crate::compare_loops`]'s `CycleRow`.

pub mod columns_csv;
pub mod compare_csv;
pub mod compare_json;
pub mod discovery_json;
pub mod fit_json;
pub mod identification_json;
pub mod models_entry;
pub mod simulate_json;

use std::collections::BTreeMap;

use stf_core::fit::FittedParam;

/// `v`, or `None` (JSON `null`) when it is not finite: JSON has no NaN or infinity.
pub fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// Parameters by name: each one's value.
pub fn values_by_name<'a>(
    params: impl IntoIterator<Item = &'a FittedParam>,
) -> BTreeMap<String, f64> {
    params
        .into_iter()
        .map(|p| (p.name.clone(), p.value))
        .collect()
}

/// Parameters by name: each one's `error` (its standard error or another; `null` where the
/// data do not give it).
pub fn errors_by_name(
    params: &[FittedParam],
    error: impl Fn(&FittedParam) -> f64,
) -> BTreeMap<String, Option<f64>> {
    params
        .iter()
        .map(|p| (p.name.clone(), finite(error(p))))
        .collect()
}

/// The name of a fit level in JSON: `force` or `trajectory`.
pub fn level_name(level: crate::experiment::FitLevel) -> &'static str {
    match level {
        crate::experiment::FitLevel::Force => "force",
        crate::experiment::FitLevel::Trajectory => "trajectory",
    }
}
