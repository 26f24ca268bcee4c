//! `stf-lab models`: list the models (built-ins and the scripts of `models/scripts`) with
//! their parameters; `--check SCRIPT` checks one script.

use std::path::{Path, PathBuf};

use anyhow::Result;
use stf_core::physics::force_model::ForceModel;
use stf_core::physics::param_spec::ParamSpec;
use stf_plugins::registry::Registry;
use stf_plugins::ScriptModel;

fn print_params(params: &[ParamSpec]) {
    for p in params {
        crate::say!(
            "    {:<10} {:>10} [{}, {}] {:<14} {}",
            p.name,
            p.default,
            p.min,
            p.max,
            p.unit,
            p.doc
        );
    }
}

/// Print every model with its parameters and one line of doc; scripts are looked for in
/// `script_dir` (default `models/scripts` when it exists).
pub fn list(script_dir: Option<&Path>) -> Result<()> {
    let default_dir = PathBuf::from("models/scripts");
    let dir = script_dir.or_else(|| default_dir.is_dir().then_some(default_dir.as_path()));
    let registry = dir.map_or_else(Registry::new, Registry::with_script_dir);
    for entry in registry.list() {
        crate::say!(
            "{}{}  —  {}",
            entry.name,
            if entry.is_script { " (script)" } else { "" },
            entry.summary
        );
        print_params(&entry.params);
    }
    Ok(())
}

/// Validate a script and print its parameters, or fail with the script's error.
pub fn check(path: &Path) -> Result<()> {
    let model = ScriptModel::load(path)?;
    let params = model.params();
    let path_taken = if model.is_compiled() {
        "compiled to native closures (fast path)"
    } else {
        "runs on the rhai VM (uses constructs outside the compiled subset)"
    };
    crate::say!(
        "{}: ok, {} parameter(s); {path_taken}",
        path.display(),
        params.len()
    );
    let limits = model.limits();
    println!(
        "  one force() call at the defaults: {} operations on rhai's VM (budget {} a call, {} \
         for all calls in a run; the compiled path counts none)",
        model.force_operations(),
        limits.call_operations,
        limits.run_operations
    );
    print_params(params);
    Ok(())
}
