//! `stf_lab._stf_lab`: the Rust half of the `stf_lab` Python package (the pure-Python layer
//! in `python/stf_lab/` wraps it in result classes). It converts at the boundary only —
//! numpy arrays in and out ([`record`]), the command line's JSON as text, errors as the
//! exceptions of `stf_lab._errors` ([`errors`]) — and runs long work off the GIL with Ctrl-C
//! honoured ([`run`]; the study's observer is [`watch`]). The workflows themselves — the study
//! layer's `stf_study::prelude` — are called from one file, [`study_calls`]; the report's
//! figures come from the program crate ([`figures`]), and so does a campaign, run in process
//! into its folder ([`campaign`]).

use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

pub mod campaign;
pub mod errors;
pub mod figures;
pub mod models;
pub mod record;
pub mod run;
pub mod study_calls;
pub mod watch;

use run::run_interruptible;
use study_calls::Outcome;

/// A workflow's outcome as a dict: `json` (text), `verdict`, `params_table` and
/// `regimes_table` (JSON text), `best`, `level`, `warnings`, `entries`, and the arrays `t`,
/// `measured` and `curves` (a list of `(label, array)`), moved into numpy.
fn outcome_dict(py: Python<'_>, o: Outcome) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("json", o.json)?;
    d.set_item("verdict", o.verdict)?;
    d.set_item("params_table", o.params_table)?;
    d.set_item("regimes_table", o.regimes_table)?;
    d.set_item("best", o.best)?;
    d.set_item("level", o.level)?;
    d.set_item("warnings", o.warnings)?;
    d.set_item("entries", o.entries)?;
    d.set_item("t", PyArray1::from_vec(py, o.t))?;
    d.set_item("measured", PyArray1::from_vec(py, o.measured))?;
    let curves = PyList::empty(py);
    for (label, values) in o.curves {
        curves.append((label, PyArray1::from_vec(py, values)))?;
    }
    d.set_item("curves", curves)?;
    Ok(d)
}

/// Run `workflow` on the experiment `path` (or `text`) off the GIL, Ctrl-C honoured.
fn workflow<'py>(
    py: Python<'py>,
    (path, text): (PathBuf, Option<String>),
    progress: Option<Bound<'py, PyAny>>,
    workflow: fn(
        stf_study::experiment::Experiment,
        &run::Run,
    ) -> Result<Outcome, stf_study::error::StudyError>,
) -> PyResult<Bound<'py, PyDict>> {
    let o = run_interruptible(py, progress.as_ref(), move |run| {
        workflow(study_calls::experiment(&path, text.as_deref())?, run)
    })?;
    outcome_dict(py, o)
}

/// `check_experiment(path, text=None)`: read and validate the experiment (from its file, or
/// `text` shown as `path`); `ExperimentError` with the file, line and key if it is not valid.
#[pyfunction]
#[pyo3(signature = (path, text=None))]
fn check_experiment(py: Python<'_>, path: PathBuf, text: Option<String>) -> PyResult<()> {
    py.detach(|| study_calls::experiment(&path, text.as_deref()).map(|_| ()))
        .map_err(|e| errors::to_py(py, &e))
}

/// `fit(path, text=None, progress=None)`: `stf-lab fit` in process, nothing written.
#[pyfunction]
#[pyo3(signature = (path, text=None, progress=None))]
fn fit<'py>(
    py: Python<'py>,
    path: PathBuf,
    text: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    workflow(py, (path, text), progress, study_calls::fit)
}

/// `compare(path, text=None, progress=None)`: `stf-lab compare` in process, nothing written.
#[pyfunction]
#[pyo3(signature = (path, text=None, progress=None))]
fn compare<'py>(
    py: Python<'py>,
    path: PathBuf,
    text: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    workflow(py, (path, text), progress, study_calls::compare)
}

/// `identify(path, text=None, progress=None)`: the `[[identify]]` stages of `stf-lab fit`.
#[pyfunction]
#[pyo3(signature = (path, text=None, progress=None))]
fn identify<'py>(
    py: Python<'py>,
    path: PathBuf,
    text: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    workflow(py, (path, text), progress, study_calls::identify)
}

/// `discover(path, text=None, progress=None)`: `stf-lab discover` in process, nothing
/// written.
#[pyfunction]
#[pyo3(signature = (path, text=None, progress=None))]
fn discover<'py>(
    py: Python<'py>,
    path: PathBuf,
    text: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    workflow(py, (path, text), progress, study_calls::discover)
}

/// `simulate(path, text=None, progress=None)`: the record of the experiment's `[simulate]`
/// section, as a dict of numpy arrays with the run's `summary` (JSON text), as `stf-lab
/// simulate` makes them, without its files.
#[pyfunction]
#[pyo3(signature = (path, text=None, progress=None))]
fn simulate<'py>(
    py: Python<'py>,
    path: PathBuf,
    text: Option<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (record, summary) = run_interruptible(py, progress.as_ref(), move |run| {
        study_calls::simulate(study_calls::experiment(&path, text.as_deref())?, run)
    })?;
    let d = record::record_dict(py, record)?;
    d.set_item("summary", summary)?;
    Ok(d)
}

/// The module.
#[pymodule]
fn _stf_lab(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(check_experiment, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add_function(wrap_pyfunction!(discover, m)?)?;
    m.add_function(wrap_pyfunction!(record::read_record, m)?)?;
    m.add_function(wrap_pyfunction!(record::record_from_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(models::list_models, m)?)?;
    m.add_function(wrap_pyfunction!(models::describe_model, m)?)?;
    m.add_function(wrap_pyfunction!(figures::measured_vs_fitted, m)?)?;
    m.add_function(wrap_pyfunction!(campaign::campaign, m)?)?;
    m.add_function(wrap_pyfunction!(campaign::read_campaign, m)?)?;
    Ok(())
}
