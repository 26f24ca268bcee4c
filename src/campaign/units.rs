//! A campaign's units as its file defines them: each record with its experiment, its
//! command and its conditions ([`Unit`]), the commands a unit may run, and the limits of the
//! file. The campaign file (`file.rs`), its records table (`records_table.rs`) and its
//! `[global]` section (`global_file.rs`) all build or read these.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::experiment::error_at;

/// The most bytes a campaign file may hold: 16 MiB (thousands of records).
pub const MAX_CAMPAIGN_BYTES: u64 = 16 << 20;

/// Record keys that are not conditions.
pub const RECORD_KEYS: [&str; 3] = ["file", "experiment", "command"];

/// The command a unit runs on its record.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq, Hash)]
#[serde(rename_all = "lowercase")]
pub enum CommandName {
    /// `stf-lab fit`.
    Fit,
    /// `stf-lab compare`.
    Compare,
    /// `stf-lab discover`.
    Discover,
}

impl CommandName {
    /// The command's name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            CommandName::Fit => "fit",
            CommandName::Compare => "compare",
            CommandName::Discover => "discover",
        }
    }
}

/// Unit N: record N, its experiment and its command.
#[derive(Clone, Debug, Serialize)]
pub struct Unit {
    /// 1-based number (`--unit N`).
    pub number: usize,
    /// The record as written in the campaign file.
    pub record_given: String,
    /// The record, resolved against the campaign file's folder.
    pub record: PathBuf,
    /// The experiment as written.
    pub experiment_given: String,
    /// The experiment, resolved.
    pub experiment: PathBuf,
    /// The command.
    pub command: CommandName,
    /// Each condition's value, in the order of `campaign.conditions`.
    pub conditions: Vec<(String, f64)>,
    /// Line of the record's entry in the campaign file (or its row in the records table).
    #[serde(skip)]
    pub line: usize,
    /// The records table the entry is a row of (`campaign.records`); `None`: a
    /// `[[records]]` table of the campaign file.
    #[serde(skip)]
    pub origin: Option<PathBuf>,
}

impl Unit {
    /// An error about this unit's entry, at its line: of the `campaign` file under `key`, or
    /// of the records table it is a row of, under `column`.
    pub fn entry_error(
        &self,
        campaign: &Path,
        key: &str,
        column: &str,
        msg: impl std::fmt::Display,
    ) -> anyhow::Error {
        match &self.origin {
            Some(table) => error_at(table, self.line, column, msg),
            None => error_at(campaign, self.line, key, msg),
        }
    }

    /// The unit's folder under `units/`: `NNN-<record stem>` (characters other than letters,
    /// digits, `-`, `_` and `.` become `_`).
    pub fn folder_name(&self) -> String {
        let stem = self
            .record
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let safe: String = stem
            .chars()
            .map(|c| {
                if c.is_alphanumeric() || matches!(c, '-' | '_' | '.') {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        format!("{:03}-{}", self.number, safe.trim_start_matches('.'))
    }
}
