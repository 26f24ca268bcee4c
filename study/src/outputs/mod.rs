//! The results files, one type each: what a command writes is a value of one of these
//! `Serialize` types, built from the study's results; the program writes them — JSON through
//! its `writing::write_json` (numbers tidied by [`crate::digits`]), CSV through the `csv`
//! crate (this module gives the bytes), the experiment entry through `toml_edit`. A type's fields *are* the file's
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
//! the program's `compare_loops` `CycleRow`.

pub mod columns_csv;
pub mod compare_csv;
pub mod compare_json;
pub mod discovery_json;
pub mod fit_json;
pub mod identification_json;
pub mod models_entry;
pub mod simulate_json;

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result};
use stf_core::fit::FittedParam;

/// `rows` as the CSV text of `path`, under the header the csv crate derives from `T`'s
/// fields (written with the first row: no rows, no header).
pub fn csv_rows<T: serde::Serialize>(path: &Path, rows: &[T]) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for row in rows {
        w.serialize(row)
            .with_context(|| format!("cannot write a row of {}", path.display()))?;
    }
    w.into_inner()
        .with_context(|| format!("cannot write {}", path.display()))
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

/// Parameters by name: each one's `error` (its standard error or another; NaN, JSON's
/// `null`, where the data do not give it).
pub fn errors_by_name(
    params: &[FittedParam],
    error: impl Fn(&FittedParam) -> f64,
) -> BTreeMap<String, f64> {
    params.iter().map(|p| (p.name.clone(), error(p))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The output types hold NaN where a value is not determined: what makes it JSON's `null`
    /// is serde_json, which the program's `write_json` uses for every f64 of every file.
    #[test]
    fn numbers_that_are_not_finite_are_written_as_null() {
        #[derive(serde::Serialize)]
        struct Doc {
            aic: f64,
            correlation: Vec<Vec<f64>>,
            std_errors: BTreeMap<String, f64>,
        }
        let param = |name: &str, std_error| FittedParam::free(name, 1.5, std_error);
        let doc = Doc {
            aic: f64::NEG_INFINITY,
            correlation: vec![vec![1.0, f64::NAN]],
            std_errors: errors_by_name(&[param("K", 0.25), param("n", f64::INFINITY)], |p| {
                p.std_error
            }),
        };
        let text = serde_json::to_string_pretty(&serde_json::to_value(&doc).unwrap()).unwrap();
        let back: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(
            back,
            serde_json::json!({
                "aic": null,
                "correlation": [[1.0, null]],
                "std_errors": { "K": 0.25, "n": null },
            })
        );
    }
}
