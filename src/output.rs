//! Writing results safely: every file is written to a temporary file beside its target and
//! renamed into place, so a crash never leaves a half-written file under the final name; an
//! existing output is replaced only when the user says `--force`.

use std::path::Path;

use anyhow::{bail, Context, Result};

/// Refuse to replace `path` unless `force` is set.
pub fn check_overwrite(path: &Path, force: bool) -> Result<()> {
    if path.exists() && !force {
        bail!(
            "{} already exists; pass --force to replace it",
            path.display()
        );
    }
    Ok(())
}

/// Write `bytes` to `path` atomically (temporary file beside it, then a rename): the one
/// implementation, shared with the figures in [`crate::report`].
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    crate::report::write_file_atomic(path, bytes)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Make `dir` ready for a command's outputs: create it, or, if it exists and holds files,
/// refuse unless `force` (then its files are replaced one by one, atomically).
pub fn prepare_dir(dir: &Path, force: bool) -> Result<()> {
    if dir.exists() {
        let occupied = std::fs::read_dir(dir)
            .with_context(|| format!("cannot read folder {}", dir.display()))?
            .next()
            .is_some();
        if occupied && !force {
            bail!(
                "{} already exists and is not empty; pass --force to replace its results",
                dir.display()
            );
        }
        return Ok(());
    }
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create folder {}", dir.display()))
}

/// Serialize `value` as pretty JSON into `path`, atomically, numbers with the digits they
/// carry ([`crate::digits`]).
pub fn write_json(path: &Path, value: &serde_json::Value) -> Result<()> {
    let mut value = value.clone();
    crate::digits::tidy_json(&mut value);
    let text = serde_json::to_string_pretty(&value)? + "\n";
    write_atomic(path, text.as_bytes())
}

/// Write columns of numbers as CSV (header `names`) into `path`, atomically.
pub fn write_columns(path: &Path, names: &[&str], columns: &[&[f64]]) -> Result<()> {
    let n = columns.iter().map(|c| c.len()).min().unwrap_or(0);
    let mut text = names.join(",");
    text.push('\n');
    for i in 0..n {
        let row: Vec<String> = columns
            .iter()
            .map(|c| crate::digits::carried(c[i]).to_string())
            .collect();
        text.push_str(&row.join(","));
        text.push('\n');
    }
    write_atomic(path, text.as_bytes())
}

/// Create the parent folder of `path` if it is missing.
pub fn ensure_parent(path: &Path) -> Result<()> {
    if let Some(parent) = path.parent() {
        if !parent.as_os_str().is_empty() {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("cannot create folder {}", parent.display()))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_atomically_and_refuses_to_clobber() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.json");
        write_atomic(&p, b"one").unwrap();
        assert!(check_overwrite(&p, false).is_err());
        assert!(check_overwrite(&p, true).is_ok());
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(leftovers.len(), 1);
    }
}
