//! The `[validate]` section of an experiment file: a second record on which every fitted
//! model is scored with its fitted parameters, read with the `[data]` mapping of the first
//! (columns, units, calibration, drive reconstruction, filters).
//!
//! ```toml
//! [validate]
//! file = "records/other.csv"   # relative to the experiment file
//! window = [0.0, 30.0]         # optional time window, s
//! ```
//!
//! The file is checked when a command loads it (`crate::validation`), before any fit starts;
//! errors name the experiment file, the line of `file` and the key ([`ValidateSpec::error`]).

use std::path::{Path, PathBuf};

use anyhow::Result;
use serde::Deserialize;
use toml::Spanned;

use super::{error_at, line_of, Ctx};

/// `[validate]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawValidate {
    file: Spanned<String>,
    window: Option<[f64; 2]>,
}

/// A validated `[validate]` section.
#[derive(Clone, Debug, PartialEq)]
pub struct ValidateSpec {
    /// The record, resolved against the experiment's folder.
    pub file: PathBuf,
    /// The record's path as written in the experiment file.
    pub given: String,
    /// Time window, s.
    pub window: Option<(f64, f64)>,
    /// The experiment file.
    pub experiment: PathBuf,
    /// Line of `file` in it.
    pub line: usize,
}

impl ValidateSpec {
    /// An error about `[validate]` `key`, naming the experiment file and the line of `file`.
    pub fn error(&self, key: &str, msg: impl std::fmt::Display) -> anyhow::Error {
        error_at(&self.experiment, self.line, key, msg)
    }
}

/// Validate `[validate]` (if present) of the file `cx` reads, paths relative to `dir`.
pub(super) fn spec(
    raw: Option<&Spanned<RawValidate>>,
    cx: &Ctx,
    dir: &Path,
) -> Result<Option<ValidateSpec>> {
    let Some(raw) = raw else {
        return Ok(None);
    };
    let r = raw.get_ref();
    let window = r.window.map(|[a, b]| (a, b));
    if let Some((a, b)) = window {
        let empty = format!("[{a}, {b}] is empty");
        cx.ensure(b > a, raw.span(), "validate.window", empty)?;
    }
    let given = r.file.get_ref().clone();
    if given.trim().is_empty() {
        return Err(cx.at(r.file.span(), "validate.file", "names no record"));
    }
    Ok(Some(ValidateSpec {
        file: dir.join(&given),
        given,
        window,
        experiment: cx.file.to_path_buf(),
        line: line_of(cx.text, r.file.span().start),
    }))
}

#[cfg(test)]
mod tests {
    use super::super::Experiment;
    use std::path::Path;

    fn parse(text: &str) -> anyhow::Result<Experiment> {
        Experiment::parse(Path::new("dir/exp.toml"), text)
    }

    #[test]
    fn the_section_parses_and_bad_values_name_file_line_and_key() {
        let e = parse(
            "[data]\nfile = \"a.csv\"\n\n[validate]\nfile = \"b.csv\"\nwindow = [1.0, 5.0]\n",
        )
        .unwrap();
        let v = e.validate.unwrap();
        assert_eq!(v.file, Path::new("dir/b.csv"));
        assert_eq!(
            (v.given.as_str(), v.window, v.line),
            ("b.csv", Some((1.0, 5.0)), 5)
        );
        assert!(parse("[data]\nfile = \"a.csv\"\n")
            .unwrap()
            .validate
            .is_none());
        let msg = format!("{:#}", v.error("validate.file", "no such record"));
        assert_eq!(msg, "dir/exp.toml:5: `validate.file`: no such record");
        for (text, key, line) in [
            (
                "[validate]\nfile = \"b.csv\"\nwindow = [5.0, 1.0]\n",
                "validate.window",
                1,
            ),
            ("\n[validate]\nfile = \"\"\n", "validate.file", 3),
            (
                "[validate]\nfile = \"b.csv\"\nwindnow = [0.0, 1.0]\n",
                "windnow",
                3,
            ),
            ("[validate]\nwindow = [0.0, 1.0]\n", "file", 1),
        ] {
            let msg = format!("{:#}", parse(text).unwrap_err());
            assert!(
                msg.contains(&format!("exp.toml:{line}")) && msg.contains(key),
                "{msg}"
            );
        }
    }
}
