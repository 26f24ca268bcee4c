//! Writing results safely, in one place. Every file the program writes — records, results,
//! figures, reports, campaign tables, batch scripts, logs — goes through [`atomic`]: a
//! temporary file beside the target, synced, renamed into place (`tempfile`'s persist), so a
//! crash never leaves a half-written file under the final name. Everything put beside an
//! output before it is in place is named by one pattern, `.<name>.<role>-<pid>-<n>`
//! ([`names`]), which the next run recognises and repairs or removes. On top of that:
//!
//! - [`lock`]: one run at a time per output (`.<name>.lock` beside it, removed at the end);
//! - [`results_dir`]: a command's output folder built apart and swapped in whole, replaced
//!   with `--force` only if everything in it, one level down too, is this program's;
//! - [`staged_files`]: several files (`simulate`'s record and sidecar, a campaign's tables)
//!   staged and put in place as one unit, a commit cut short finished by the next run.
//!
//! An existing output is replaced only when the user says `--force`, and only if it is a
//! regular file or new ([`check_overwrite`]); two outputs of one command never resolve to one
//! path ([`check_distinct`]). The core writes to any `impl Write`; the atomic part is here.
//!
//! [`failpoint`] is the tests' way to kill or interrupt a run at an exact step
//! (`STF_LAB_FAILPOINT=<step>=kill|int`); it does nothing unless that variable names the step.

pub mod atomic;
pub mod lock;
pub mod names;
pub mod results_dir;
pub mod staged_files;

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

pub use atomic::{write_with, WriteError};
pub use names::is_temporary_name;

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

/// Write `bytes` to `path` atomically ([`atomic::write_atomic`], for the program's
/// `anyhow` errors).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    atomic::write_atomic(path, bytes)?;
    Ok(())
}

/// Serialize `value` as pretty JSON into `path`, atomically, numbers with the digits they
/// carry ([`crate::digits`]); object keys in sorted order.
pub fn write_json<T: serde::Serialize + ?Sized>(path: &Path, value: &T) -> Result<()> {
    let text = json_text(path, value)?;
    write_atomic(path, text.as_bytes())?;
    Ok(())
}

/// The text [`write_json`] writes.
pub fn json_text<T: serde::Serialize + ?Sized>(path: &Path, value: &T) -> Result<String> {
    let mut value = serde_json::to_value(value)
        .with_context(|| format!("cannot serialize {}", path.display()))?;
    crate::digits::tidy_json(&mut value);
    Ok(serde_json::to_string_pretty(&value)? + "\n")
}

/// Create the parent folder of `path` if it is missing.
pub fn ensure_parent(path: &Path) -> Result<()> {
    if let Some(parent) = path.parent() {
        atomic::ensure_dir(parent)?;
    }
    Ok(())
}

/// Remove this program's temporaries of `target` (any role) left beside it by a killed run,
/// the output's lock held. The names removed.
pub fn clean_stale(target: &Path) -> Result<Vec<String>> {
    let name = names::file_name(target);
    let Ok(entries) = std::fs::read_dir(parent_of(target)) else {
        return Ok(Vec::new());
    };
    let mut removed = Vec::new();
    for entry in entries.filter_map(|e| e.ok()) {
        let entry_name = entry.file_name().to_string_lossy().into_owned();
        if !names::is_temporary_of(&entry_name, &name) {
            continue;
        }
        let path = entry.path();
        let gone = match entry.file_type() {
            Ok(t) if t.is_dir() => std::fs::remove_dir_all(&path),
            _ => std::fs::remove_file(&path),
        };
        gone.with_context(|| {
            format!(
                "cannot remove {}, left by an interrupted run",
                path.display()
            )
        })?;
        removed.push(entry_name);
    }
    removed.sort();
    Ok(removed)
}

/// Remove every temporary of this program's pattern directly in `folder` (a folder only this
/// program writes in, whose lock is held: a campaign's `logs/`). The names removed.
pub fn clean_folder(folder: &Path) -> Result<Vec<String>> {
    let Ok(entries) = std::fs::read_dir(folder) else {
        return Ok(Vec::new());
    };
    let mut removed = Vec::new();
    for entry in entries.filter_map(|e| e.ok()) {
        let name = entry.file_name().to_string_lossy().into_owned();
        if is_temporary_name(&name) && entry.file_type().is_ok_and(|t| t.is_file()) {
            std::fs::remove_file(entry.path()).with_context(|| {
                format!(
                    "cannot remove {}, left by an interrupted run",
                    entry.path().display()
                )
            })?;
            removed.push(name);
        }
    }
    removed.sort();
    Ok(removed)
}

/// The tests' kill switch: when `STF_LAB_FAILPOINT` is `<step>=kill`, the process kills
/// itself (SIGKILL: nothing runs after) at `step`; with `<step>=int` it interrupts itself
/// (SIGINT) and goes on once the handler has started, as a Ctrl-C in the middle of the step.
pub fn failpoint(step: &str) {
    let Some(wanted) = std::env::var_os("STF_LAB_FAILPOINT") else {
        return;
    };
    let wanted = wanted.to_string_lossy();
    let Some((at, how)) = wanted.rsplit_once('=') else {
        return;
    };
    if at != step {
        return;
    }
    #[cfg(unix)]
    {
        use nix::sys::signal::{raise, Signal};
        match how {
            "kill" => {
                let _ = raise(Signal::SIGKILL);
            }
            "int" => {
                let _ = raise(Signal::SIGINT);
                for _ in 0..5000 {
                    if crate::terminal::interrupt::is_interrupted() {
                        break;
                    }
                    std::thread::sleep(std::time::Duration::from_millis(1));
                }
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_to_clobber_without_force() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.json");
        write_atomic(&p, b"one").unwrap();
        assert!(check_overwrite(&p, false).is_err());
        assert!(check_overwrite(&p, true).is_ok());
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
    fn clean_stale_removes_only_the_targets_temporaries() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("rec.csv");
        for name in [
            ".rec.csv.new-99-0",
            ".rec.5-1.tmp.csv",
            ".rec.json.new-99-1",
            "rec.csv",
            "mine.txt",
        ] {
            std::fs::write(dir.path().join(name), "x").unwrap();
        }
        std::fs::create_dir(dir.path().join(".rec.csv.old-7-0")).unwrap();
        let removed = clean_stale(&target).unwrap();
        assert_eq!(
            removed,
            [".rec.5-1.tmp.csv", ".rec.csv.new-99-0", ".rec.csv.old-7-0"]
        );
        assert!(dir.path().join("mine.txt").exists() && target.exists());
        assert!(dir.path().join(".rec.json.new-99-1").exists());
    }
}
