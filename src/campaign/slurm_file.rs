//! The `[slurm]` section of a campaign file: how `--slurm` cuts the campaign into jobs for
//! the cluster it is submitted to. Every key is optional; parsed into a raw serde type and
//! checked into a [`SlurmSpec`] with the rest of the file (`super::file`), each error naming
//! the campaign file, the line and the key.
//!
//! ```toml
//! [slurm]
//! max_array_size = 1001   # the cluster's MaxArraySize (default: read from `scontrol show config`)
//! units_per_task = 20     # units run one after another by one array task (default: from the commands)
//! throttle = 50           # at most this many tasks of an array run at once (`--array=…%50`)
//! cpus_per_task = 2       # `--cpus-per-task` of every array task (default 1)
//! ```

use std::path::Path;

use anyhow::Result;
use serde::Deserialize;
use toml::Spanned;

use crate::experiment::{error_at, line_of};

/// `[slurm]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSlurm {
    max_array_size: Option<Spanned<i64>>,
    units_per_task: Option<Spanned<i64>>,
    throttle: Option<Spanned<i64>>,
    cpus_per_task: Option<Spanned<i64>>,
}

/// The checked `[slurm]` settings; `None`: not given (a default or the cluster's value holds).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SlurmSpec {
    /// Slurm's `MaxArraySize`: array task indices must be below it (so at most this many
    /// tasks per array, indices 0 to `max_array_size - 1`).
    pub max_array_size: Option<usize>,
    /// Units one array task runs, one after another.
    pub units_per_task: Option<usize>,
    /// Tasks of one array running at once (`%N` of `--array`).
    pub throttle: Option<usize>,
    /// `--cpus-per-task` of the array tasks.
    pub cpus_per_task: Option<usize>,
}

/// Check `[slurm]` of the campaign file at `path` (its text `text`, for the lines).
pub(super) fn check(raw: &Spanned<RawSlurm>, path: &Path, text: &str) -> Result<SlurmSpec> {
    let r = raw.get_ref();
    let value = |key: &str, v: &Option<Spanned<i64>>, least: i64, what: &str| -> Result<_> {
        let Some(v) = v else { return Ok(None) };
        let n = *v.get_ref();
        if n < least {
            return Err(error_at(
                path,
                line_of(text, v.span().start),
                &format!("slurm.{key}"),
                format!("{n}: {what}"),
            ));
        }
        Ok(Some(n as usize))
    };
    Ok(SlurmSpec {
        max_array_size: value(
            "max_array_size",
            &r.max_array_size,
            2,
            "give the cluster's MaxArraySize (at least 2: task indices are below it)",
        )?,
        units_per_task: value(
            "units_per_task",
            &r.units_per_task,
            1,
            "give at least 1 unit per array task",
        )?,
        throttle: value(
            "throttle",
            &r.throttle,
            1,
            "give at least 1 task of an array running at once",
        )?,
        cpus_per_task: value(
            "cpus_per_task",
            &r.cpus_per_task,
            1,
            "give at least 1 CPU per task",
        )?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Deserialize)]
    struct Doc {
        slurm: Spanned<RawSlurm>,
    }

    fn parse(text: &str) -> Result<SlurmSpec> {
        let doc: Doc = toml::from_str(text).map_err(|e| anyhow::anyhow!("{e}"))?;
        check(&doc.slurm, Path::new("c.toml"), text)
    }

    #[test]
    fn settings_are_read_and_bad_values_named_with_line_and_key() {
        let s =
            parse("[slurm]\nmax_array_size = 1001\nunits_per_task = 20\nthrottle = 4\n").unwrap();
        assert_eq!(
            s,
            SlurmSpec {
                max_array_size: Some(1001),
                units_per_task: Some(20),
                throttle: Some(4),
                cpus_per_task: None,
            }
        );
        let e = parse("[slurm]\n\nunits_per_task = 0\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("c.toml:3: `slurm.units_per_task`: 0: give at least 1"),
            "{e}"
        );
        let e = parse("[slurm]\nmax_array_size = 1\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("`slurm.max_array_size`: 1: "), "{e}");
        let e = parse("[slurm]\ncpus = 2\n").unwrap_err().to_string();
        assert!(e.contains("unknown field `cpus`"), "{e}");
    }
}
