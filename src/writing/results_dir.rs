//! The output folder of `fit`, `compare` and `discover` is written as one unit. A run builds
//! its results in a staging folder beside the output, `.<name>.new-<pid>-<n>`, and swaps it
//! in at the end: the old folder is renamed to `.<name>.old-<pid>-<n>`, the new one to
//! `<name>`, and the old one removed ([`super::names`]' pattern). A reader, or a run killed
//! at any moment, sees the old results or the new ones, never a mix; a folder whose run
//! writes no report keeps no old report.
//!
//! The output is locked for the run ([`super::lock`]), so a second run into it is refused.
//! Under that lock, what a killed run left is ours to clean: [`repair`] puts the old folder
//! back if the run died between the two renames (the output missing, its `.old-` beside it)
//! and removes stale staging and old folders. `--force` replaces only a folder that holds
//! nothing but this program's results and temporaries, one level down included: the result
//! files ([`RESULT_FILES`]) as regular files, and `figures/` holding only figures (each an
//! SVG, a PNG and a CSV of one name: [`is_figure`]). Anything else (notes, the experiment's
//! record, a folder named like a result) would be lost, so it is named in an error and kept.
//!
//! The swap is split into plain steps ([`step_aside`], [`step_in`], [`clear_old`]) so tests
//! can stop between them as a crash would.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::lock::OutputLock;
use super::names::{self, Role};
use super::{is_temporary_name, parent_of};

/// Every file this program writes in an output folder (all commands).
pub const RESULT_FILES: &[&str] = &[
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
];

/// The folder of figures in an output folder.
pub const FIGURES: &str = "figures";

/// At most this many strangers are named in an error (then how many more).
const NAMED: usize = 8;

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
        folder_name(target)?;
        check_folder_or_new(target)?;
        // Checked before the lock too, so that a refused run leaves no lock file behind.
        check_replaceable(target, force)?;
        let parent = parent_of(target);
        super::atomic::ensure_dir(&parent)?;
        let lock = OutputLock::acquire(target)?;
        for note in repair(target)? {
            crate::tell!("note: {note}");
        }
        check_replaceable(target, force)?;
        let staging = names::temporary(target, Role::New);
        {
            let _w = crate::terminal::interrupt::writing();
            std::fs::create_dir(&staging)
                .with_context(|| format!("cannot create folder {}", staging.display()))?;
            crate::terminal::interrupt::staged(&staging);
        }
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
        let _hold = crate::terminal::interrupt::hold_off();
        check_folder_or_new(&self.target)?;
        check_replaceable(&self.target, true)?;
        let old = names::temporary(&self.target, Role::Old);
        let moved = step_aside(&self.target, &old)?;
        if let Err(e) = step_in(&self.staging, &self.target) {
            if moved {
                let _ = std::fs::rename(&old, &self.target);
            }
            return Err(e);
        }
        self.committed = true;
        crate::terminal::interrupt::unstaged(&self.staging);
        crate::terminal::interrupt::written(self.target.display().to_string());
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
            crate::terminal::interrupt::unstaged(&self.staging);
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
/// anything this program does not write, one level down included (that would be lost).
pub fn check_replaceable(target: &Path, force: bool) -> Result<()> {
    let Ok(held) = entries(target) else {
        return Ok(());
    };
    let mut strangers = Vec::new();
    for (name, kind) in &held {
        match (name.as_str(), kind) {
            (FIGURES, Kind::Folder) => strangers.extend(
                figure_strangers(&target.join(FIGURES))?
                    .into_iter()
                    .map(|s| format!("{FIGURES}/{s}")),
            ),
            (n, Kind::File) if RESULT_FILES.contains(&n) => {}
            _ => strangers.push(describe(target, name, *kind)),
        }
    }
    if !strangers.is_empty() {
        bail!(
            "{} holds {}, which stf-lab does not write; replacing the folder would lose it: \
             move it, or choose another output folder",
            target.display(),
            name_list(&strangers)
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

/// What an entry is: a regular file, a folder, or anything else (a link, a FIFO …).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    /// A regular file (not a link).
    File,
    /// A folder (not a link).
    Folder,
    /// A symbolic link, device, FIFO or socket.
    Other,
}

/// The entries of `folder` with their kinds, sorted, this program's temporaries left out.
pub fn entries(folder: &Path) -> Result<Vec<(String, Kind)>> {
    let read = std::fs::read_dir(folder)?;
    let mut held = Vec::new();
    for entry in read {
        let entry = entry.with_context(|| format!("cannot read folder {}", folder.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        if is_temporary_name(&name) {
            continue;
        }
        let kind = match entry.file_type() {
            Ok(t) if t.is_file() => Kind::File,
            Ok(t) if t.is_dir() => Kind::Folder,
            _ => Kind::Other,
        };
        held.push((name, kind));
    }
    held.sort();
    Ok(held)
}

/// `name`, a folder named with its first file (`fit.json/thesis.tex`) or a `/`.
pub fn describe(parent: &Path, name: &str, kind: Kind) -> String {
    if kind != Kind::Folder {
        return name.to_string();
    }
    match entries(&parent.join(name))
        .ok()
        .and_then(|e| e.into_iter().next())
    {
        Some((inner, inner_kind)) => format!(
            "{name}/{}",
            describe(&parent.join(name), &inner, inner_kind)
        ),
        None => format!("{name}/"),
    }
}

/// `a, b and c` (at most [`NAMED`], then how many more).
pub fn name_list(names: &[String]) -> String {
    let shown: Vec<&str> = names.iter().take(NAMED).map(String::as_str).collect();
    let more = names.len().saturating_sub(NAMED);
    match shown.split_last() {
        _ if more > 0 => format!("{} and {more} more", shown.join(", ")),
        Some((last, [])) => (*last).to_string(),
        Some((last, rest)) => format!("{} and {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// Whether `name` in a figures folder holding `names` is part of a figure: an SVG, a PNG and
/// a CSV of one stem, all three regular files.
pub fn is_figure(name: &str, files: &[&str]) -> bool {
    let Some((stem, ext)) = name.rsplit_once('.') else {
        return false;
    };
    ["svg", "png", "csv"].contains(&ext)
        && ["svg", "png", "csv"]
            .iter()
            .all(|e| files.contains(&format!("{stem}.{e}").as_str()))
}

/// What a figures folder holds besides figures and temporaries (sub-folders named with
/// their first file).
pub fn figure_strangers(dir: &Path) -> Result<Vec<String>> {
    let held = entries(dir)?;
    let files: Vec<&str> = held
        .iter()
        .filter(|(_, k)| *k == Kind::File)
        .map(|(n, _)| n.as_str())
        .collect();
    Ok(held
        .iter()
        .filter(|(n, k)| !(*k == Kind::File && is_figure(n, &files)))
        .map(|(n, k)| describe(dir, n, *k))
        .collect())
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

/// The role of `name` if it is a swap folder of `target_name` (staging or old results).
fn swap_kind(name: &str, target_name: &str) -> Option<Role> {
    names::parse(name)
        .filter(|t| t.of == target_name && t.role != Role::Commit)
        .map(|t| t.role)
}

/// Under the output's lock: put the old results back if a run died between the swap's two
/// renames, and remove stale staging and old folders of `target`. What it did, in words.
pub fn repair(target: &Path) -> Result<Vec<String>> {
    let name = folder_name(target)?;
    let parent = parent_of(target);
    let Ok(entries) = std::fs::read_dir(&parent) else {
        return Ok(Vec::new());
    };
    let mut stale: Vec<(bool, PathBuf)> = entries
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let file = e.file_name().to_string_lossy().into_owned();
            swap_kind(&file, &name).map(|k| (k == Role::Old, e.path()))
        })
        .collect();
    stale.sort();
    let mut notes = Vec::new();
    if std::fs::symlink_metadata(target).is_err() {
        if let Some(i) = stale.iter().position(|(old, _)| *old) {
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
        let removed = match path.is_dir() {
            true => std::fs::remove_dir_all(&path),
            false => std::fs::remove_file(&path),
        };
        removed.with_context(|| {
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
/// opened as files). Shared with [`super::staged_files`].
pub(super) fn sync_folder(folder: &Path) {
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
        assert_eq!(left, ["fit"], "the folder alone: no staging, no lock file");
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
    fn strangers_one_level_down_are_named_and_kept() {
        let (_tmp, out) = old_results();
        for stem in ["loop_x", "parity"] {
            for ext in ["svg", "png", "csv"] {
                write(&out.join("figures"), &format!("{stem}.{ext}"), "f");
            }
        }
        assert!(check_replaceable(&out, true).is_ok(), "figures are results");
        write(&out.join("figures"), "mynotes.txt", "mine");
        write(&out.join("figures/sub"), "data.bin", "x");
        write(&out.join("figures"), "lone.csv", "a,b");
        std::fs::remove_file(out.join("fit.json")).unwrap();
        write(&out.join("fit.json"), "thesis.tex", "mine");
        let e = ResultsDir::begin(&out, true).unwrap_err().to_string();
        for named in [
            "figures/lone.csv",
            "figures/mynotes.txt",
            "figures/sub/data.bin",
            "fit.json/thesis.tex",
        ] {
            assert!(e.contains(named), "{named}: {e}");
        }
        assert!(!e.contains("loop_x"), "{e}");
        assert_eq!(read(&out, "figures/sub/data.bin"), "x");
        assert_eq!(read(&out, "fit.json/thesis.tex"), "mine");
    }

    #[test]
    fn a_refused_run_leaves_no_lock_file() {
        let (tmp, out) = old_results();
        write(&out, "notes.txt", "mine");
        assert!(ResultsDir::begin(&out, true).is_err());
        assert!(ResultsDir::begin(&out, false).is_err());
        let mut left: Vec<_> = std::fs::read_dir(tmp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(left, ["fit"]);
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
