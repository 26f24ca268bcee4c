//! `[[models]]` and `[[simulate.truth]]` entries of an experiment file: a built-in `name` or
//! a `script` (exactly one), further models summed with it (`plus`), and `params` — a value,
//! or a table of `value`, `min`, `max`, `fixed` — each with its line. Whether the names
//! resolve and the values lie within the model's bounds needs the registry (scripts), so
//! `crate::model_config` checks that, from these typed entries.

use std::collections::BTreeMap;

use anyhow::Result;
use serde::Deserialize;
use stf_core::fit::FitParam;
use stf_core::physics::channel_law::Law;
use toml::Spanned;

use super::Ctx;

/// A parameter value as written: a number, or a table with value / min / max / fixed.
#[derive(Clone, Debug)]
enum RawParam {
    /// Just the value.
    Value(f64),
    /// Value with bounds and a fixed/free switch, or a law of a channel.
    Table(RawTable),
}

/// A parameter's table as written: `{ value, min, max, fixed }`, or a law of a measured
/// channel `{ law, channel, base, gain, exp }`.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTable {
    value: Option<f64>,
    min: Option<f64>,
    max: Option<f64>,
    fixed: Option<bool>,
    law: Option<String>,
    channel: Option<String>,
    base: Option<f64>,
    gain: Option<f64>,
    exp: Option<f64>,
}

/// Read by hand rather than as an untagged enum, whose error ("data did not match any
/// variant") names neither what was expected nor which key of a table was wrong.
impl<'de> Deserialize<'de> for RawParam {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = RawParam;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or a table { value, min, max, fixed }")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<RawParam, E> {
                Ok(RawParam::Value(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<RawParam, E> {
                Ok(RawParam::Value(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<RawParam, E> {
                Ok(RawParam::Value(v as f64))
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<RawParam, A::Error> {
                let table = serde::de::value::MapAccessDeserializer::new(map);
                RawTable::deserialize(table).map(RawParam::Table)
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// What an entry sets of a parameter — its table form as written (`{ value, min, max,
/// fixed }`); what is not given keeps the model's default. It stays apart from the checked
/// setting, core's [`FitParam`], because "not given" is part of it.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamOverride {
    /// Initial or fixed value.
    pub value: Option<f64>,
    /// Lower bound.
    pub min: Option<f64>,
    /// Upper bound.
    pub max: Option<f64>,
    /// Held at its value in fits.
    pub fixed: Option<bool>,
}

impl ParamOverride {
    /// Set on `p` what this gives.
    pub fn apply(&self, p: &mut FitParam) {
        p.value = self.value.unwrap_or(p.value);
        p.min = self.min.unwrap_or(p.min);
        p.max = self.max.unwrap_or(p.max);
        p.fixed = self.fixed.unwrap_or(p.fixed);
    }
}

/// One `[[models]]` (or `[[simulate.truth]]`) entry as written.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawModel {
    name: Option<String>,
    script: Option<String>,
    #[serde(default)]
    plus: Vec<String>,
    #[serde(default)]
    params: BTreeMap<String, Spanned<RawParam>>,
}

/// Where an entry's first model comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ModelSource {
    /// A built-in model's name (`name = "power_law"`), or a sum `a + b`.
    Name(String),
    /// A script model's path, relative to the experiment file (`script = "m.rhai"`).
    Script(String),
}

impl ModelSource {
    /// The name or path, as the registry resolves it.
    pub fn spec(&self) -> &str {
        match self {
            ModelSource::Name(s) | ModelSource::Script(s) => s,
        }
    }
}

/// A parameter that follows a measured channel, as an entry gives it
/// (`F_y = { law = "affine", channel = "u_ctrl", base = 20.0, gain = 100.0 }`).
#[derive(Clone, Debug, PartialEq)]
pub struct LawGiven {
    /// How the parameter follows the channel.
    pub law: Law,
    /// The record's column it follows.
    pub channel: String,
    /// Starts of the law's coefficients, in [`Law::coefficients`]' order (`base`, `gain`,
    /// `exp`, those the law has); `None` keeps the law's default start.
    pub starts: Vec<Option<f64>>,
}

/// A parameter as an entry gives it: its name, what it sets and where.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamGiven {
    /// The parameter's name in the (summed) model.
    pub name: String,
    /// What is set; the rest keeps the model's default.
    pub set: ParamOverride,
    /// The law of a channel it follows, if any (then `set` is empty: its coefficients are
    /// parameters of their own).
    pub law: Option<LawGiven>,
    /// Line of the parameter in the file (1-based).
    pub line: usize,
}

/// A checked model entry, with where it stands in the file.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelEntry {
    /// The entry's first model.
    pub source: ModelSource,
    /// Further models added to it (`plus = ["added_mass"]`).
    pub plus: Vec<String>,
    /// The parameters given, by name.
    pub params: Vec<ParamGiven>,
    /// Line of the entry in the file (1-based).
    pub line: usize,
    /// Key path (`models[0]`, `simulate.truth[1]`).
    pub key: String,
}

impl ModelEntry {
    /// The names and paths of the entry's models, in order: its source, then `plus`.
    pub fn specs(&self) -> impl Iterator<Item = &str> {
        std::iter::once(self.source.spec()).chain(self.plus.iter().map(String::as_str))
    }
}

/// Check a list of entries whose key is `prefix` (`models`, `simulate.truth`).
pub(super) fn check(list: &[Spanned<RawModel>], prefix: &str, cx: &Ctx) -> Result<Vec<ModelEntry>> {
    if let Some(past) = list.get(MAX_MODELS) {
        let msg = format!(
            "{} `[[{prefix}]]` entries; a run takes at most {MAX_MODELS} (each is fitted, kept in \
             memory with its curves and written with its report: 2 000 took 1.6 GB and 1.8 GB \
             of output): split them across experiments, or run them as a campaign",
            list.len()
        );
        return Err(cx.at(past.span(), prefix, msg));
    }
    list.iter()
        .enumerate()
        .map(|(i, m)| entry(m, format!("{prefix}[{i}]"), cx))
        .collect()
}

/// The most entries of one list of models (`[[models]]`, `[[simulate.truth]]`): far more than
/// a comparison reads, few enough that a run's memory and output stay small.
pub const MAX_MODELS: usize = 100;

/// One entry: exactly one of `name` and `script`.
fn entry(m: &Spanned<RawModel>, key: String, cx: &Ctx) -> Result<ModelEntry> {
    let r = m.get_ref();
    let source = match (&r.name, &r.script) {
        (Some(_), Some(_)) => {
            return Err(cx.at(m.span(), &key, "give either `name` or `script`, not both"))
        }
        (None, None) => {
            return Err(cx.at(
                m.span(),
                &key,
                "a model needs `name` (a built-in) or `script` (a .rhai file)",
            ))
        }
        (Some(name), None) => ModelSource::Name(name.clone()),
        (None, Some(script)) => ModelSource::Script(script.clone()),
    };
    let params = r
        .params
        .iter()
        .map(|(name, v)| {
            let line = cx.line(v.span().start);
            let (set, law) = match v.get_ref() {
                RawParam::Value(value) => (
                    ParamOverride {
                        value: Some(*value),
                        ..ParamOverride::default()
                    },
                    None,
                ),
                RawParam::Table(t) => {
                    let key = format!("{key}.params.{name}");
                    (
                        table_setting(t),
                        law_of(t, name).map_err(|m| cx.at(v.span(), &key, m))?,
                    )
                }
            };
            Ok(ParamGiven {
                name: name.clone(),
                set,
                law,
                line,
            })
        })
        .collect::<Result<_>>()?;
    Ok(ModelEntry {
        source,
        plus: r.plus.clone(),
        params,
        line: cx.line(m.span().start),
        key,
    })
}

/// The `{ value, min, max, fixed }` part of a parameter's table.
fn table_setting(t: &RawTable) -> ParamOverride {
    ParamOverride {
        value: t.value,
        min: t.min,
        max: t.max,
        fixed: t.fixed,
    }
}

/// The law of a channel a parameter's table gives (`law` and `channel` together), checked:
/// a known law, no `value`/`min`/`max`/`fixed` beside it (its coefficients are parameters of
/// their own), only the coefficients the law has.
fn law_of(t: &RawTable, name: &str) -> std::result::Result<Option<LawGiven>, String> {
    let coefficients = [("base", t.base), ("gain", t.gain), ("exp", t.exp)];
    let (law, channel) = match (&t.law, &t.channel) {
        (None, None) => {
            return match coefficients.iter().find(|(_, v)| v.is_some()) {
                Some((k, _)) => Err(format!(
                    "`{k}` is a start of a law's coefficient: give the law too, e.g. \
                     `{name} = {{ law = \"affine\", channel = \"u_ctrl\", {k} = … }}`"
                )),
                None => Ok(None),
            }
        }
        (Some(_), None) => {
            return Err(format!(
                "a law needs the `channel` it follows (a column of the record): \
                 `{name} = {{ law = \"affine\", channel = \"u_ctrl\" }}`"
            ))
        }
        (None, Some(c)) => {
            return Err(format!(
                "following channel `{c}` needs a `law`: one of {}",
                law_names()
            ))
        }
        (Some(l), Some(c)) => (l, c),
    };
    let law = Law::named(law).ok_or_else(|| {
        format!(
            "unknown law `{law}`{}; the laws: {}",
            stf_core::names::did_you_mean(law, LAWS.iter().map(|l| l.name())),
            law_names()
        )
    })?;
    if let Some(k) = [
        ("value", t.value.is_some()),
        ("min", t.min.is_some()),
        ("max", t.max.is_some()),
        ("fixed", t.fixed.is_some()),
    ]
    .iter()
    .find_map(|(k, given)| given.then_some(k))
    {
        return Err(format!(
            "`{k}` does not go with a law: its coefficients are parameters of their own \
             (`{name}_base`, `{name}_gain`, …); set them there, e.g. `{name}_gain = {{ min = 0.0 }}`"
        ));
    }
    let has = law.coefficients();
    if let Some((k, _)) = coefficients
        .iter()
        .find(|(k, v)| v.is_some() && !has.contains(k))
    {
        return Err(format!(
            "the {} law has no `{k}`: its coefficients are {}",
            law.name(),
            has.join(", ")
        ));
    }
    if channel.trim().is_empty() {
        return Err("`channel` is empty: give the record's column it follows".into());
    }
    let starts = has
        .iter()
        .map(|k| {
            coefficients
                .iter()
                .find(|(c, _)| c == k)
                .and_then(|(_, v)| *v)
        })
        .collect();
    Ok(Some(LawGiven {
        law,
        channel: channel.clone(),
        starts,
    }))
}

/// Every law, in the order the docs list them.
const LAWS: [Law; 3] = [Law::Linear, Law::Affine, Law::Power];

/// The laws' names, quoted, for messages.
fn law_names() -> String {
    LAWS.iter()
        .map(|l| format!("`{}`", l.name()))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::parse_exp as parse;

    #[test]
    fn more_models_than_a_run_takes_are_refused_at_the_first_past_the_limit() {
        let entries = |n: usize| "[[models]]\nname = \"viscous\"\n".repeat(n);
        assert_eq!(
            parse(&entries(MAX_MODELS)).unwrap().models.len(),
            MAX_MODELS
        );
        let msg = parse(&entries(2000)).unwrap_err().to_string();
        assert!(
            msg.starts_with(&format!(
                "exp.toml:{}: `models`: 2000 `[[models]]` entries; a run takes at most 100",
                2 * MAX_MODELS + 1
            )),
            "{msg}"
        );
    }

    #[test]
    fn an_entry_is_checked_into_its_source_sum_and_parameters_with_their_lines() {
        let e = parse(
            "[[models]]\nname = \"power_law\"\nplus = [\"added_mass\"]\n\
             params = { K = 2.0, n = { value = 1.2, min = 1.0, fixed = true } }\n\
             [[models]]\nscript = \"m.rhai\"\n",
        )
        .unwrap();
        let m = &e.models[0];
        assert_eq!(m.source, ModelSource::Name("power_law".into()));
        assert_eq!(m.specs().collect::<Vec<_>>(), ["power_law", "added_mass"]);
        assert_eq!((m.line, m.key.as_str()), (1, "models[0]"));
        let n = ParamGiven {
            name: "n".into(),
            set: ParamOverride {
                value: Some(1.2),
                min: Some(1.0),
                max: None,
                fixed: Some(true),
            },
            law: None,
            line: 4,
        };
        assert_eq!(m.params[1], n);
        assert_eq!(
            (m.params[0].name.as_str(), m.params[0].set.value),
            ("K", Some(2.0))
        );
        let mut p = FitParam::new("n", 1.5).bounds(0.5, 3.0);
        n.set.apply(&mut p);
        assert_eq!(p, FitParam::new("n", 1.2).bounds(1.0, 3.0).fixed(true));
        m.params[0].set.apply(&mut p);
        assert_eq!(p, FitParam::new("n", 2.0).bounds(1.0, 3.0).fixed(true));
        assert_eq!(e.models[1].source, ModelSource::Script("m.rhai".into()));
        assert_eq!(
            (e.models[1].line, e.models[1].key.as_str()),
            (5, "models[1]")
        );
    }

    #[test]
    fn an_entry_with_both_or_neither_source_names_its_line_and_key() {
        for (text, says) in [
            (
                "[[models]]\nname = \"viscous\"\nscript = \"m.rhai\"\n",
                "not both",
            ),
            ("[[models]]\nplus = [\"viscous\"]\n", "needs `name`"),
        ] {
            let msg = format!("{:#}", parse(&format!("\n{text}")).unwrap_err());
            assert!(
                msg.starts_with("exp.toml:2: `models[0]`: ") && msg.contains(says),
                "{msg}"
            );
        }
        let msg = format!(
            "{:#}",
            parse("[simulate]\nfree = { t1 = 1.0 }\n[[simulate.truth]]\nscript = \"a\"\nname = \"b\"\n")
                .unwrap_err()
        );
        assert!(
            msg.starts_with("exp.toml:3: `simulate.truth[0]`: "),
            "{msg}"
        );
    }

    #[test]
    fn a_misspelled_key_inside_a_model_names_its_line() {
        let msg = format!(
            "{:#}",
            parse("[[models]]\nname = \"viscous\"\nparmas = { c_s = 1.0 }\n").unwrap_err()
        );
        assert!(
            msg.contains("exp.toml:3") && msg.contains("parmas"),
            "{msg}"
        );
    }
}
