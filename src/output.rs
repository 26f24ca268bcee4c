//! Writing results safely: every file is written to a temporary file beside its target and
//! renamed into place, so a crash never leaves a half-written file under the final name; an
//! existing output is replaced only when the user says `--force`, and only if it is a regular
//! file (a rename would put a file in place of a device, a FIFO or a socket); two outputs of
//! one command never resolve to one path. A command's output folder is written as one unit
//! by [`crate::results_dir`].

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// Refuse to replace `path` unless `force` is set; refuse always if it is not a regular file.
pub fn check_overwrite(path: &Path, force: bool) -> Result<()> {
    check_regular_or_new(path)?;
    if path.exists() && !force {
        bail!(
            "{} already exists; pass --force to replace it",
            path.display()
        );
    }
    Ok(())
}

/// Refuse an output path that exists and is not a regular file (a device, FIFO, socket or
/// folder, or a link to one): outputs go only to regular files or new paths.
pub fn check_regular_or_new(path: &Path) -> Result<()> {
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_dir() => bail!(
            "{} is a folder; this output is a file: give a file path",
            path.display()
        ),
        Ok(meta) if !meta.is_file() => bail!(
            "{} is not a regular file (a device, FIFO or socket); outputs go only to regular \
             files or new paths",
            path.display()
        ),
        _ => Ok(()),
    }
}

/// Where `path` leads: the real path of what exists of it (links and `..` resolved), the
/// missing rest appended.
pub fn resolve(path: &Path) -> PathBuf {
    if let Ok(real) = std::fs::canonicalize(path) {
        return real;
    }
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    match (absolute.parent(), absolute.file_name()) {
        (Some(parent), Some(name)) => resolve(parent).join(name),
        _ => absolute,
    }
}

/// Refuse outputs of one command that resolve to the same path (each `(what, path)`, e.g.
/// `("the record", out)`): the later would silently replace the earlier.
pub fn check_distinct(outputs: &[(&str, &Path)]) -> Result<()> {
    let resolved: Vec<PathBuf> = outputs.iter().map(|(_, p)| resolve(p)).collect();
    for (i, a) in resolved.iter().enumerate() {
        for (j, b) in resolved.iter().enumerate().skip(i + 1) {
            if a == b {
                bail!(
                    "{} {} and {} {} are the same file; give outputs that differ",
                    outputs[i].0,
                    outputs[i].1.display(),
                    outputs[j].0,
                    outputs[j].1.display()
                );
            }
        }
    }
    Ok(())
}

/// The folder that holds `target` (`.` for a bare name).
pub fn parent_of(target: &Path) -> PathBuf {
    match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// A path beside `target` named `.<name>.<tag>` (its lock file, staging folder …).
pub fn sibling(target: &Path, tag: &str) -> PathBuf {
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    target.with_file_name(format!(".{name}.{tag}"))
}

/// Whether `name` is one of this program's per-file temporaries, `.<stem>.<pid>-<n>.tmp[.ext]`
/// (`report::atomic::temporary_sibling`), or the record writer's `.<name>.<pid>.tmp`: left
/// only by a run that was killed while writing.
pub fn is_temporary_name(name: &str) -> bool {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let parts = name
        .strip_prefix('.')
        .and_then(|rest| rest.rsplit_once(".tmp"));
    let Some(((stem, id), ext)) = parts.and_then(|(b, ext)| Some((b.rsplit_once('.')?, ext)))
    else {
        return false;
    };
    let one_ext = ext.is_empty() || ext.strip_prefix('.').is_some_and(|e| !e.contains('.'));
    one_ext
        && !stem.is_empty()
        && match id.split_once('-') {
            Some((pid, n)) => digits(pid) && digits(n),
            None => digits(id),
        }
}

/// Write `bytes` to `path` atomically (temporary file beside it, then a rename): the one
/// implementation, shared with the figures in [`crate::report`].
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    crate::report::write_file_atomic(path, bytes)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Serialize `value` as pretty JSON into `path`, atomically, numbers with the digits they
/// carry ([`crate::digits`]); object keys in sorted order.
pub fn write_json<T: serde::Serialize + ?Sized>(path: &Path, value: &T) -> Result<()> {
    let mut value = serde_json::to_value(value)
        .with_context(|| format!("cannot serialize {}", path.display()))?;
    crate::digits::tidy_json(&mut value);
    let text = serde_json::to_string_pretty(&value)? + "\n";
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

    #[test]
    fn refuses_special_files_and_folders_as_file_outputs() {
        let dir = tempfile::tempdir().unwrap();
        let e = check_overwrite(dir.path(), true).unwrap_err().to_string();
        assert!(e.contains("is a folder"), "{e}");
        let fifo = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.map(|s| s.success()).unwrap_or(false) {
            let e = check_overwrite(&fifo, true).unwrap_err().to_string();
            assert!(e.contains("not a regular file"), "{e}");
        }
        assert!(check_overwrite(&dir.path().join("new.csv"), false).is_ok());
    }

    #[test]
    fn outputs_that_resolve_to_one_path_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("rec.json");
        let b = dir.path().join("sub/../rec.json");
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let e = check_distinct(&[("the record", &a), ("its sidecar", &b)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("are the same file"), "{e}");
        assert!(check_distinct(&[("a", &a), ("b", &dir.path().join("rec.csv"))]).is_ok());
    }

    #[test]
    fn recognises_only_its_own_temporaries() {
        for ours in [
            ".fitted.123-4.tmp.csv",
            ".fit.9-0.tmp.json",
            ".rec.csv.77.tmp",
        ] {
            assert!(is_temporary_name(ours), "{ours}");
        }
        for not_ours in [
            "fitted.csv",
            ".fitted.tmp.csv",
            ".x.12-a.tmp.csv",
            ".notes.tmp",
            ".a.1.tmp.b.c",
        ] {
            assert!(!is_temporary_name(not_ours), "{not_ours}");
        }
    }
}
