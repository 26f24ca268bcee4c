//! `stf-lab compare EXP.toml --out DIR`: fit every model, then compare them regime by regime:
//! the study's comparison ([`stf_study::compare`]), its results folder written by
//! [`crate::results::compare`].

use std::path::Path;

use anyhow::Result;

use crate::experiment::Experiment;
use crate::results;
use crate::say;
use crate::terminal::progress::Progress;
use crate::writing::results_dir::{wrote_line, ResultsDir};

/// Run `stf-lab compare` on an experiment loaded from its file: the results are built in a
/// staging folder and swapped in as a whole ([`ResultsDir`]).
pub fn run_experiment(mut exp: Experiment, out: &Path, force: bool, quiet: bool) -> Result<()> {
    let progress = Progress::new(quiet);
    let inputs = stf_study::compare::load(&mut exp, &progress)?;
    let results = ResultsDir::begin(out, force)?;
    let compared = inputs.compare(&exp, &progress)?;
    results::compare::write(&exp, &compared, results.path())?;
    results.commit()?;
    let files = ["compare.json", "compare.md", "compare.csv", "cycles.csv"];
    say!("{}", wrote_line(out, &files, exp.output.report));
    Ok(())
}
