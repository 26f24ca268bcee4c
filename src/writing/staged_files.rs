//! Several files put in place as one unit (`simulate`'s record and its JSON sidecar; a
//! campaign's `campaign.json`, `campaign.csv`, `report.md` and `report.html`). Each is first
//! written in full beside its target under a temporary name ([`super::names`]); then
//! [`StagedFiles::commit`] writes the list of renames to a commit file beside the first
//! target (`.<name>.commit-<pid>-<n>`, synced), makes the renames, and removes the list —
//! interrupts held off meanwhile ([`crate::terminal::interrupt::hold_off`]). Dropped without a commit,
//! the staged files are removed and the old files stay as they were.
//!
//! A run killed between two renames leaves its commit file; the next run into the same
//! output, under its lock, finishes those renames first ([`finish_commits`]): the files are
//! all new, never some from one run and some from another. Then [`super::clean_stale`]
//! removes what else a killed run left. A kill before the commit file is whole leaves the old
//! files, and the half-written list is removed as a temporary.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use super::names::{self, Role};
use super::{check_regular_or_new, parent_of};

/// Files staged beside their targets, not yet in place.
#[derive(Debug, Default)]
pub struct StagedFiles {
    pairs: Vec<(PathBuf, PathBuf)>,
}

/// The commit file: the renames of a commit, file names in its folder.
#[derive(Debug, Deserialize, Serialize)]
struct CommitList {
    /// `(staged, target)` file names.
    renames: Vec<(String, String)>,
}

impl StagedFiles {
    /// No file staged yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// The path to write `target`'s new content to (in the folder of the first target: all
    /// the files of one commit share a folder).
    pub fn stage(&mut self, target: &Path) -> Result<PathBuf> {
        if let Some((_, first)) = self.pairs.first() {
            if parent_of(first) != parent_of(target) {
                bail!(
                    "{} and {} are in different folders; they cannot be put in place as one",
                    first.display(),
                    target.display()
                );
            }
        }
        let staged = names::temporary(target, Role::New);
        crate::terminal::interrupt::staged(&staged);
        self.pairs.push((staged.clone(), target.to_path_buf()));
        Ok(staged)
    }

    /// Rename every staged file onto its target, as one unit. Each target is checked again
    /// to be a regular file or new.
    pub fn commit(mut self) -> Result<()> {
        let Some((_, first)) = self.pairs.first().cloned() else {
            return Ok(());
        };
        let _hold = crate::terminal::interrupt::hold_off();
        for (_, target) in &self.pairs {
            check_regular_or_new(target)?;
        }
        let list = CommitList {
            renames: self
                .pairs
                .iter()
                .map(|(s, t)| (names::file_name(s), names::file_name(t)))
                .collect(),
        };
        let journal = names::temporary(&first, Role::Commit);
        let text = serde_json::to_vec(&list).context("cannot list the renames")?;
        super::atomic::write_unguarded(&journal, |out| out.write_all(&text))?;
        for (i, (staged, target)) in std::mem::take(&mut self.pairs).into_iter().enumerate() {
            if i == 1 {
                super::failpoint(&format!("commit:{}", names::file_name(&first)));
            }
            std::fs::rename(&staged, &target).with_context(|| {
                format!(
                    "cannot move {} into place at {}",
                    staged.display(),
                    target.display()
                )
            })?;
            crate::terminal::interrupt::unstaged(&staged);
            crate::terminal::interrupt::written(target.display().to_string());
        }
        super::results_dir::sync_folder(&parent_of(&first));
        std::fs::remove_file(&journal)
            .with_context(|| format!("cannot remove {}", journal.display()))
    }
}

impl Drop for StagedFiles {
    fn drop(&mut self) {
        for (staged, _) in &self.pairs {
            let _ = std::fs::remove_file(staged);
            crate::terminal::interrupt::unstaged(staged);
        }
    }
}

/// Under the outputs' lock: finish the commits a killed run left beside `first` (the first
/// target of its commits): rename the staged files still there onto their targets, remove
/// the commit file. What it did, in words.
pub fn finish_commits(first: &Path) -> Result<Vec<String>> {
    let folder = parent_of(first);
    let first_name = names::file_name(first);
    let Ok(entries) = std::fs::read_dir(&folder) else {
        return Ok(Vec::new());
    };
    let mut journals: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .filter(|e| {
            names::parse(&e.file_name().to_string_lossy())
                .is_some_and(|t| t.role == Role::Commit && t.of == first_name)
        })
        .map(|e| e.path())
        .collect();
    journals.sort();
    let mut notes = Vec::new();
    for journal in journals {
        // A list that does not read was cut short while being written: no rename had begun.
        let list = std::fs::read(&journal)
            .ok()
            .and_then(|b| serde_json::from_slice::<CommitList>(&b).ok());
        let mut finished = Vec::new();
        for (staged, target) in list.map(|l| l.renames).unwrap_or_default() {
            let (staged, target) = (folder.join(staged), folder.join(target));
            if staged.is_file() {
                check_regular_or_new(&target)?;
                std::fs::rename(&staged, &target).with_context(|| {
                    format!(
                        "cannot move {} into place at {}, left by an interrupted run",
                        staged.display(),
                        target.display()
                    )
                })?;
                finished.push(target.display().to_string());
            }
        }
        std::fs::remove_file(&journal)
            .with_context(|| format!("cannot remove {}", journal.display()))?;
        if !finished.is_empty() {
            notes.push(format!(
                "a run was stopped while putting its files in place beside {}; finished putting \
                 them in place: {}",
                first.display(),
                finished.join(", ")
            ));
        }
    }
    Ok(notes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names_in(dir: &Path) -> Vec<String> {
        let mut n: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        n.sort();
        n
    }

    #[test]
    fn staged_files_go_in_together_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("rec.csv"), dir.path().join("rec.json"));
        std::fs::write(&a, "old").unwrap();
        let mut staged = StagedFiles::new();
        let (sa, sb) = (staged.stage(&a).unwrap(), staged.stage(&b).unwrap());
        std::fs::write(&sa, "new").unwrap();
        std::fs::write(&sb, "{}").unwrap();
        drop(staged);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old");
        assert!(!sa.exists() && !sb.exists() && !b.exists());

        let mut staged = StagedFiles::new();
        std::fs::write(staged.stage(&a).unwrap(), "new").unwrap();
        std::fs::write(staged.stage(&b).unwrap(), "{}").unwrap();
        staged.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new");
        assert_eq!(names_in(dir.path()), ["rec.csv", "rec.json"]);
    }

    #[test]
    fn a_commit_cut_short_is_finished_by_the_next_run() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("rec.csv"), dir.path().join("rec.json"));
        std::fs::write(&a, "old").unwrap();
        std::fs::write(&b, "old").unwrap();
        // What a run killed after its first rename leaves: the new record in place, the new
        // sidecar staged, the list of renames.
        let sb = dir.path().join(".rec.json.new-77-1");
        std::fs::write(&a, "new").unwrap();
        std::fs::write(&sb, "new").unwrap();
        let list = CommitList {
            renames: vec![
                (".rec.csv.new-77-0".into(), "rec.csv".into()),
                (".rec.json.new-77-1".into(), "rec.json".into()),
            ],
        };
        std::fs::write(
            dir.path().join(".rec.csv.commit-77-2"),
            serde_json::to_vec(&list).unwrap(),
        )
        .unwrap();
        std::fs::write(dir.path().join(".rec.csv.commit-78-0"), "{\"rena").unwrap();
        let notes = finish_commits(&a).unwrap();
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(notes[0].contains("rec.json"), "{notes:?}");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "new");
        assert_eq!(names_in(dir.path()), ["rec.csv", "rec.json"]);
    }

    #[test]
    fn files_of_one_commit_share_a_folder() {
        let dir = tempfile::tempdir().unwrap();
        let mut staged = StagedFiles::new();
        staged.stage(&dir.path().join("a.csv")).unwrap();
        let e = staged.stage(&dir.path().join("sub/b.json")).unwrap_err();
        assert!(e.to_string().contains("different folders"), "{e}");
    }
}
