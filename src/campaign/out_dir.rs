//! A campaign's output folder. It is not replaced as a whole like a command's (its finished
//! units are what a rerun resumes from): each unit's folder is
//! (`crate::writing::results_dir`), and the tables and report are put in place as one unit
//! (`crate::writing::staged_files`). The folder may hold only what a campaign writes
//! ([`CAMPAIGN_FILES`] as files, [`CAMPAIGN_FOLDERS`] as folders and `figures/` holding only figures) and
//! this program's temporaries: a folder holding anything else (another command's results,
//! notes) is refused before anything is written, naming what it holds. A campaign run holds
//! the folder's lock (`crate::writing::lock`) from start to end, so two runs into one folder
//! cannot interleave; under it, [`begin`] finishes the commit of tables a killed run left and
//! removes its temporaries. A unit run alone (`--unit N`) locks its own folder.

use std::path::Path;

use anyhow::{bail, Context, Result};

use crate::writing::lock::OutputLock;
use crate::writing::results_dir::{
    check_folder_or_new, describe, entries, figure_strangers, name_list, Kind, FIGURES,
};
use crate::writing::staged_files::finish_commits;
use crate::writing::{clean_folder, clean_stale};

/// The files a campaign writes at the top of its folder; the first is the first of the
/// tables' commit.
pub const CAMPAIGN_FILES: &[&str] = &[
    "campaign.json",
    "campaign.csv",
    super::global::GLOBAL_JSON,
    "report.md",
    "report.html",
];

/// The folders a campaign writes in its folder.
pub const CAMPAIGN_FOLDERS: &[&str] = &[
    super::unit::UNITS,
    super::runner::LOGS,
    super::slurm_script::SLURM,
    FIGURES,
];

/// Refuse `out` if it exists and is not a folder, or holds anything a campaign does not
/// write (one level down in `figures/`).
pub fn check(out: &Path) -> Result<()> {
    check_folder_or_new(out)?;
    let Ok(held) = entries(out) else {
        return Ok(());
    };
    let mut strangers = Vec::new();
    for (name, kind) in &held {
        match kind {
            Kind::Folder if name == FIGURES => strangers.extend(
                figure_strangers(&out.join(FIGURES))?
                    .into_iter()
                    .map(|s| format!("{FIGURES}/{s}")),
            ),
            Kind::Folder if CAMPAIGN_FOLDERS.contains(&name.as_str()) => {}
            Kind::File if CAMPAIGN_FILES.contains(&name.as_str()) => {}
            _ => strangers.push(describe(out, name, *kind)),
        }
    }
    if !strangers.is_empty() {
        bail!(
            "{} holds {}, which a campaign does not write: give a new folder, or one a \
             campaign wrote (it resumes there)",
            out.display(),
            name_list(&strangers)
        );
    }
    Ok(())
}

/// Check `out`, create it and lock it for this run; then finish what a killed run left
/// half done (the tables' commit) and remove its temporaries. (Checked before the lock
/// too: a refused run leaves no lock file.)
pub fn begin(out: &Path) -> Result<OutputLock> {
    check(out)?;
    crate::writing::atomic::ensure_dir(out)
        .with_context(|| format!("cannot create folder {}", out.display()))?;
    let lock = OutputLock::acquire(out)?;
    check(out)?;
    for note in finish_commits(&out.join(CAMPAIGN_FILES[0]))? {
        crate::tell!("note: {note}");
    }
    for name in CAMPAIGN_FILES {
        for stale in clean_stale(&out.join(name))? {
            crate::tell!(
                "note: removed {stale} in {}, left by an interrupted run",
                out.display()
            );
        }
    }
    for stale in clean_folder(&out.join(super::runner::LOGS))? {
        crate::tell!(
            "note: removed {stale} in {}, left by an interrupted run",
            out.join(super::runner::LOGS).display()
        );
    }
    Ok(lock)
}
