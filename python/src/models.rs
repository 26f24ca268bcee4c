//! The model registry from Python: the built-in models and the scripts of a folder, each with
//! its summary and parameters (name, unit, default, bounds, doc), as `stf-lab models` lists
//! them; and one model resolved by name, sum (`a + b`) or script path, as in experiment files.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use stf_core::physics::force_model::ForceModel;
use stf_core::physics::model_sum::ModelSum;
use stf_core::physics::param_spec::ParamSpec;
use stf_plugins::registry::Registry;

use crate::errors::py_error;

/// A parameter as a dict.
fn param_dict<'py>(py: Python<'py>, p: &ParamSpec) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", &p.name)?;
    d.set_item("unit", &p.unit)?;
    d.set_item("default", p.default)?;
    d.set_item("min", p.min)?;
    d.set_item("max", p.max)?;
    d.set_item("doc", &p.doc)?;
    Ok(d)
}

/// A model as a dict: `name`, `summary`, `is_script`, `params`.
fn model_dict<'py>(
    py: Python<'py>,
    name: &str,
    summary: &str,
    is_script: bool,
    params: &[ParamSpec],
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("name", name)?;
    d.set_item("summary", summary)?;
    d.set_item("is_script", is_script)?;
    let list = PyList::empty(py);
    for p in params {
        list.append(param_dict(py, p)?)?;
    }
    d.set_item("params", list)?;
    Ok(d)
}

/// `list_models(script_dir=None)`: every built-in model, then every `*.rhai` script of
/// `script_dir` (a script that does not load is listed with its error as summary).
#[pyfunction]
#[pyo3(signature = (script_dir=None))]
pub fn list_models(py: Python<'_>, script_dir: Option<PathBuf>) -> PyResult<Bound<'_, PyList>> {
    let registry = script_dir.map_or_else(Registry::new, Registry::with_script_dir);
    let list = PyList::empty(py);
    for m in py.detach(|| registry.list()) {
        list.append(model_dict(py, &m.name, &m.summary, m.is_script, &m.params)?)?;
    }
    Ok(list)
}

/// `describe_model(spec, base_dir=".")`: the model a spec names — a built-in, a script path
/// (relative to `base_dir`) or a sum `a + b` — with its parameters as a fit sees them
/// (`model.param` where a bare name would be ambiguous). An unknown name is a `ModelError`
/// listing the known ones.
#[pyfunction]
#[pyo3(signature = (spec, base_dir=PathBuf::from(".")))]
pub fn describe_model<'py>(
    py: Python<'py>,
    spec: &str,
    base_dir: PathBuf,
) -> PyResult<Bound<'py, PyDict>> {
    let registry = Registry::new();
    let terms: Vec<&str> = spec.split('+').map(str::trim).collect();
    let model = py.detach(|| -> anyhow::Result<ModelSum> {
        if let Some(empty) = terms.iter().position(|t| t.is_empty()) {
            anyhow::bail!("model `{spec}`: term {} is empty", empty + 1);
        }
        let parts = terms
            .iter()
            .map(|t| registry.resolve(t, &base_dir))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(ModelSum::new(parts)?)
    });
    let model = model.map_err(|e| py_error(py, "ModelError", format!("{e:#}")))?;
    let is_script = terms.iter().any(|t| t.ends_with(".rhai"));
    let summary = match model.terms().len() {
        1 => stf_models::BUILTINS
            .iter()
            .find(|b| b.name == spec.trim())
            .map_or_else(String::new, |b| b.summary.to_string()),
        n => format!("a sum of {n} models"),
    };
    model_dict(py, model.name(), &summary, is_script, model.params())
}
