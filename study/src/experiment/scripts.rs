//! The `[scripts]` section of an experiment file: the limits script models run under in this
//! run ([`stf_plugins::ScriptLimits`]), each key optional.
//!
//! ```toml
//! [scripts]
//! call_operations = 1_000_000        # operations one call may perform
//! run_operations = 10_000_000_000    # operations all calls of one script may perform in this run
//! call_seconds = 10.0                # wall-clock last resort per call
//! max_bytes = 65536                  # size limits, checked before a script is compiled
//! max_functions = 256
//! max_nodes = 10_000
//! max_constants = 1_000
//! ```

use anyhow::Result;
use serde::Deserialize;
use stf_plugins::{ScriptLimits, ScriptRun};
use toml::Spanned;

use super::Ctx;

/// `[scripts]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawScripts {
    max_bytes: Option<usize>,
    max_functions: Option<usize>,
    max_nodes: Option<usize>,
    max_constants: Option<usize>,
    call_operations: Option<u64>,
    run_operations: Option<u64>,
    call_seconds: Option<f64>,
}

/// The run scripts load in: the defaults, with the keys of `[scripts]` (if present).
pub(super) fn run(raw: Option<&Spanned<RawScripts>>, cx: &Ctx) -> Result<ScriptRun> {
    let mut limits = ScriptLimits::default();
    let Some(raw) = raw else {
        return Ok(ScriptRun::new(limits));
    };
    let (span, r) = (raw.span(), raw.get_ref());
    let counts = [
        ("max_bytes", count(&mut limits.max_bytes, r.max_bytes)),
        (
            "max_functions",
            count(&mut limits.max_functions, r.max_functions),
        ),
        ("max_nodes", count(&mut limits.max_nodes, r.max_nodes)),
        (
            "max_constants",
            count(&mut limits.max_constants, r.max_constants),
        ),
        (
            "call_operations",
            count(&mut limits.call_operations, r.call_operations),
        ),
        (
            "run_operations",
            count(&mut limits.run_operations, r.run_operations),
        ),
    ];
    if let Some((key, _)) = counts.into_iter().find(|(_, ok)| !ok) {
        let key = format!("scripts.{key}");
        return Err(cx.at(span, &key, "must be at least 1"));
    }
    if let Some(s) = r.call_seconds {
        let what = format!("{s} must be a positive number of seconds");
        cx.ensure(s > 0.0, span, "scripts.call_seconds", what)?;
        limits.call_seconds = s;
    }
    Ok(ScriptRun::new(limits))
}

/// Set `slot` to `value` if given; `false` if that is 0, not a count of at least 1.
fn count<T: PartialEq + Default>(slot: &mut T, value: Option<T>) -> bool {
    match value {
        Some(v) if v == T::default() => false,
        Some(v) => {
            *slot = v;
            true
        }
        None => true,
    }
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
            // Not a count: TOML's own message, at the key's line.
            ("[scripts]\nrun_operations = -5\n", "exp.toml:2:"),
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
