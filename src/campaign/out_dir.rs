//! A campaign's output folder. It is not replaced as a whole like a command's (its finished
//! units are what a rerun resumes from): each unit's folder is (`crate::results_dir`), and
//! the table and report files are written atomically. The folder may hold only what a
//! campaign writes ([`CAMPAIGN_NAMES`]) and this program's temporaries: a folder holding
//! anything else (another command's results, notes) is refused before anything is written.
//! A campaign run holds the folder's lock (`crate::output_lock`) from start to end, so two
//! runs into one folder cannot interleave; a unit run alone (`--unit N`) locks its own folder.

use std::path::Path;

use anyhow::{bail, Context, Result};

use crate::output::is_temporary_name;
use crate::output_lock::OutputLock;

/// Every name a campaign writes in its output folder.
pub const CAMPAIGN_NAMES: &[&str] = &[
    super::unit::UNITS,
    super::runner::LOGS,
    super::slurm_script::SLURM,
    "campaign.json",
    "campaign.csv",
    super::global::GLOBAL_JSON,
    "report.md",
    "report.html",
    "figures",
];

/// Refuse `out` if it exists and is not a folder, or holds anything a campaign does not write.
pub fn check(out: &Path) -> Result<()> {
    crate::results_dir::check_folder_or_new(out)?;
    let Ok(entries) = std::fs::read_dir(out) else {
        return Ok(());
    };
    let mut names: Vec<String> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !is_temporary_name(n))
        .collect();
    names.sort();
    if let Some(stranger) = names.iter().find(|n| !CAMPAIGN_NAMES.contains(&n.as_str())) {
        bail!(
            "{} holds {stranger}, which a campaign does not write: give a new folder, or one a \
             campaign wrote (it resumes there)",
            out.display()
        );
    }
    Ok(())
}

/// Check `out`, create it and lock it for this run.
pub fn begin(out: &Path) -> Result<OutputLock> {
    check(out)?;
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create folder {}", out.display()))?;
    let lock = OutputLock::acquire(out)?;
    check(out)?;
    Ok(lock)
}
