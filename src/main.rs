//! `stf-lab`: the command-line program of the shear-thickening fluid lab.
//!
//! ```text
//! stf-lab models                          list models with their parameters
//! stf-lab simulate EXP.toml --out F.csv   write a synthetic record (section [simulate])
//! ```

// `!(a > b)` is how this program says "not greater, or NaN": the NaN case is meant.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod cmd_models;
mod cmd_simulate;
mod experiment;
mod model_config;
mod output;
// Figures and reports; no command calls them yet (fit, compare and discover will): drop the
// allow then (unused_imports: its re-exports are unused until then too).
#[allow(dead_code, unused_imports)]
mod report;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// A lab for shear-thickening fluid force models: simulate, fit, compare, discover.
#[derive(Parser)]
#[command(name = "stf-lab", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the force models (built-in and scripts) with their parameters.
    Models,
    /// Write a synthetic record from the experiment's [simulate] section.
    Simulate {
        /// The experiment file.
        experiment: PathBuf,
        /// The record to write (CSV); a JSON sidecar is written beside it.
        #[arg(long)]
        out: PathBuf,
        /// Replace existing output files.
        #[arg(long)]
        force: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Models => cmd_models::list(),
        Command::Simulate {
            experiment,
            out,
            force,
        } => cmd_simulate::run(&experiment, &out, force),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
