//! The `[scripts]` section of an experiment file: the limits script models run under in this
//! run ([`stf_plugins::ScriptLimits`]), each key optional.
//!
//! ```toml
//! [scripts]
//! call_operations = 1_000_000        # operations one call may perform
//! run_operations = 10_000_000_000    # operations all calls of one script may perform in this run
//! call_seconds = 10.0                # wall-clock last resort per call
//! run_seconds = 600.0                # wall-clock seconds of one script's calls in this run;
//!                                    # a run planned to take longer is refused before it starts
//! max_bytes = 65536                  # size limits, checked before a script is compiled
//! max_functions = 256
//! max_nodes = 10_000
//! max_constants = 1_000
//! ```
//!
//! Counts may be written as integers or as numbers (`run_operations = 1e9`), as every count
//! of an experiment file may.

use anyhow::Result;
use serde::Deserialize;
use stf_plugins::{ScriptLimits, ScriptRun};
use toml::Spanned;

use super::Ctx;

/// `[scripts]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawScripts {
    max_bytes: Option<Spanned<f64>>,
    max_functions: Option<Spanned<f64>>,
    max_nodes: Option<Spanned<f64>>,
    max_constants: Option<Spanned<f64>>,
    call_operations: Option<Spanned<f64>>,
    run_operations: Option<Spanned<f64>>,
    call_seconds: Option<Spanned<f64>>,
    run_seconds: Option<Spanned<f64>>,
}

/// The run scripts load in: the defaults, with the keys of `[scripts]` (if present).
pub(super) fn run(raw: Option<&Spanned<RawScripts>>, cx: &Ctx) -> Result<ScriptRun> {
    let mut limits = ScriptLimits::default();
    let Some(raw) = raw else {
        return Ok(ScriptRun::new(limits));
    };
    let r = raw.get_ref();
    let count = |value: &Option<Spanned<f64>>, key: &str| -> Result<Option<u64>> {
        value
            .as_ref()
            .map(|v| cx.count(v, &format!("scripts.{key}"), 1, "count"))
            .transpose()
    };
    let size = |value: &Option<Spanned<f64>>, key: &str| -> Result<Option<usize>> {
        Ok(count(value, key)?.map(|n| usize::try_from(n).unwrap_or(usize::MAX)))
    };
    let seconds = |value: &Option<Spanned<f64>>, key: &str| -> Result<Option<f64>> {
        let Some(v) = value else { return Ok(None) };
        let s = *v.get_ref();
        let what = format!("{s} must be a positive number of seconds");
        cx.ensure(s > 0.0, v.span(), &format!("scripts.{key}"), what)?;
        Ok(Some(s))
    };
    let l = &mut limits;
    l.max_bytes = size(&r.max_bytes, "max_bytes")?.unwrap_or(l.max_bytes);
    l.max_functions = size(&r.max_functions, "max_functions")?.unwrap_or(l.max_functions);
    l.max_nodes = size(&r.max_nodes, "max_nodes")?.unwrap_or(l.max_nodes);
    l.max_constants = size(&r.max_constants, "max_constants")?.unwrap_or(l.max_constants);
    l.call_operations = count(&r.call_operations, "call_operations")?.unwrap_or(l.call_operations);
    l.run_operations = count(&r.run_operations, "run_operations")?.unwrap_or(l.run_operations);
    l.call_seconds = seconds(&r.call_seconds, "call_seconds")?.unwrap_or(l.call_seconds);
    l.run_seconds = seconds(&r.run_seconds, "run_seconds")?.unwrap_or(l.run_seconds);
    Ok(ScriptRun::new(limits))
}

#[cfg(test)]
mod tests {
    use crate::experiment::parse_exp as parse;

    use stf_plugins::ScriptLimits;

    #[test]
    fn the_keys_set_the_limits_and_the_rest_keep_their_defaults() {
        let e = parse("[scripts]\nrun_operations = 5000\nmax_functions = 3\ncall_seconds = 2.5\n")
            .unwrap();
        assert_eq!(
            e.scripts.limits(),
            &ScriptLimits {
                run_operations: 5000,
                max_functions: 3,
                call_seconds: 2.5,
                ..ScriptLimits::default()
            }
        );
        // A count written as a number, as `max_samples = 1e7` is (it was refused as a float).
        let e = parse("[scripts]\nrun_operations = 1e9\nrun_seconds = 3600\nmax_nodes = 2e4\n")
            .unwrap();
        assert_eq!(
            e.scripts.limits(),
            &ScriptLimits {
                run_operations: 1_000_000_000,
                run_seconds: 3600.0,
                max_nodes: 20_000,
                ..ScriptLimits::default()
            }
        );
        assert_eq!(
            parse("").unwrap().scripts.limits(),
            &ScriptLimits::default()
        );
    }

    #[test]
    fn zero_or_negative_limits_and_unknown_keys_are_refused_with_the_key() {
        for (text, key) in [
            (
                "[scripts]\ncall_operations = 0\n",
                "scripts.call_operations",
            ),
            ("[scripts]\nmax_bytes = 0\n", "scripts.max_bytes"),
            ("[scripts]\ncall_seconds = -1.0\n", "scripts.call_seconds"),
            (
                "[scripts]\nrun_seconds = 0\n",
                "exp.toml:2: `scripts.run_seconds`: 0 must be",
            ),
            (
                "[scripts]\nrun_operations = -5\n",
                "exp.toml:2: `scripts.run_operations`: -5 is not a count (at least 1)",
            ),
            (
                "[scripts]\nrun_operations = 2.5e30\n",
                "`scripts.run_operations`: 2.5e30 is not a count",
            ),
            ("[scripts]\ndeadline = 1.0\n", "deadline"),
        ] {
            let msg = format!("{:#}", parse(text).unwrap_err());
            assert!(
                msg.starts_with("exp.toml:") && msg.contains(key),
                "{text}: {msg}"
            );
        }
    }
}
