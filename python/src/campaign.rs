//! A campaign from Python: `stf-lab campaign` in this process, one unit after another
//! ([`stf_lab::campaign::command::run_in_process`]: the same units' study calls and writers,
//! the same table, report and `[global]` fit), into its output folder, which is what a
//! campaign makes. The result is read back from that folder (`campaign.json`, and
//! `global.json` with a `[global]` section), so the Python result and the files are one.

use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use stf_study::error::{ErrorKind, StudyError};

use crate::errors::{of_kind, to_py};
use crate::run::run_interruptible;
use crate::watch::Watch;

/// `campaign.json` and (if there is one) `global.json` of the campaign folder `out`, as text.
fn tables(out: &Path) -> Result<(String, Option<String>), StudyError> {
    let read = |name: &str| std::fs::read_to_string(out.join(name));
    let campaign = read("campaign.json").map_err(|e| {
        of_kind(
            ErrorKind::Experiment,
            format!(
                "{}: cannot read the campaign's table: {e}",
                out.join("campaign.json").display()
            ),
        )
    })?;
    Ok((campaign, read("global.json").ok()))
}

/// `campaign(path, out, force=False, progress=None)`: run the campaign file `path` into the
/// folder `out` (units not finished only, all with `force`), then its table, report and
/// `[global]` fit; `(campaign.json, global.json or None)` as text. A failed unit fails the
/// call with the command line's message, after the table is written (read it with
/// `read_campaign`).
#[pyfunction]
#[pyo3(signature = (path, out, force=false, progress=None))]
pub fn campaign<'py>(
    py: Python<'py>,
    path: PathBuf,
    out: PathBuf,
    force: bool,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<(String, Option<String>)> {
    stf_lab::terminal::silence();
    run_interruptible(py, progress.as_ref(), move |run| {
        let watch = Watch::new(run);
        stf_lab::campaign::command::run_in_process(&path, &out, force, &watch)?;
        tables(&out)
    })
}

/// `read_campaign(out)`: the tables of a campaign folder written earlier (by Python or the
/// command line), as [`campaign`] returns them.
#[pyfunction]
pub fn read_campaign(py: Python<'_>, out: PathBuf) -> PyResult<(String, Option<String>)> {
    tables(&out).map_err(|e| to_py(py, &e))
}
