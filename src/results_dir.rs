//! The output folder of `fit`, `compare` and `discover` is written as one unit. A run builds
//! its results in a staging folder beside the output, `.<name>.new-<pid>`, and swaps it in
//! at the end: the old folder is renamed to `.<name>.old-<pid>`, the new one to `<name>`, and
//! the old one removed. A reader, or a run killed at any moment, sees the old results or the
//! new ones, never a mix; a folder whose run writes no report keeps no old report.
//!
//! The output is locked for the run ([`crate::output_lock`]), so a second run into it is
//! refused. Under that lock, what a killed run left is ours to clean: [`repair`] puts the old
//! folder back if the run died between the two renames (the output missing, its `.old-`
//! beside it) and removes stale staging and old folders. `--force` replaces only a folder
//! that holds nothing but this program's results ([`RESULT_NAMES`]) and temporaries: a
//! stranger in it (notes, the experiment's record) would be lost, so it is refused instead.
//!
//! The swap is split into plain steps ([`step_aside`], [`step_in`], [`clear_old`]) so tests
//! can stop between them as a crash would.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use crate::output::{is_temporary_name, parent_of, sibling};
use crate::output_lock::OutputLock;

/// Every name this program writes in an output folder (all commands).
pub const RESULT_NAMES: &[&str] = &[
    "fit.json",
    "params.csv",
    "fitted.csv",
    "compare.json",
    "compare.md",
    "compare.csv",
    "cycles.csv",
    "discovery.json",
    "discovered.csv",
    "unit.json",
    "report.html",
    "report.md",
    "figures",
];

/// The closing line of a command: `wrote out/fit.json, out/params.csv and out/report.html …`,
/// the report's files (`report.html`, `report.md`, `figures/`) only when `report` was written.
pub fn wrote_line(out: &Path, files: &[&str], report: bool) -> String {
    let mut all: Vec<String> = files
        .iter()
        .map(|f| out.join(f).display().to_string())
        .collect();
    if report {
        all.extend(["report.html", "report.md"].map(|f| out.join(f).display().to_string()));
        all.push(format!("{}/", out.join("figures").display()));
    }
    match all.split_last() {
        None => format!("wrote {}", out.display()),
        Some((last, [])) => format!("wrote {last}"),
        Some((last, rest)) => format!("wrote {} and {last}", rest.join(", ")),
    }
}

/// A results folder being built; dropped without [`ResultsDir::commit`], its staging folder
/// is removed and the old results stay as they were.
#[derive(Debug)]
pub struct ResultsDir {
    target: PathBuf,
    staging: PathBuf,
    committed: bool,
    _lock: OutputLock,
}

impl ResultsDir {
    /// Lock `target`, repair what a killed run left, check that it may be replaced (new,
    /// empty, or with `force` holding only results), and create the staging folder.
    pub fn begin(target: &Path, force: bool) -> Result<Self> {
        let name = folder_name(target)?;
        check_folder_or_new(target)?;
        let parent = parent_of(target);
        std::fs::create_dir_all(&parent)
            .with_context(|| format!("cannot create folder {}", parent.display()))?;
        let lock = OutputLock::acquire(target)?;
        for note in repair(target)? {
            crate::tell!("note: {note}");
        }
        check_replaceable(target, force)?;
        let staging = parent.join(format!(".{name}.new-{}", std::process::id()));
        std::fs::create_dir(&staging)
            .with_context(|| format!("cannot create folder {}", staging.display()))?;
        crate::interrupt::staged(&staging);
        Ok(ResultsDir {
            target: target.to_path_buf(),
            staging,
            committed: false,
            _lock: lock,
        })
    }

    /// The folder to write the results into (the staging folder until the commit).
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Swap the new results in: rename the old folder aside, the new one into place, then
    /// remove the old one. Interrupts wait until the results are in place.
    pub fn commit(mut self) -> Result<()> {
        let _hold = crate::interrupt::hold_off();
        check_folder_or_new(&self.target)?;
        check_replaceable(&self.target, true)?;
        let old = sibling(&self.target, &format!("old-{}", std::process::id()));
        let moved = step_aside(&self.target, &old)?;
        if let Err(e) = step_in(&self.staging, &self.target) {
            if moved {
                let _ = std::fs::rename(&old, &self.target);
            }
            return Err(e);
        }
        self.committed = true;
        crate::interrupt::unstaged(&self.staging);
        crate::interrupt::written(self.target.display().to_string());
        sync_folder(&parent_of(&self.target));
        if moved {
            if let Err(e) = clear_old(&old) {
                crate::tell!("warning: {e:#}");
            }
        }
        Ok(())
    }
}

impl Drop for ResultsDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.staging);
            crate::interrupt::unstaged(&self.staging);
        }
    }
}

/// The last component of `target`, refused if it has none (`.`, `..`, `/`): the folder is
/// swapped by name in its parent.
fn folder_name(target: &Path) -> Result<String> {
    match target.components().next_back() {
        Some(std::path::Component::Normal(n)) => Ok(n.to_string_lossy().into_owned()),
        _ => bail!(
            "{}: give the output folder by name (e.g. out/fit): it is replaced as a whole",
            target.display()
        ),
    }
}

/// Refuse an output folder path that exists and is not a folder (a file, a device, a FIFO).
pub fn check_folder_or_new(target: &Path) -> Result<()> {
    match std::fs::symlink_metadata(target) {
        Ok(m) if m.is_dir() => Ok(()),
        Ok(m) if m.file_type().is_symlink() => bail!(
            "{} is a symbolic link; give the output folder itself (it is replaced as a whole)",
            target.display()
        ),
        Ok(_) => bail!(
            "{} exists and is not a folder; the results of this command go to a folder",
            target.display()
        ),
        Err(_) => Ok(()),
    }
}

/// Refuse to replace `target` if it holds results and `force` is not set, or if it holds
/// anything this program does not write (that would be lost).
pub fn check_replaceable(target: &Path, force: bool) -> Result<()> {
    let Ok(entries) = std::fs::read_dir(target) else {
        return Ok(());
    };
    let mut held = entries
        .map(|e| Ok(e?.file_name().to_string_lossy().into_owned()))
        .collect::<std::io::Result<Vec<String>>>()
        .with_context(|| format!("cannot read folder {}", target.display()))?;
    held.retain(|n| !is_temporary_name(n));
    held.sort();
    if let Some(stranger) = held.iter().find(|n| !RESULT_NAMES.contains(&n.as_str())) {
        bail!(
            "{} holds {stranger}, which stf-lab does not write; replacing the folder would lose \
             it: move it, or choose another output folder",
            target.display()
        );
    }
    if !held.is_empty() && !force {
        bail!(
            "{} already exists and is not empty; pass --force to replace its results",
            target.display()
        );
    }
    Ok(())
}

/// Step 1 of the swap: rename `target` (if it exists) to `old`. Whether it was moved.
pub fn step_aside(target: &Path, old: &Path) -> Result<bool> {
    if std::fs::symlink_metadata(target).is_err() {
        return Ok(false);
    }
    std::fs::rename(target, old).with_context(|| {
        format!(
            "cannot move the old results {} aside to {}",
            target.display(),
            old.display()
        )
    })?;
    Ok(true)
}

/// Step 2: rename the staging folder to `target`.
pub fn step_in(staging: &Path, target: &Path) -> Result<()> {
    std::fs::rename(staging, target).with_context(|| {
        format!(
            "cannot move the new results {} into place at {}",
            staging.display(),
            target.display()
        )
    })
}

/// Step 3: remove the old results.
pub fn clear_old(old: &Path) -> Result<()> {
    std::fs::remove_dir_all(old).with_context(|| {
        format!(
            "the new results are in place, but the old ones at {} could not be removed",
            old.display()
        )
    })
}

/// The tag of `name` if it is a swap folder of `target_name`: `.<name>.new-<pid>` or
/// `.<name>.old-<pid>` ("new" or "old").
fn swap_kind<'a>(name: &'a str, target_name: &str) -> Option<&'a str> {
    let rest = name.strip_prefix('.')?.strip_prefix(target_name)?;
    let (kind, pid) = rest.strip_prefix('.')?.split_once('-')?;
    let digits = !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit());
    (digits && (kind == "new" || kind == "old")).then_some(kind)
}

/// Under the output's lock: put the old results back if a run died between the swap's two
/// renames, and remove stale staging and old folders of `target`. What it did, in words.
pub fn repair(target: &Path) -> Result<Vec<String>> {
    let name = folder_name(target)?;
    let parent = parent_of(target);
    let Ok(entries) = std::fs::read_dir(&parent) else {
        return Ok(Vec::new());
    };
    let mut stale: Vec<(String, PathBuf)> = entries
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let file = e.file_name().to_string_lossy().into_owned();
            swap_kind(&file, &name).map(|k| (k.to_string(), e.path()))
        })
        .collect();
    stale.sort();
    let mut notes = Vec::new();
    if std::fs::symlink_metadata(target).is_err() {
        if let Some(i) = stale.iter().position(|(k, _)| k == "old") {
            let (_, old) = stale.remove(i);
            std::fs::rename(&old, target).with_context(|| {
                format!(
                    "{} is missing after an interrupted run; its previous results are at {} and \
                     cannot be moved back",
                    target.display(),
                    old.display()
                )
            })?;
            notes.push(format!(
                "a run into {0} was stopped while swapping its results in; the previous results \
                 were put back from {1}",
                target.display(),
                old.display()
            ));
        }
    }
    for (_, path) in stale {
        std::fs::remove_dir_all(&path).with_context(|| {
            format!(
                "cannot remove {}, left by an interrupted run",
                path.display()
            )
        })?;
        notes.push(format!(
            "removed {}, left by an interrupted run",
            path.display()
        ));
    }
    Ok(notes)
}

/// Make the renames in `folder` durable (best effort; a no-op where folders cannot be
/// opened as files).
fn sync_folder(folder: &Path) {
    if let Ok(f) = std::fs::File::open(folder) {
        let _ = f.sync_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) {
        std::fs::create_dir_all(dir).unwrap();
        std::fs::write(dir.join(name), text).unwrap();
    }

    fn read(dir: &Path, name: &str) -> String {
        std::fs::read_to_string(dir.join(name)).unwrap()
    }

    /// A temporary folder holding the results folder `fit/` of an earlier run (`fit.json`: A).
    fn old_results() -> (tempfile::TempDir, PathBuf) {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("fit");
        write(&out, "fit.json", "A");
        (tmp, out)
    }

    #[test]
    fn the_closing_line_names_only_what_was_written() {
        let out = Path::new("out");
        assert_eq!(
            wrote_line(out, &["fit.json", "params.csv"], false),
            "wrote out/fit.json and out/params.csv"
        );
        assert_eq!(
            wrote_line(out, &["fit.json"], true),
            "wrote out/fit.json, out/report.html, out/report.md and out/figures/"
        );
    }

    #[test]
    fn a_commit_replaces_the_whole_folder() {
        let (tmp, out) = old_results();
        write(&out, "report.md", "A");
        let run = ResultsDir::begin(&out, true).unwrap();
        write(run.path(), "fit.json", "B");
        assert_eq!(
            read(&out, "fit.json"),
            "A",
            "old results stand until the commit"
        );
        run.commit().unwrap();
        assert_eq!(read(&out, "fit.json"), "B");
        assert!(!out.join("report.md").exists(), "no old report is kept");
        let left: Vec<_> = std::fs::read_dir(tmp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(left.len(), 2, "{left:?}"); // the folder and its lock file
    }

    #[test]
    fn a_run_dropped_before_its_commit_leaves_the_old_results_and_no_staging() {
        let (_tmp, out) = old_results();
        let run = ResultsDir::begin(&out, true).unwrap();
        let staging = run.path().to_path_buf();
        write(&staging, "fit.json", "B");
        drop(run);
        assert!(!staging.exists());
        assert_eq!(read(&out, "fit.json"), "A");
    }

    #[test]
    fn a_crash_between_the_renames_is_repaired_by_the_next_run() {
        let (tmp, out) = old_results();
        // A run that stops after step 1: the output is missing, old and new lie beside it.
        let old = tmp.path().join(".fit.old-4242");
        let staging = tmp.path().join(".fit.new-4242");
        write(&staging, "fit.json", "B");
        assert!(step_aside(&out, &old).unwrap());
        assert!(!out.exists());
        let notes = repair(&out).unwrap();
        assert_eq!(read(&out, "fit.json"), "A", "the previous results are back");
        assert!(!old.exists() && !staging.exists());
        assert!(notes[0].contains("were put back from"), "{notes:?}");
        assert!(notes[1].contains(".fit.new-4242"), "{notes:?}");
    }

    #[test]
    fn a_crash_after_the_swap_leaves_the_new_results_and_the_old_is_cleaned() {
        let (tmp, out) = old_results();
        let old = tmp.path().join(".fit.old-4242");
        let staging = tmp.path().join(".fit.new-4242");
        write(&staging, "fit.json", "B");
        step_aside(&out, &old).unwrap();
        step_in(&staging, &out).unwrap();
        // Stopped before step 3.
        let notes = repair(&out).unwrap();
        assert_eq!(read(&out, "fit.json"), "B");
        assert!(!old.exists());
        assert_eq!(notes.len(), 1, "{notes:?}");
        // The next run starts clean.
        assert!(ResultsDir::begin(&out, true).is_ok());
    }

    #[test]
    fn repair_touches_only_its_own_names() {
        let (tmp, out) = old_results();
        for other in [".fit.new-x", ".fit.older-1", ".fits.new-1", "fit.new-1"] {
            write(&tmp.path().join(other), "keep", "");
        }
        assert!(repair(&out).unwrap().is_empty());
        for other in [".fit.new-x", ".fit.older-1", ".fits.new-1", "fit.new-1"] {
            assert!(tmp.path().join(other).exists(), "{other}");
        }
    }

    #[test]
    fn refuses_strangers_non_folders_and_unforced_replacement() {
        let (tmp, out) = old_results();
        let e = ResultsDir::begin(&out, false).unwrap_err().to_string();
        assert!(e.contains("pass --force"), "{e}");
        write(&out, "notes.txt", "mine");
        let e = ResultsDir::begin(&out, true).unwrap_err().to_string();
        assert!(e.contains("holds notes.txt"), "{e}");
        let file = tmp.path().join("file");
        write(tmp.path(), "file", "x");
        let e = ResultsDir::begin(&file, true).unwrap_err().to_string();
        assert!(e.contains("is not a folder"), "{e}");
        let e = ResultsDir::begin(Path::new("."), true)
            .unwrap_err()
            .to_string();
        assert!(e.contains("give the output folder by name"), "{e}");
    }

    #[test]
    fn a_folder_with_only_stray_temporaries_counts_as_empty() {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("fit");
        write(&out, ".fitted.123-0.tmp.csv", "half");
        let run = ResultsDir::begin(&out, false).unwrap();
        write(run.path(), "fit.json", "B");
        run.commit().unwrap();
        let names: Vec<_> = std::fs::read_dir(&out).unwrap().collect();
        assert_eq!(names.len(), 1);
    }
}
