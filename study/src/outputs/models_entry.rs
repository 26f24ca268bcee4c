//! The experiment entries `discover` prints and stores in `discovery.json`
//! (`final_model.experiment_entry`, `final_model.system_entry`): the final model as a
//! `[[models]]` entry, and the refitted oscillator as a `[system]` table, that `fit` and
//! `compare` accept as they are. Both are serialized by the toml crates, so any name is
//! quoted and escaped as TOML needs and every number is a TOML number (`nan`, `1e25`); the
//! entry goes through `toml_edit` to keep its parameters on one line, as experiment files
//! write them (`params = { K = 4.0, n = 1.5 }`). Values carry 15 significant digits
//! ([`crate::digits::carried`]), as every output does: pasted back, they reproduce the fit.

use indexmap::IndexMap;
use serde::Serialize;
use stf_core::fit::FittedParam;
use toml_edit::Item;

/// A `[[models]]` entry: one model, named as the experiment names it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModelsEntry {
    /// The array of tables `[[models]]`, with one entry.
    pub models: [ModelEntryToml; 1],
}

/// One model of `[[models]]`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModelEntryToml {
    /// The first model of the sum (a built-in's name or a script's path).
    pub name: String,
    /// The models added to it, in order (omitted when none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub plus: Vec<String>,
    /// Parameter values by name, in the model's order, SI units.
    pub params: IndexMap<String, EntryValue>,
}

/// A parameter's value in an entry: a number, or a law of a measured channel.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum EntryValue {
    /// A constant.
    Value(f64),
    /// `{ law = "affine", channel = "u", base = …, gain = … }`.
    Law(LawEntry),
}

/// A parameter that follows a channel, as an experiment gives it: the law's name, its
/// channel and its coefficients' values (those the law has).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LawEntry {
    /// `linear`, `affine` or `power`.
    pub law: &'static str,
    /// The record's column.
    pub channel: String,
    /// P_base (not for the linear law).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub base: Option<f64>,
    /// P_gain.
    pub gain: f64,
    /// P_exp (the power law's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exp: Option<f64>,
}

impl ModelsEntry {
    /// The entry of the model whose terms are `terms` (its first is `name`, the rest `plus`;
    /// none is the zero force `none`) with the values of `params`.
    pub fn new<'a>(terms: &[&str], params: impl IntoIterator<Item = &'a FittedParam>) -> Self {
        let (name, plus) = terms.split_first().unwrap_or((&"none", &[]));
        ModelsEntry {
            models: [ModelEntryToml {
                name: name.to_string(),
                plus: plus.iter().map(|t| t.to_string()).collect(),
                params: params
                    .into_iter()
                    .map(|p| {
                        let value = EntryValue::Value(crate::digits::carried(p.value));
                        (p.name.clone(), value)
                    })
                    .collect(),
            }],
        }
    }

    /// The entry of the model whose terms are `terms` with the values `params` as they are
    /// (by name, laws included).
    pub fn with_values(terms: &[&str], params: IndexMap<String, EntryValue>) -> Self {
        let (name, plus) = terms.split_first().unwrap_or((&"none", &[]));
        ModelsEntry {
            models: [ModelEntryToml {
                name: name.to_string(),
                plus: plus.iter().map(|t| t.to_string()).collect(),
                params,
            }],
        }
    }

    /// The entry as TOML text: `[[models]]`, then `name`, `plus` and `params` inline.
    pub fn to_toml(&self) -> Result<String, toml_edit::ser::Error> {
        let mut doc = toml_edit::ser::to_document(self)?;
        if let Some(models) = doc.get_mut("models") {
            let inline = std::mem::take(models);
            *models = inline
                .into_array_of_tables()
                .map_or_else(|item| item, Item::ArrayOfTables);
        }
        Ok(doc.to_string())
    }
}

/// A `[system]` table: the oscillator parameters a discovery refitted.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SystemEntry {
    /// Values by name, in the order refitted, SI units.
    pub system: IndexMap<String, f64>,
}

impl SystemEntry {
    /// The table as TOML text: `[system]`, then one line a parameter.
    pub fn to_toml(&self) -> Result<String, toml::ser::Error> {
        toml::to_string(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn param(name: &str, value: f64) -> FittedParam {
        FittedParam::free(name, value, f64::NAN)
    }

    #[test]
    fn a_sum_of_models_is_a_name_with_plus_and_inline_params() {
        let e = ModelsEntry::new(
            &["power_law", "cubic_stiffness"],
            &[param("K", 4.01), param("n", 1.5), param("k3", 2e4)],
        );
        assert_eq!(
            e.to_toml().unwrap(),
            "[[models]]\nname = \"power_law\"\nplus = [\"cubic_stiffness\"]\n\
             params = { K = 4.01, n = 1.5, k3 = 20000.0 }\n"
        );
        let single = ModelsEntry::new(&["viscous"], &[param("c_s", 1.25)]);
        assert_eq!(
            single.to_toml().unwrap(),
            "[[models]]\nname = \"viscous\"\nparams = { c_s = 1.25 }\n"
        );
        let zero = ModelsEntry::new(&[], &[]);
        assert_eq!(
            zero.to_toml().unwrap(),
            "[[models]]\nname = \"none\"\nparams = {}\n"
        );
    }

    #[test]
    fn a_law_is_an_inline_table_in_the_params() {
        let law = LawEntry {
            law: "affine",
            channel: "u_ctrl".into(),
            base: Some(0.5),
            gain: 1.5,
            exp: None,
        };
        let params = [
            ("c_s".to_string(), EntryValue::Value(5.0)),
            ("F_y".to_string(), EntryValue::Law(law)),
        ];
        let e = ModelsEntry::with_values(&["viscous", "yield"], params.into_iter().collect());
        assert_eq!(
            e.to_toml().unwrap(),
            "[[models]]\nname = \"viscous\"\nplus = [\"yield\"]\nparams = { c_s = 5.0, F_y = \
             { law = \"affine\", channel = \"u_ctrl\", base = 0.5, gain = 1.5 } }\n"
        );
    }

    #[test]
    fn names_are_escaped_and_every_number_reads_back() {
        let path = "scripts/my \"best\" model\\v2.rhai";
        let e = ModelsEntry::new(
            &[path],
            &[
                param("we\"ird key", 1e25),
                param("tiny", 1e-7),
                param("k", f64::NAN),
            ],
        );
        let text = e.to_toml().unwrap();
        let back: toml::Table = toml::from_str(&text).unwrap();
        let model = &back["models"][0];
        assert_eq!(model["name"].as_str(), Some(path));
        assert_eq!(model["params"]["we\"ird key"].as_float(), Some(1e25));
        assert_eq!(model["params"]["tiny"].as_float(), Some(1e-7));
        assert!(model["params"]["k"].as_float().unwrap().is_nan());
    }

    #[test]
    fn the_system_table_keeps_the_refitted_order() {
        let e = SystemEntry {
            system: [("m".to_string(), 7.65), ("k".to_string(), 269.93)]
                .into_iter()
                .collect(),
        };
        assert_eq!(e.to_toml().unwrap(), "[system]\nm = 7.65\nk = 269.93\n");
    }
}
