//! Campaign files: the TOML of `stf-lab campaign`, parsed into a raw serde type and checked
//! into a trusted [`Campaign`], the house pattern of experiment files (`crate::experiment`).
//!
//! ```toml
//! [campaign]
//! experiment = "fit.toml"       # the work for every record (a record may name its own)
//! command = "fit"               # fit | compare | discover (a record may name its own)
//! conditions = ["amplitude", "concentration"]   # user-named columns, numbers
//!
//! [[records]]
//! file = "rec_a1_c1.csv"        # paths are relative to the campaign file
//! amplitude = 0.035
//! concentration = 0.40
//! ```
//!
//! Every error names the file, the line and the key (`campaign.toml:12: `records[2].file`:
//! …`), and everything is checked before any unit starts: each record exists, each condition
//! is a finite number on every record, each unit's experiment parses (its own errors name it)
//! and has what its command needs.
//! Two optional sections have files of their own: `[global]` (`super::global_file`) and
//! `[slurm]` (`super::slurm_file`: how `--slurm` cuts the units into jobs).

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::Deserialize;
use toml::Spanned;

use crate::experiment::{error_at, line_of, Ctx, Experiment};

use super::units::RECORD_KEYS;
pub use super::units::{CommandName, Unit, MAX_CAMPAIGN_BYTES};

/// `[campaign]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawHeader {
    experiment: Option<Spanned<String>>,
    command: Option<Spanned<CommandName>>,
    #[serde(default)]
    conditions: Vec<Spanned<String>>,
    #[serde(default)]
    units: BTreeMap<String, Spanned<String>>,
    records: Option<Spanned<String>>,
}

/// The whole file as written; a record is a table of any keys (its conditions are named by
/// the user), sorted out by [`check_record`].
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCampaign {
    campaign: Option<Spanned<RawHeader>>,
    #[serde(default)]
    records: Vec<RawRecord>,
    global: Option<Spanned<super::global_file::RawGlobal>>,
    slurm: Option<Spanned<super::slurm_file::RawSlurm>>,
}

/// A `[[records]]` table as written.
type RawRecord = Spanned<BTreeMap<String, Spanned<toml::Value>>>;

/// A checked campaign.
#[derive(Clone, Debug)]
pub struct Campaign {
    /// The campaign file.
    pub path: PathBuf,
    /// Condition names, in the order of `campaign.conditions`.
    pub conditions: Vec<String>,
    /// The unit of a condition, where `campaign.units` gives one (for the figures' axes).
    pub condition_units: BTreeMap<String, String>,
    /// One unit per record, in the file's order.
    pub units: Vec<Unit>,
    /// The joint fit of `[global]`, if any.
    pub global: Option<super::global_file::GlobalSpec>,
    /// How `--slurm` cuts the units into jobs (`[slurm]`; empty when absent).
    pub slurm: super::slurm_file::SlurmSpec,
}

/// The folder of the file at `path`, `.` for a bare name.
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

impl Campaign {
    /// Read and check a campaign file, with every unit's record and experiment.
    pub fn load(path: &Path) -> Result<Campaign> {
        let text = stf_core::data::bounded::read_file_to_string(path, MAX_CAMPAIGN_BYTES)
            .map_err(|e| anyhow::anyhow!("cannot read campaign file {}: {e}", path.display()))?;
        Self::parse(path, &text)
    }

    /// Check the text of a campaign file that lives at `path`.
    pub fn parse(path: &Path, text: &str) -> Result<Campaign> {
        let cx = Ctx::new(path, text);
        let raw: RawCampaign = toml::from_str(text).map_err(|e| cx.deserialize_error(&e))?;
        let Some(header) = raw.campaign else {
            return Err(error_at(path, 1, "campaign", "missing section [campaign]"));
        };
        let conditions = check_conditions(&header, path, text)?;
        let condition_units = check_units(&header, &conditions, path, text)?;
        let dir = folder_of(path);
        let defaults = Defaults {
            experiment: header.get_ref().experiment.as_ref(),
            command: header.get_ref().command.as_ref().map(|c| *c.get_ref()),
        };
        let place = Place { path, text, dir };
        let units = match &header.get_ref().records {
            Some(table) => table_units(table, &raw.records, &conditions, &defaults, &place)?,
            None => toml_units(&header, &raw.records, &conditions, &defaults, &place)?,
        };
        let experiments = check_experiments(&units, &place)?;
        check_parameter_clash(&header, &units, &experiments, &place)?;
        let default_experiment = defaults.experiment.map(|e| place.dir.join(e.get_ref()));
        let global = raw
            .global
            .as_ref()
            .map(|g| {
                let at = super::global_file::At { path, text };
                super::global_file::check(
                    g,
                    &conditions,
                    &units,
                    default_experiment.as_deref(),
                    &at,
                )
            })
            .transpose()?;
        let slurm = match &raw.slurm {
            Some(s) => super::slurm_file::check(s, path, text)?,
            None => Default::default(),
        };
        Ok(Campaign {
            path: path.to_path_buf(),
            conditions,
            condition_units,
            units,
            global,
            slurm,
        })
    }

    /// Unit `number` (1-based), or an error saying how many there are.
    pub fn unit(&self, number: usize) -> Result<&Unit> {
        match number.checked_sub(1).and_then(|i| self.units.get(i)) {
            Some(u) => Ok(u),
            None => anyhow::bail!(
                "{}: no unit {number}: the campaign has units 1 to {}",
                self.path.display(),
                self.units.len()
            ),
        }
    }
}

/// The units of `[[records]]` tables.
fn toml_units(
    header: &Spanned<RawHeader>,
    records: &[RawRecord],
    conditions: &[String],
    defaults: &Defaults,
    place: &Place,
) -> Result<Vec<Unit>> {
    if records.is_empty() {
        return Err(place.error(
            header.span().start,
            "records",
            "no records: add a [[records]] table with `file` for each, or `campaign.records = \
             \"table.csv\"`",
        ));
    }
    records
        .iter()
        .enumerate()
        .map(|(i, r)| check_record(i, r, conditions, defaults, place))
        .collect()
}

/// The units of the records table `campaign.records` (no `[[records]]` beside it).
fn table_units(
    table: &Spanned<String>,
    records: &[RawRecord],
    conditions: &[String],
    defaults: &Defaults,
    place: &Place,
) -> Result<Vec<Unit>> {
    let here = || {
        format!(
            "{}:{}: `campaign.records`",
            place.path.display(),
            line_of(place.text, table.span().start)
        )
    };
    if let Some(first) = records.first() {
        return Err(place.error(
            first.span().start,
            "records[0]",
            format!(
                "both `campaign.records = \"{}\"` and [[records]] tables: give the records one \
                 way",
                table.get_ref()
            ),
        ));
    }
    let row_defaults = super::records_table::RowDefaults {
        experiment: defaults.experiment.map(|e| e.get_ref().as_str()),
        command: defaults.command,
        dir: &place.dir,
    };
    super::records_table::read(&place.dir.join(table.get_ref()), conditions, &row_defaults)
        .with_context(here)
}

/// `campaign.conditions`, checked: names unique and not a record key.
fn check_conditions(header: &Spanned<RawHeader>, path: &Path, text: &str) -> Result<Vec<String>> {
    let mut names = Vec::new();
    for (i, c) in header.get_ref().conditions.iter().enumerate() {
        let name = c.get_ref().trim().to_string();
        let at = |msg: &str| {
            error_at(
                path,
                line_of(text, c.span().start),
                &format!("campaign.conditions[{i}]"),
                msg,
            )
        };
        if name.is_empty() {
            return Err(at("an empty condition name"));
        }
        if RECORD_KEYS.contains(&name.as_str()) {
            return Err(at(&format!(
                "`{name}` is a record key, not a condition: choose another name"
            )));
        }
        if let Some(clash) = super::condition_names::fixed_clash(&name) {
            return Err(at(&clash));
        }
        if names.contains(&name) {
            return Err(at(&format!("`{name}` is listed twice")));
        }
        names.push(name);
    }
    Ok(names)
}

/// `campaign.units`, checked: each key a listed condition, each unit a non-empty string.
fn check_units(
    header: &Spanned<RawHeader>,
    conditions: &[String],
    path: &Path,
    text: &str,
) -> Result<BTreeMap<String, String>> {
    let mut out = BTreeMap::new();
    for (name, unit) in &header.get_ref().units {
        let at = |msg: String| {
            error_at(
                path,
                line_of(text, unit.span().start),
                &format!("campaign.units.{name}"),
                msg,
            )
        };
        if !conditions.contains(name) {
            return Err(at(format!(
                "`{name}` is not a condition: `campaign.conditions` lists [{}]",
                conditions.join(", ")
            )));
        }
        let unit = unit.get_ref().trim();
        if unit.is_empty() {
            return Err(at(
                "an empty unit: leave the condition out of `units`".into()
            ));
        }
        out.insert(name.clone(), unit.to_string());
    }
    Ok(out)
}

/// What `[campaign]` gives every record.
struct Defaults<'a> {
    experiment: Option<&'a Spanned<String>>,
    command: Option<CommandName>,
}

/// Where errors point and paths resolve.
struct Place<'a> {
    path: &'a Path,
    text: &'a str,
    dir: PathBuf,
}

impl Place<'_> {
    fn error(&self, offset: usize, key: &str, msg: impl std::fmt::Display) -> anyhow::Error {
        error_at(self.path, line_of(self.text, offset), key, msg)
    }
}

/// Record `i` checked into unit `i + 1`.
fn check_record(
    i: usize,
    raw: &RawRecord,
    conditions: &[String],
    defaults: &Defaults,
    place: &Place,
) -> Result<Unit> {
    let key = format!("records[{i}]");
    let table = raw.get_ref();
    let start = raw.span().start;
    let string = |name: &str| -> Result<Option<(String, usize)>> {
        match table.get(name) {
            None => Ok(None),
            Some(v) => match v.get_ref() {
                toml::Value::String(s) => Ok(Some((s.clone(), v.span().start))),
                other => Err(place.error(
                    v.span().start,
                    &format!("{key}.{name}"),
                    format!("expected a string, found {}", other.type_str()),
                )),
            },
        }
    };
    let Some((record_given, record_at)) = string("file")? else {
        return Err(place.error(start, &key, "missing `file`: the record's path"));
    };
    let record = place.dir.join(&record_given);
    if let Some(problem) = stf_core::data::bounded::record_path_problem(&record) {
        return Err(place.error(record_at, &format!("{key}.file"), problem));
    }
    let (experiment_given, _) = match string("experiment")? {
        Some(e) => e,
        None => match defaults.experiment {
            Some(e) => (e.get_ref().clone(), e.span().start),
            None => {
                return Err(place.error(
                    start,
                    &key,
                    "no experiment: give `campaign.experiment`, or `experiment` on the record",
                ))
            }
        },
    };
    let command = record_command(table, &key, defaults, place, start)?;
    let values = record_conditions(table, &key, conditions, place, start)?;
    Ok(Unit {
        number: i + 1,
        experiment: place.dir.join(&experiment_given),
        experiment_given,
        record,
        record_given,
        command,
        conditions: values,
        line: line_of(place.text, start),
        origin: None,
    })
}

/// The record's `command`, else the campaign's.
fn record_command(
    table: &BTreeMap<String, Spanned<toml::Value>>,
    key: &str,
    defaults: &Defaults,
    place: &Place,
    start: usize,
) -> Result<CommandName> {
    match table.get("command") {
        Some(v) => CommandName::deserialize(v.get_ref().clone()).map_err(|e| {
            let written = v.get_ref().to_string();
            place.error(
                v.span().start,
                &format!("{key}.command"),
                crate::experiment::plain_words::plain(e.message().trim_end(), &written),
            )
        }),
        None => defaults.command.ok_or_else(|| {
            place.error(
                start,
                key,
                "no command: give `campaign.command` (fit, compare or discover), or `command` on \
                 the record",
            )
        }),
    }
}

/// The record's condition values, in the order of `conditions`; a key that is neither a
/// record key nor a condition is refused (a misspelled condition must not go unnoticed).
fn record_conditions(
    table: &BTreeMap<String, Spanned<toml::Value>>,
    key: &str,
    conditions: &[String],
    place: &Place,
    start: usize,
) -> Result<Vec<(String, f64)>> {
    for (name, v) in table {
        if !RECORD_KEYS.contains(&name.as_str()) && !conditions.contains(name) {
            return Err(place.error(
                v.span().start,
                &format!("{key}.{name}"),
                format!(
                    "not a condition: list it in `campaign.conditions` (now [{}])",
                    conditions.join(", ")
                ),
            ));
        }
    }
    conditions
        .iter()
        .map(|name| {
            let Some(v) = table.get(name) else {
                return Err(place.error(
                    start,
                    key,
                    format!("missing condition `{name}`: every record gives every condition"),
                ));
            };
            let number = match v.get_ref() {
                toml::Value::Float(x) => Some(*x),
                toml::Value::Integer(n) => Some(*n as f64),
                _ => None,
            };
            match number {
                Some(x) if x.is_finite() => Ok((name.clone(), x)),
                _ => Err(place.error(
                    v.span().start,
                    &format!("{key}.{name}"),
                    format!(
                        "a condition is a finite number, found {}",
                        describe(v.get_ref())
                    ),
                )),
            }
        })
        .collect()
}

/// A value as the user wrote it, for an error.
fn describe(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => format!("the string \"{s}\""),
        toml::Value::Float(x) => format!("{x}"),
        other => format!("a {}", other.type_str()),
    }
}

/// Every unit's experiment parsed once (each file once), and checked for what its command
/// needs; an error names the campaign's line and key, then the experiment's own.
fn check_experiments<'u>(
    units: &'u [Unit],
    place: &Place,
) -> Result<HashMap<&'u Path, Experiment>> {
    let mut parsed: HashMap<&Path, Experiment> = HashMap::new();
    for (i, unit) in units.iter().enumerate() {
        let key = format!("records[{i}]");
        let at = |msg: String| unit.entry_error(place.path, &key, "experiment", msg);
        if !parsed.contains_key(unit.experiment.as_path()) {
            if !unit.experiment.is_file() {
                return Err(at(format!(
                    "no such experiment: {}",
                    unit.experiment.display()
                )));
            }
            let exp = Experiment::load(&unit.experiment).map_err(|e| {
                let at = unit.entry_error(
                    place.path,
                    &key,
                    "experiment",
                    format!(
                        "the experiment {} does not parse",
                        unit.experiment.display()
                    ),
                );
                e.context(at.to_string())
            })?;
            parsed.insert(&unit.experiment, exp);
        }
        let exp = &parsed[unit.experiment.as_path()];
        if unit.command == CommandName::Discover && exp.discover.is_none() {
            return Err(at(format!(
                "`discover` needs a [discover] section (base = \"…\") in {}",
                unit.experiment.display()
            )));
        }
    }
    Ok(parsed)
}

/// No condition is named as a parameter some unit may write as a column of `campaign.csv`
/// (`super::condition_names`): the error names the condition, the parameter's model and the
/// experiment.
fn check_parameter_clash(
    header: &Spanned<RawHeader>,
    units: &[Unit],
    experiments: &HashMap<&Path, Experiment>,
    place: &Place,
) -> Result<()> {
    let mut seen = std::collections::HashSet::new();
    for unit in units {
        if !seen.insert((unit.experiment.as_path(), unit.command)) {
            continue;
        }
        let exp = &experiments[unit.experiment.as_path()];
        let columns =
            super::condition_names::parameter_columns(exp, unit.command == CommandName::Discover);
        for (i, c) in header.get_ref().conditions.iter().enumerate() {
            let name = c.get_ref().trim();
            if let Some(what) = columns.get(name) {
                return Err(error_at(
                    place.path,
                    line_of(place.text, c.span().start),
                    &format!("campaign.conditions[{i}]"),
                    format!(
                        "`{name}` is {what} in {}: campaign.csv has a column of that name for \
                         it, and a condition of that name would make a second one; choose \
                         another name (e.g. `{name}_condition`)",
                        unit.experiment.display()
                    ),
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A folder with a record `r.csv` and an experiment `e.toml`; the campaign's text parsed
    /// as `c.toml` in it.
    fn parse(text: &str) -> Result<Campaign> {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("r.csv"), "t,phi,x\n0,0,0\n").unwrap();
        std::fs::write(
            dir.path().join("e.toml"),
            "[[models]]\nname = \"power_law\"\n",
        )
        .unwrap();
        Campaign::parse(&dir.path().join("c.toml"), text)
    }

    fn message(text: &str) -> String {
        let e = format!("{:#}", parse(text).unwrap_err());
        e.split_once("c.toml")
            .map_or(e.clone(), |(_, m)| m.to_string())
    }

    const HEAD: &str =
        "[campaign]\nexperiment = \"e.toml\"\ncommand = \"fit\"\nconditions = [\"c\"]\n";

    #[test]
    fn a_record_takes_the_campaign_s_work_and_may_name_its_own() {
        let c = parse(&format!(
            "{HEAD}\n[[records]]\nfile = \"r.csv\"\nc = 1\n\n[[records]]\nfile = \"r.csv\"\nc = 2.5\ncommand = \"compare\"\n"
        ))
        .unwrap();
        assert_eq!(c.units.len(), 2);
        assert_eq!(c.units[0].command, CommandName::Fit);
        assert_eq!(c.units[1].command, CommandName::Compare);
        assert_eq!(c.units[1].conditions, vec![("c".to_string(), 2.5)]);
        assert_eq!((c.units[0].line, c.units[1].line), (6, 10));
        assert_eq!(c.units[1].folder_name(), "002-r");
        assert!(c.condition_units.is_empty());
        let with_unit = HEAD.replace("c\"]", "c\"]\nunits = { c = \"kg·m\" }");
        let c = parse(&format!(
            "{with_unit}\n[[records]]\nfile = \"r.csv\"\nc = 1\n"
        ))
        .unwrap();
        assert_eq!(c.condition_units["c"], "kg·m");
        assert!(c.unit(3).is_err() && c.unit(0).is_err());
    }

    #[test]
    fn each_bad_record_is_named_with_line_and_key() {
        let rec = |body: &str| format!("{HEAD}\n[[records]]\n{body}");
        assert_eq!(
            message(&rec("file = \"r.csv\"\n")),
            ":6: `records[0]`: missing condition `c`: every record gives every condition"
        );
        assert!(message(&rec("file = \"r.csv\"\nc = 1\nd = 2\n"))
            .starts_with(":9: `records[0].d`: not a condition: list it in `campaign.conditions`"));
        assert_eq!(
            message(&rec("c = 1\n")),
            ":6: `records[0]`: missing `file`: the record's path"
        );
        assert_eq!(
            message(&rec("file = \"r.csv\"\nc = nan\n")),
            ":8: `records[0].c`: a condition is a finite number, found NaN"
        );
        assert!(
            message(&rec("file = \"r.csv\"\nc = 1\ncommand = \"simulate\"\n"))
                .starts_with(":9: `records[0].command`: unknown value `simulate`")
        );
        let m = message(&rec(
            "file = \"r.csv\"\nc = 1\nexperiment = \"none.toml\"\n",
        ));
        assert!(
            m.starts_with(":6: `records[0]`: no such experiment: ") && m.ends_with("none.toml"),
            "{m}"
        );
    }

    #[test]
    fn records_may_come_from_a_table_but_not_both_ways_at_once() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("r.csv"), "t,phi,x\n0,0,0\n").unwrap();
        std::fs::write(
            dir.path().join("e.toml"),
            "[[models]]\nname = \"power_law\"\n",
        )
        .unwrap();
        std::fs::write(dir.path().join("t.csv"), "file,c\nr.csv,1\nr.csv,2\n").unwrap();
        let path = dir.path().join("c.toml");
        let head = format!("{HEAD}records = \"t.csv\"\n");
        let c = Campaign::parse(&path, &head).unwrap();
        assert_eq!(c.units.len(), 2);
        assert_eq!(c.units[1].conditions, [("c".to_string(), 2.0)]);
        let both = format!("{head}\n[[records]]\nfile = \"r.csv\"\nc = 1\n");
        let e = format!("{:#}", Campaign::parse(&path, &both).unwrap_err());
        assert!(
            e.contains(
                "c.toml:7: `records[0]`: both `campaign.records = \"t.csv\"` and [[records]]"
            ),
            "{e}"
        );
        std::fs::write(dir.path().join("t.csv"), "file,c\nr.csv,1\nr.csv,two\n").unwrap();
        let e = format!("{:#}", Campaign::parse(&path, &head).unwrap_err());
        assert!(e.contains("c.toml:5: `campaign.records`: "), "{e}");
        assert!(
            e.contains("t.csv:3: `c`: a condition is a finite number, found \"two\""),
            "{e}"
        );
        // A row's experiment that does not exist is named at the table's line and column.
        std::fs::write(
            dir.path().join("t.csv"),
            "file,c,experiment\nr.csv,1,none.toml\n",
        )
        .unwrap();
        let e = format!("{:#}", Campaign::parse(&path, &head).unwrap_err());
        assert!(
            e.contains("t.csv:2: `experiment`: no such experiment"),
            "{e}"
        );
        let e = format!(
            "{:#}",
            Campaign::parse(&path, &HEAD.replace("c\"]", "c\"]\nrecords = \"none.csv\""))
                .unwrap_err()
        );
        assert!(
            e.contains("cannot read the records table") && e.contains("none.csv"),
            "{e}"
        );
    }

    #[test]
    fn the_header_is_checked_too() {
        assert_eq!(
            message("[[records]]\nfile = \"r.csv\"\n"),
            ":1: `campaign`: missing section [campaign]"
        );
        assert!(message(HEAD).starts_with(":1: `records`: no records"));
        assert!(message("[campaign]\nconditions = [\"file\"]\n")
            .starts_with(":2: `campaign.conditions[0]`: `file` is a record key"));
        assert!(message("[campaign]\nconditions = [\"a\", \"a\"]\n")
            .starts_with(":2: `campaign.conditions[1]`: `a` is listed twice"));
        let no_work = "[campaign]\n\n[[records]]\nfile = \"r.csv\"\n";
        assert!(message(no_work).starts_with(":3: `records[0]`: no experiment"));
        assert!(
            message("[campaign]\nconditions = [\"a\"]\nunits = { b = \"m\" }\n")
                .starts_with(":3: `campaign.units.b`: `b` is not a condition")
        );
        assert!(
            message("[campaign]\nconditions = [\"a\"]\nunits = { a = \" \" }\n")
                .starts_with(":3: `campaign.units.a`: an empty unit")
        );
        assert!(message("[campaign]\nexperimnt = \"e.toml\"\n")
            .starts_with(":2: `campaign`: unknown key `experimnt`"));
    }
}
