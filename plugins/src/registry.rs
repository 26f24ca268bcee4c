//! The model registry: built-in models by name, script models by path.
//!
//! A spec ending in `.rhai` is a script path (relative paths are taken from a base directory,
//! usually the experiment file's); anything else is looked up in [`stf_models::BUILTINS`].
//! An unknown name is an error listing the known ones.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use stf_core::physics::force_model::ForceModel;
use stf_core::physics::param_spec::ParamSpec;

use crate::error::ScriptError;
use crate::limits::ScriptRun;
use crate::script_model::ScriptModel;

/// One model a user can pick.
#[derive(Clone, Debug)]
pub struct ModelListing {
    /// The name to write in an experiment file (a built-in's name or a script's path).
    pub name: String,
    /// One line saying what the model is.
    pub summary: String,
    /// The parameters.
    pub params: Vec<ParamSpec>,
    /// Whether the model is a script.
    pub is_script: bool,
}

/// Built-in models plus scripts from an optional directory.
#[derive(Clone, Debug, Default)]
pub struct Registry {
    script_dir: Option<PathBuf>,
    run: ScriptRun,
}

impl Registry {
    /// The built-in models only (scripts are still resolved by path).
    pub fn new() -> Self {
        Registry::default()
    }

    /// The built-in models; scripts load in `run` (its limits and operation budgets).
    pub fn in_run(run: ScriptRun) -> Self {
        Registry {
            run,
            ..Registry::default()
        }
    }

    /// The built-ins plus the `*.rhai` scripts of `dir` in listings.
    pub fn with_script_dir(dir: impl Into<PathBuf>) -> Self {
        Registry {
            script_dir: Some(dir.into()),
            ..Registry::default()
        }
    }

    /// The model named by `spec`: a built-in's name, or a path ending in `.rhai` (relative to
    /// `base_dir` unless absolute).
    pub fn resolve(&self, spec: &str, base_dir: &Path) -> Result<Arc<dyn ForceModel>, ScriptError> {
        let spec = spec.trim();
        if spec.ends_with(".rhai") {
            // `join` keeps an absolute path as it is.
            return Ok(Arc::new(ScriptModel::load_in(
                base_dir.join(spec),
                &self.run,
            )?));
        }
        stf_models::find(spec).ok_or_else(|| ScriptError::UnknownModel {
            name: spec.to_string(),
            did_you_mean: stf_core::names::did_you_mean(spec, stf_models::names()),
            known: stf_models::names().join(", "),
        })
    }

    /// The script model at `path` (relative to `base_dir` unless absolute), given as a script
    /// (`script = "…"`): a path that is a folder, or a file whose name does not end in
    /// `.rhai`, is named as such rather than looked up as a built-in's name.
    pub fn resolve_script(
        &self,
        path: &str,
        base_dir: &Path,
    ) -> Result<Arc<dyn ForceModel>, ScriptError> {
        let full = base_dir.join(path.trim());
        let not = |why: &str| ScriptError::NotAScript {
            path: full.display().to_string(),
            why: why.to_string(),
        };
        if full.is_dir() {
            return Err(not(
                "is a folder, not a script: give the path of a rhai script (a file ending in .rhai)",
            ));
        }
        if !path.trim().ends_with(".rhai") {
            return Err(not(if full.exists() {
                "is not a rhai script (its name does not end in .rhai): give a script's path, \
                 or `name = \"…\"` for a built-in model"
            } else {
                "no such file, and not a rhai script's name (a script's ends in .rhai)"
            }));
        }
        self.resolve(path, base_dir)
    }

    /// Every built-in model, then every script of the script directory (sorted by file name).
    /// A script that fails to load is listed with its error as summary and no parameters.
    pub fn list(&self) -> Vec<ModelListing> {
        let mut entries: Vec<ModelListing> = stf_models::BUILTINS
            .iter()
            .map(|b| ModelListing {
                name: b.name.to_string(),
                summary: b.summary.to_string(),
                params: (b.build)().params().to_vec(),
                is_script: false,
            })
            .collect();
        for path in self.scripts() {
            let (summary, params) = match ScriptModel::load(&path) {
                Ok(m) => (m.summary().to_string(), m.params().to_vec()),
                Err(e) => (format!("(does not load: {e})"), Vec::new()),
            };
            entries.push(ModelListing {
                name: path.display().to_string(),
                summary,
                params,
                is_script: true,
            });
        }
        entries
    }

    /// The `*.rhai` files of the script directory, sorted.
    pub fn scripts(&self) -> Vec<PathBuf> {
        let Some(Ok(read)) = self.script_dir.as_ref().map(std::fs::read_dir) else {
            return Vec::new();
        };
        let mut paths: Vec<PathBuf> = read
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "rhai"))
            .collect();
        paths.sort();
        paths
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn unknown_names_list_the_known_ones() {
        let err = Registry::new()
            .resolve("powr_law", Path::new("."))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(err.contains("powr_law"), "{err}");
        for name in stf_models::names() {
            assert!(err.contains(name), "{err}");
        }
    }

    #[test]
    fn absolute_script_paths_ignore_the_base_dir() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/scripts/power_law.rhai");
        let model = Registry::new()
            .resolve(path.to_str().unwrap(), Path::new("/no/such/dir"))
            .unwrap();
        assert_eq!(model.name(), "power_law");
    }

    #[test]
    fn builtins_are_listed_first() {
        let list = Registry::new().list();
        assert_eq!(list.len(), stf_models::BUILTINS.len());
        assert_eq!(list[0].name, stf_models::BUILTINS[0].name);
        assert!(!list[0].is_script);
    }
}
