//! The lab's figures for Python: drawn by the same code as the reports (`stf_lab::report`),
//! into a temporary folder, and handed back as the SVG and PNG bytes, so a notebook shows the
//! report's picture inline and a user may save it anywhere.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};
use stf_lab::report::{measured_vs_model, DISPLACEMENT_MM, STF_FORCE};

use crate::errors::other;

/// `measured_vs_fitted(level, t, measured, fitted)`: the report's "measured against each
/// fitted model" figure — the STF force (`level = "force"`, N) or the displacement
/// (`"trajectory"`, m, drawn in mm) — as a dict with `svg` (text) and `png` (bytes).
#[pyfunction]
pub fn measured_vs_fitted<'py>(
    py: Python<'py>,
    level: &str,
    t: PyReadonlyArray1<'py, f64>,
    measured: PyReadonlyArray1<'py, f64>,
    fitted: Vec<(String, PyReadonlyArray1<'py, f64>)>,
) -> PyResult<Bound<'py, PyDict>> {
    let (quantity, scale) = match level {
        "force" => (STF_FORCE, 1.0),
        "trajectory" => (DISPLACEMENT_MM, 1e3),
        unknown => {
            let msg =
                format!("level `{unknown}`: a figure is drawn at `force` or `trajectory` level");
            return Err(other(py, msg));
        }
    };
    let scaled = |a: &PyReadonlyArray1<'py, f64>| -> Vec<f64> {
        a.as_array().iter().map(|v| v * scale).collect()
    };
    let t: Vec<f64> = t.as_array().to_vec();
    let measured = scaled(&measured);
    let curves: Vec<(String, Vec<f64>)> =
        fitted.iter().map(|(l, a)| (l.clone(), scaled(a))).collect();
    let drawn = py.detach(|| -> anyhow::Result<(String, Vec<u8>)> {
        let dir = tempfile::tempdir()?;
        let refs: Vec<(&str, &[f64])> = curves
            .iter()
            .map(|(l, v)| (l.as_str(), v.as_slice()))
            .collect();
        let files = measured_vs_model(
            dir.path(),
            "measured_vs_fitted",
            quantity,
            &t,
            &measured,
            &refs,
        )?;
        Ok((
            std::fs::read_to_string(&files.svg)?,
            std::fs::read(&files.png)?,
        ))
    });
    let (svg, png) = drawn.map_err(|e| other(py, format!("cannot draw the figure: {e:#}")))?;
    let d = PyDict::new(py);
    d.set_item("svg", svg)?;
    d.set_item("png", PyBytes::new(py, &png))?;
    Ok(d)
}
