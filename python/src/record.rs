//! Records across the boundary: read from a file (CSV or `.mat`, laid out as an experiment's
//! `[data]` keys say), built from numpy arrays with units and a sample rate, and handed to
//! Python as a dict of numpy arrays that own the record's buffers (no copy: a `Vec<f64>`
//! becomes the array's memory).

use std::path::{Path, PathBuf};

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use stf_core::data::record::{Record, RecordError, Signal, Unit, MEMORY_SOURCE};
use stf_study::error::{ErrorKind, StudyError};

use crate::errors::{of_kind, to_py};

/// The record as a dict: `source`, and each signal of the data contract as a float64 array
/// (`None` where the record lacks it). The vectors move into the arrays.
pub fn record_dict(py: Python<'_>, r: Record) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("source", r.source)?;
    d.set_item("t", PyArray1::from_vec(py, r.t))?;
    d.set_item("x", PyArray1::from_vec(py, r.x))?;
    for (name, column) in [
        ("phi", r.phi),
        ("f_stf", r.f_stf),
        ("omega", r.omega),
        ("u", r.u),
    ] {
        match column {
            Some(v) => d.set_item(name, PyArray1::from_vec(py, v))?,
            None => d.set_item(name, py.None())?,
        }
    }
    Ok(d)
}

/// Read the record `file` with the layout of the experiment `layout` (an experiment file's
/// text holding a `[data]` section, paths relative to `dir`), or the data contract's.
pub fn read(file: &Path, layout: Option<(&Path, &str)>) -> Result<Record, StudyError> {
    let Some((exp_path, text)) = layout else {
        return stf_core::data::record::ReadOptions::default()
            .read(file)
            .map_err(|e| of_kind(ErrorKind::Record, e.to_string()));
    };
    let exp = crate::study_calls::experiment(exp_path, Some(text))?;
    stf_study::fitting::read_record(&exp, file).map_err(StudyError::from)
}

/// `read_record(path, layout_path=None, layout_text=None)`: the record at `path` (its type
/// by extension), laid out as the `[data]` keys of `layout_text` say (that text is an
/// experiment file's, shown in errors as `layout_path`).
#[pyfunction]
#[pyo3(signature = (path, layout_path=None, layout_text=None))]
pub fn read_record<'py>(
    py: Python<'py>,
    path: PathBuf,
    layout_path: Option<PathBuf>,
    layout_text: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let layout = layout_path.as_deref().zip(layout_text.as_deref());
    let record = py
        .detach(|| read(&path, layout))
        .map_err(|e| to_py(py, &e))?;
    record_dict(py, record)
}

/// One signal's values in SI: `values` in `unit` (the data contract's names: `mm`, `deg`,
/// `rpm`, `mN`, …; `V` with `gain`, `counts` with `per_rev`), scaled.
fn in_si(
    signal: Signal,
    values: PyReadonlyArray1<'_, f64>,
    unit: Option<&str>,
    gain: Option<f64>,
    per_rev: Option<f64>,
) -> Result<Vec<f64>, StudyError> {
    let scale = match unit {
        None => 1.0,
        Some(u) => Unit::parse(signal, u, gain, per_rev)
            .map_err(|e| {
                let msg = format!("units.{}: {e}", signal.name());
                of_kind(
                    ErrorKind::Record,
                    RecordError::new(MEMORY_SOURCE, msg).to_string(),
                )
            })?
            .scale(),
    };
    let v = values.as_array();
    Ok(v.iter().map(|x| x * scale).collect())
}

/// `record_from_arrays(columns, units, rate, t0, gains, per_rev)`: a record from numpy arrays
/// (float64; `t` or a sample `rate`, `x`, and `phi`, `f_stf`, `omega`, `u` as present), each
/// in the unit `units` gives it (SI otherwise), checked against the data contract.
#[pyfunction]
#[pyo3(signature = (columns, units=None, rate=None, t0=0.0, gains=None, per_rev=None))]
pub fn record_from_arrays<'py>(
    py: Python<'py>,
    columns: &Bound<'py, PyDict>,
    units: Option<&Bound<'py, PyDict>>,
    rate: Option<f64>,
    t0: f64,
    gains: Option<&Bound<'py, PyDict>>,
    per_rev: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let lookup =
        |d: Option<&Bound<'py, PyDict>>, key: &str| -> PyResult<Option<Bound<'py, PyAny>>> {
            match d {
                Some(d) => d.get_item(key),
                None => Ok(None),
            }
        };
    let mut signals: Vec<Option<Vec<f64>>> = Vec::new();
    for signal in Signal::ALL {
        let name = signal.name();
        let Some(values) = columns.get_item(name)? else {
            signals.push(None);
            continue;
        };
        let values: PyReadonlyArray1<'_, f64> = values.extract()?;
        let unit: Option<String> = lookup(units, name)?.map(|u| u.extract()).transpose()?;
        let gain: Option<f64> = lookup(gains, name)?.map(|g| g.extract()).transpose()?;
        let per_rev = (signal == Signal::Phi).then_some(per_rev).flatten();
        let si =
            in_si(signal, values, unit.as_deref(), gain, per_rev).map_err(|e| to_py(py, &e))?;
        signals.push(Some(si));
    }
    let record = build(signals, rate, t0).map_err(|e| to_py(py, &e))?;
    record_dict(py, record)
}

/// The record of the contract's `signals` (in [`Signal::ALL`]'s order), its time from `t` or
/// from `rate` and `t0`, validated.
fn build(mut s: Vec<Option<Vec<f64>>>, rate: Option<f64>, t0: f64) -> Result<Record, StudyError> {
    let fail = |msg: &str| {
        of_kind(
            ErrorKind::Record,
            RecordError::new(MEMORY_SOURCE, msg).to_string(),
        )
    };
    let mut take = |i: usize| s.get_mut(i).and_then(Option::take);
    let (t, x, phi, f_stf, omega, u) = (take(0), take(1), take(2), take(3), take(4), take(5));
    let x = x.ok_or_else(|| fail("no `x` column: a record needs the displacement"))?;
    let t = match (t, rate) {
        (Some(_), Some(_)) => return Err(fail("give `t` or a sample `rate`, not both")),
        (Some(t), None) => t,
        (None, Some(rate)) if rate.is_finite() && rate > 0.0 => {
            (0..x.len()).map(|i| t0 + i as f64 / rate).collect()
        }
        (None, Some(rate)) => {
            return Err(fail(&format!(
                "`rate` = {rate} must be a positive number of samples per second"
            )))
        }
        (None, None) => return Err(fail("no `t` column and no sample `rate`")),
    };
    let record = Record {
        source: MEMORY_SOURCE.to_string(),
        t,
        x,
        phi,
        f_stf,
        omega,
        u,
    };
    record
        .check()
        .map_err(|e| of_kind(ErrorKind::Record, e.to_string()))?;
    Ok(record)
}
