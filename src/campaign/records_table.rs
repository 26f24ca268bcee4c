//! `records = "table.csv"` in `[campaign]`: the records as a CSV table instead of
//! `[[records]]` tables, read with the `csv` crate.
//!
//! ```text
//! file,F0,concentration,experiment
//! records/a1_c1.csv,0.035,0.36,trajectory_a1.toml
//! records/a2_c1.csv,0.0462,0.36,
//! ```
//!
//! The header names the columns: `file` (required), one per condition of
//! `campaign.conditions` (each required), and optionally `experiment` and `command` (an empty
//! cell takes `[campaign]`'s). Paths are relative to the campaign file, as in `[[records]]`.
//! Every error names the table, its line (the editor's, the header being line 1) and the
//! column: an unknown or missing column, a missing record, a condition that is not a finite
//! number, an unknown command. The table is read once, capped like the campaign file.

use std::path::{Path, PathBuf};

use anyhow::Result;
use serde::Deserialize;

use super::units::{CommandName, Unit, MAX_CAMPAIGN_BYTES, RECORD_KEYS};
use crate::experiment::error_at;

/// What `[campaign]` gives every row, and where paths resolve.
pub struct RowDefaults<'a> {
    /// `campaign.experiment` as written.
    pub experiment: Option<&'a str>,
    /// `campaign.command`.
    pub command: Option<CommandName>,
    /// The campaign file's folder.
    pub dir: &'a Path,
}

/// The units of the table at `table` (a path as resolved), in its rows' order.
pub fn read(table: &Path, conditions: &[String], defaults: &RowDefaults) -> Result<Vec<Unit>> {
    let text = stf_core::data::bounded::read_file_to_string(table, MAX_CAMPAIGN_BYTES)
        .map_err(|e| anyhow::anyhow!("cannot read the records table {}: {e}", table.display()))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let header: Vec<String> = reader
        .headers()
        .map_err(|e| csv_error(table, &e))?
        .iter()
        .map(str::to_string)
        .collect();
    let columns = Columns::of(&header, conditions, table)?;
    let mut units = Vec::new();
    for row in reader.records() {
        let row = row.map_err(|e| csv_error(table, &e))?;
        let place = Row {
            table,
            header: &header,
            cells: &row,
            line: row.position().map_or(0, |p| p.line() as usize),
        };
        units.push(unit(units.len() + 1, &place, &columns, defaults)?);
    }
    if units.is_empty() {
        return Err(error_at(
            table,
            1,
            "file",
            "no records: the table has a header only",
        ));
    }
    Ok(units)
}

/// Where each known column is.
struct Columns {
    file: usize,
    experiment: Option<usize>,
    command: Option<usize>,
    conditions: Vec<(String, usize)>,
}

impl Columns {
    /// The header checked: `file` and every condition present, no other column than those,
    /// `experiment` and `command`, none twice.
    fn of(header: &[String], conditions: &[String], table: &Path) -> Result<Columns> {
        for (i, name) in header.iter().enumerate() {
            if !RECORD_KEYS.contains(&name.as_str()) && !conditions.contains(name) {
                return Err(error_at(
                    table,
                    1,
                    name,
                    format!(
                        "column {} is neither a record column (file, experiment, command) nor a \
                         condition of `campaign.conditions` (now [{}])",
                        i + 1,
                        conditions.join(", ")
                    ),
                ));
            }
            if header[..i].contains(name) {
                return Err(error_at(
                    table,
                    1,
                    name,
                    format!("column {} repeats it", i + 1),
                ));
            }
        }
        let find = |name: &str| header.iter().position(|h| h == name);
        let missing = |name: &str, what: &str| {
            error_at(
                table,
                1,
                name,
                format!("missing column: the header needs {what}"),
            )
        };
        let file = find("file").ok_or_else(|| missing("file", "`file`, the records' paths"))?;
        let conditions = conditions
            .iter()
            .map(|c| {
                find(c)
                    .map(|i| (c.clone(), i))
                    .ok_or_else(|| missing(c, "a column per condition"))
            })
            .collect::<Result<_>>()?;
        Ok(Columns {
            file,
            experiment: find("experiment"),
            command: find("command"),
            conditions,
        })
    }
}

/// A row of the table and where it is.
struct Row<'a> {
    table: &'a Path,
    header: &'a [String],
    cells: &'a csv::StringRecord,
    line: usize,
}

impl Row<'_> {
    /// Column `c`'s cell (empty if the row is short).
    fn cell(&self, c: usize) -> &str {
        self.cells.get(c).unwrap_or("")
    }

    /// An error about column `c` of this row.
    fn error(&self, c: usize, msg: impl std::fmt::Display) -> anyhow::Error {
        error_at(self.table, self.line, &self.header[c], msg)
    }
}

/// Unit `number` from `row`.
fn unit(number: usize, row: &Row, columns: &Columns, defaults: &RowDefaults) -> Result<Unit> {
    let cell = |c: usize| row.cell(c);
    let at = |c: usize, msg: String| row.error(c, msg);
    let (line, table) = (row.line, row.table);
    let record_given = cell(columns.file).to_string();
    let record = defaults.dir.join(&record_given);
    let problem = if record_given.is_empty() {
        Some(format!("no such record: {}", record.display()))
    } else {
        stf_core::data::bounded::record_path_problem(&record)
    };
    if let Some(problem) = problem {
        return Err(at(columns.file, problem));
    }
    let given = |c: Option<usize>| c.map(cell).filter(|s| !s.is_empty());
    let experiment_given = match given(columns.experiment).or(defaults.experiment) {
        Some(e) => e.to_string(),
        None => {
            return Err(at(
                columns.file,
                "no experiment: give `campaign.experiment`, or an `experiment` column".into(),
            ))
        }
    };
    let command = match given(columns.command) {
        Some(c) => CommandName::deserialize(serde::de::value::StrDeserializer::<
            serde::de::value::Error,
        >::new(c))
        .map_err(|e| {
            let msg = crate::experiment::plain_words::plain(&e.to_string(), c);
            at(columns.command.unwrap_or(0), msg)
        })?,
        None => defaults.command.ok_or_else(|| {
            at(
                columns.file,
                "no command: give `campaign.command`, or a `command` column".into(),
            )
        })?,
    };
    let conditions = columns
        .conditions
        .iter()
        .map(|(name, c)| match cell(*c).parse::<f64>() {
            Ok(x) if x.is_finite() => Ok((name.clone(), x)),
            _ => Err(at(
                *c,
                format!("a condition is a finite number, found \"{}\"", cell(*c)),
            )),
        })
        .collect::<Result<_>>()?;
    Ok(Unit {
        number,
        experiment: defaults.dir.join(&experiment_given),
        experiment_given,
        record,
        record_given,
        command,
        conditions,
        line,
        origin: Some(PathBuf::from(table)),
    })
}

/// A CSV error (a row of the wrong length, bad UTF-8) with the table's name and line.
fn csv_error(table: &Path, e: &csv::Error) -> anyhow::Error {
    let line = e.position().map_or(0, |p| p.line() as usize);
    anyhow::anyhow!("{}:{line}: {e}", table.display())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `table` read in a folder with a record `r.csv`, conditions `c`, `d`.
    fn read_table(table: &str) -> Result<Vec<Unit>> {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("r.csv"), "t,phi,x\n0,0,0\n").unwrap();
        let path = dir.path().join("t.csv");
        std::fs::write(&path, table).unwrap();
        let defaults = RowDefaults {
            experiment: Some("e.toml"),
            command: Some(CommandName::Fit),
            dir: dir.path(),
        };
        read(&path, &["c".into(), "d".into()], &defaults)
    }

    fn message(table: &str) -> String {
        let e = format!("{:#}", read_table(table).unwrap_err());
        e.split_once("t.csv")
            .map_or(e.clone(), |(_, m)| m.to_string())
    }

    #[test]
    fn a_good_table_gives_one_unit_per_row() {
        let units =
            read_table("file, d ,c,command,experiment\nr.csv,2,1.5,,\nr.csv,3,-1,compare,o.toml\n")
                .unwrap();
        assert_eq!(units.len(), 2);
        assert_eq!(units[0].conditions, [("c".into(), 1.5), ("d".into(), 2.0)]);
        assert_eq!(
            (units[0].command, units[0].experiment_given.as_str()),
            (CommandName::Fit, "e.toml")
        );
        assert_eq!(
            (units[1].command, units[1].experiment_given.as_str()),
            (CommandName::Compare, "o.toml")
        );
        assert_eq!((units[1].number, units[1].line), (2, 3));
        assert!(units[1].origin.as_ref().unwrap().ends_with("t.csv"));
    }

    #[test]
    fn each_bad_cell_or_column_is_named_with_line_and_column() {
        assert_eq!(
            message("file,c,d\nr.csv,1,2\nr.csv,1,x\n"),
            ":3: `d`: a condition is a finite number, found \"x\""
        );
        assert_eq!(
            message("file,c,d\nr.csv,,2\n"),
            ":2: `c`: a condition is a finite number, found \"\""
        );
        assert!(message("file,c,d\nnone.csv,1,2\n").starts_with(":2: `file`: no such record: "));
        assert!(message("file,c,d,fill\nr.csv,1,2,3\n")
            .starts_with(":1: `fill`: column 4 is neither a record column"));
        assert_eq!(
            message("file,c\nr.csv,1\n"),
            ":1: `d`: missing column: the header needs a column per condition"
        );
        assert!(message("c,d\n1,2\n").starts_with(":1: `file`: missing column"));
        assert!(message("file,c,d,command\nr.csv,1,2,simulate\n")
            .starts_with(":2: `command`: unknown value `simulate`"));
        assert!(
            message("file,c,d\nr.csv,1\n").starts_with(":2: "),
            "{}",
            message("file,c,d\nr.csv,1\n")
        );
        assert!(message("file,c,d\n").starts_with(":1: `file`: no records"));
    }
}
