//! Campaigns: many records, one command (`stf-lab campaign CAMPAIGN.toml --out DIR`). A
//! campaign file ([`file`]) lists records (or names a CSV table of them, [`records_table`]) with their conditions and the work for each; unit N
//! is (record N, its experiment, its command), run into `DIR/units/<NNN>-<stem>/` by
//! [`unit`] — in a child process of the local [`runner`], or a Slurm array task ([`slurm`],
//! [`slurm_script`]) — and recognised as finished by the hash of its inputs ([`hash`]). After the units, the
//! [`table`] (`campaign.csv`, `campaign.json`: a row per record × model) and the
//! [`report`] are built from the units' JSON ([`unit_results`]). The output folder's rules
//! are in [`out_dir`]; [`command`] runs it all. A `[global]` section
//! ([`global_file`]) adds a joint fit of all records with shared and law parameters
//! (the study's `stf_study::joint`), compared with per-record fits ([`global`] writes `DIR/global.json`) and
//! shown first in the report ([`global_report`]).

pub mod command;
pub mod condition_names;
pub mod csv_columns;
pub mod figure_series;
pub mod file;
pub mod global;
pub mod global_file;
pub mod global_report;
pub mod hash;
pub mod labels;
pub mod out_dir;
pub mod records_table;
pub mod report;
pub mod runner;
pub mod slurm;
pub mod slurm_file;
pub mod slurm_plan;
pub mod slurm_script;
pub mod table;
pub mod unit;
pub mod unit_results;
pub mod units;

pub use file::{Campaign, CommandName, Unit};
