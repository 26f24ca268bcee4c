//! The hash of a unit's inputs, by which a rerun recognises a finished unit: SHA-256 (the
//! `sha2` crate) over the unit's entry in the campaign file (record and experiment as written,
//! command, conditions), the program's version, and the bytes of every file the unit reads —
//! the experiment, the record, the scripts its models and `[discover]` name, and its
//! `[validate]` record. Each part is framed by its label and length, so no two different
//! sets of inputs hash alike by running into one another. Files are streamed, not loaded.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::Serialize;
use sha2::{Digest, Sha256};

use super::file::{CommandName, Unit};
use crate::experiment::Experiment;

/// The part of a unit's entry that decides its results (paths as written, so a campaign
/// folder moved elsewhere keeps its finished units).
#[derive(Serialize)]
struct Entry<'a> {
    record: &'a str,
    experiment: &'a str,
    command: CommandName,
    conditions: &'a [(String, f64)],
}

/// The files `exp` reads besides its record: scripts named by its models and `[discover]`,
/// and its `[validate]` record. Names that are not files (built-in models) are left out.
pub fn files_read(exp: &Experiment) -> Vec<PathBuf> {
    let mut specs: Vec<&str> = exp.models.iter().flat_map(|m| m.specs()).collect();
    if let Some(d) = &exp.discover {
        specs.extend(d.base.iter().map(String::as_str));
        specs.extend(d.candidates.iter().flatten().map(String::as_str));
    }
    let mut files: Vec<PathBuf> = specs
        .into_iter()
        .flat_map(|s| s.split('+'))
        .map(str::trim)
        .filter(|s| s.ends_with(".rhai"))
        .map(|s| exp.dir.join(s))
        .filter(|p| p.is_file())
        .collect();
    files.extend(exp.validate.iter().map(|v| v.file.clone()));
    files.sort();
    files.dedup();
    files
}

/// The hex SHA-256 of `unit`'s inputs, with `exp` its experiment as loaded.
pub fn unit_hash(unit: &Unit, exp: &Experiment) -> Result<String> {
    let mut h = Sha256::new();
    let entry = Entry {
        record: &unit.record_given,
        experiment: &unit.experiment_given,
        command: unit.command,
        conditions: &unit.conditions,
    };
    let entry = serde_json::to_vec(&entry)?;
    part(&mut h, "entry", &entry);
    part(&mut h, "version", env!("CARGO_PKG_VERSION").as_bytes());
    file_part(&mut h, "experiment", &unit.experiment)?;
    file_part(&mut h, "record", &unit.record)?;
    for f in files_read(exp) {
        file_part(&mut h, "file", &f)?;
    }
    Ok(h.finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<String>())
}

/// A labelled, length-framed part.
fn part(h: &mut Sha256, label: &str, bytes: &[u8]) {
    h.update(label.as_bytes());
    h.update((bytes.len() as u64).to_le_bytes());
    h.update(bytes);
}

/// A file's bytes as a part, streamed.
fn file_part(h: &mut Sha256, label: &str, path: &Path) -> Result<()> {
    let mut file =
        std::fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
    let len = file
        .metadata()
        .with_context(|| format!("cannot read {}", path.display()))?
        .len();
    h.update(label.as_bytes());
    h.update(len.to_le_bytes());
    let copied =
        std::io::copy(&mut file, h).with_context(|| format!("cannot read {}", path.display()))?;
    if copied != len {
        anyhow::bail!("{} changed while it was read", path.display());
    }
    h.flush()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn framing_keeps_parts_apart() {
        let digest = |parts: &[(&str, &[u8])]| {
            let mut h = Sha256::new();
            for (l, b) in parts {
                part(&mut h, l, b);
            }
            h.finalize().to_vec()
        };
        assert_ne!(
            digest(&[("a", b"xy"), ("b", b"z")]),
            digest(&[("a", b"x"), ("b", b"yz")])
        );
    }
}
