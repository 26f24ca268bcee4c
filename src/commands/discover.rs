//! `stf-lab discover EXP.toml --out DIR`: find where the base model and the measurement
//! disagree, name the missing effect, add it, repeat, and show the gap shrink: the study's
//! discovery ([`stf_study::discover`]), its results folder written by
//! [`crate::results::discover`].

use std::path::Path;

use anyhow::Result;

use crate::experiment::Experiment;
use crate::fitting::estimate_line;
use crate::results;
use crate::say;
use crate::terminal::progress::Progress;
use crate::writing::results_dir::{wrote_line, ResultsDir};

/// Run `stf-lab discover` on an experiment loaded from its file: the results are built in a
/// staging folder and swapped in as a whole ([`ResultsDir`]).
pub fn run_experiment(mut exp: Experiment, out: &Path, force: bool, quiet: bool) -> Result<()> {
    let progress = Progress::new(quiet);
    let inputs = stf_study::discover::load(&mut exp, &progress)?;
    if let Some(line) = estimate_line(&inputs.data) {
        say!("{line}");
    }
    let results = ResultsDir::begin(out, force)?;
    let found = inputs.discover(&exp, &progress)?;
    results::discover::write(&exp, &found, results.path())?;
    results.commit()?;
    let files = ["discovery.json", "discovered.csv"];
    say!("{}", wrote_line(out, &files, exp.output.report));
    Ok(())
}
