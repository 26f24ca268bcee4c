//! `stf-lab fit EXP.toml --out DIR`: calibrate every model of the experiment, or run the
//! oscillator identification stages of `[[identify]]`: the study's fit
//! ([`stf_study::fit`], [`stf_study::identify`]), its results folder written by
//! [`crate::results::fit`].

use std::path::Path;

use anyhow::Result;

use crate::experiment::Experiment;
use crate::fitting::estimate_line;
use crate::results;
use crate::say;
use crate::terminal::progress::Progress;
use crate::writing::results_dir::{wrote_line, ResultsDir};

/// Run `stf-lab fit` on an experiment loaded from its file: the results are built in a
/// staging folder and swapped in as a whole ([`ResultsDir`]).
pub fn run_experiment(mut exp: Experiment, out: &Path, force: bool, quiet: bool) -> Result<()> {
    let progress = Progress::new(quiet);
    let mut files = vec!["fit.json", "params.csv"];
    let results = if !exp.identify.is_empty() {
        let results = ResultsDir::begin(out, force)?;
        let found = stf_study::identify::identify(&exp, &progress)?;
        results::fit::write_identification(&exp, results.path(), &found)?;
        results
    } else {
        let inputs = stf_study::fit::load(&mut exp, &progress)?;
        let results = ResultsDir::begin(out, force)?;
        if let Some(line) = estimate_line(&inputs.data) {
            say!("{line}");
        }
        let fitted = inputs.fit(&exp, &progress)?;
        results::fit::write(&exp, &fitted, results.path())?;
        files.push("fitted.csv");
        results
    };
    results.commit()?;
    say!("{}", wrote_line(out, &files, exp.output.report));
    Ok(())
}
