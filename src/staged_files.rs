//! Outputs that are single files (`simulate`'s record and its JSON sidecar) written as one
//! step: each is first written in full beside its target as `.<name>.new-<pid>`, and all are
//! renamed into place together at the end, interrupts held off meanwhile
//! ([`crate::interrupt::hold_off`]). A run stopped before that leaves the old files as they
//! were; dropped without [`StagedFiles::commit`], the staged files are removed. The caller
//! holds the output's lock ([`crate::output_lock`]), under which [`clean_stale`] removes what a
//! killed run left beside a target — this program's temporaries of that target only.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::output::{check_regular_or_new, is_temporary_name, parent_of};

/// Files staged beside their targets, not yet in place.
#[derive(Debug, Default)]
pub struct StagedFiles {
    pairs: Vec<(PathBuf, PathBuf)>,
}

impl StagedFiles {
    /// No file staged yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// The path to write `target`'s new content to.
    pub fn stage(&mut self, target: &Path) -> PathBuf {
        let staged = crate::output::sibling(target, &format!("new-{}", std::process::id()));
        crate::interrupt::staged(&staged);
        self.pairs.push((staged.clone(), target.to_path_buf()));
        staged
    }

    /// Rename every staged file onto its target. Each target is checked again to be a
    /// regular file or new.
    pub fn commit(mut self) -> Result<()> {
        let _hold = crate::interrupt::hold_off();
        for (_, target) in &self.pairs {
            check_regular_or_new(target)?;
        }
        for (staged, target) in std::mem::take(&mut self.pairs) {
            std::fs::rename(&staged, &target).with_context(|| {
                format!(
                    "cannot move {} into place at {}",
                    staged.display(),
                    target.display()
                )
            })?;
            crate::interrupt::unstaged(&staged);
            crate::interrupt::written(target.display().to_string());
        }
        Ok(())
    }
}

impl Drop for StagedFiles {
    fn drop(&mut self) {
        for (staged, _) in &self.pairs {
            let _ = std::fs::remove_file(staged);
            crate::interrupt::unstaged(staged);
        }
    }
}

/// Whether `entry` (a file name beside `target`) is one of this program's temporaries of
/// `target`: its staged file `.<name>.new-<pid>`, the per-file temporaries of the atomic
/// writers (`.<stem>.<pid>-<n>.tmp.<ext>`, `.<name>.<pid>.tmp`), or one of those of a staged
/// file (`..<name>.…tmp…`).
pub fn is_temporary_of(entry: &str, target: &Path) -> bool {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let Some(file) = target.file_name().map(|f| f.to_string_lossy().into_owned()) else {
        return false;
    };
    let stem = target
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = target
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    if let Some(pid) = entry.strip_prefix(&format!(".{file}.new-")) {
        return digits(pid);
    }
    if entry.starts_with(&format!("..{file}.")) {
        return is_temporary_name(entry);
    }
    let atomic = entry
        .strip_prefix(&format!(".{stem}."))
        .and_then(|r| r.strip_suffix(&format!(".tmp{ext}")))
        .and_then(|id| id.split_once('-'))
        .is_some_and(|(pid, n)| digits(pid) && digits(n));
    let record = entry
        .strip_prefix(&format!(".{file}."))
        .and_then(|r| r.strip_suffix(".tmp"))
        .is_some_and(digits);
    atomic || record
}

/// Remove this program's temporaries of `target` left beside it by a killed run (call with
/// the output's lock held). The names removed.
pub fn clean_stale(target: &Path) -> Result<Vec<String>> {
    let Ok(entries) = std::fs::read_dir(parent_of(target)) else {
        return Ok(Vec::new());
    };
    let mut removed = Vec::new();
    for entry in entries.filter_map(|e| e.ok()) {
        let name = entry.file_name().to_string_lossy().into_owned();
        let is_file = entry.file_type().is_ok_and(|t| t.is_file());
        if is_file && is_temporary_of(&name, target) {
            std::fs::remove_file(entry.path()).with_context(|| {
                format!(
                    "cannot remove {}, left by an interrupted run",
                    entry.path().display()
                )
            })?;
            removed.push(name);
        }
    }
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recognises_the_temporaries_of_one_target_only() {
        let target = Path::new("out/rec.csv");
        for ours in [
            ".rec.csv.new-12",
            ".rec.12-0.tmp.csv",
            ".rec.csv.12.tmp",
            "..rec.csv.new-12.77.tmp",
        ] {
            assert!(is_temporary_of(ours, target), "{ours}");
        }
        for other in [
            "rec.csv",
            ".rec.json.new-12",
            ".rec.v2.12-0.tmp.csv",
            ".rec.12-0.tmp.json",
            ".rec.csv.new-x",
            ".rec.csv.lock",
            "notes.tmp",
        ] {
            assert!(!is_temporary_of(other, target), "{other}");
        }
    }

    #[test]
    fn staged_files_go_in_together_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("rec.csv"), dir.path().join("rec.json"));
        std::fs::write(&a, "old").unwrap();
        let mut staged = StagedFiles::new();
        let (sa, sb) = (staged.stage(&a), staged.stage(&b));
        std::fs::write(&sa, "new").unwrap();
        std::fs::write(&sb, "{}").unwrap();
        drop(staged);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old");
        assert!(!sa.exists() && !sb.exists() && !b.exists());

        let mut staged = StagedFiles::new();
        std::fs::write(staged.stage(&a), "new").unwrap();
        std::fs::write(staged.stage(&b), "{}").unwrap();
        staged.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn clean_stale_removes_only_ours() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("rec.csv");
        for name in [".rec.csv.new-99", ".rec.5-1.tmp.csv", "rec.csv", "mine.txt"] {
            std::fs::write(dir.path().join(name), "x").unwrap();
        }
        let mut removed = clean_stale(&target).unwrap();
        removed.sort();
        assert_eq!(removed, [".rec.5-1.tmp.csv", ".rec.csv.new-99"]);
        assert!(dir.path().join("mine.txt").exists() && target.exists());
    }
}
