//! One run at a time per output: an advisory lock (`fs4`, `flock`/`LockFileEx`) on a lock file
//! beside the output, `.<name>.lock`, held until the run ends. A second run into the same
//! output is refused at once with a message naming the process that holds it; the lock goes
//! with the process, so a killed run never leaves the output locked. The lock file itself
//! stays (removing it would let two runs lock two different files); it holds the last
//! holder's process id and nothing else.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// The lock file of output `target`: `.<name>.lock` in the same folder.
pub fn lock_path(target: &Path) -> PathBuf {
    crate::output::sibling(target, "lock")
}

/// A held lock; released when dropped (or when the process ends, however it ends).
#[derive(Debug)]
pub struct OutputLock {
    _file: File,
}

impl OutputLock {
    /// Lock output `target` (a file or a folder) for this run, or refuse if another run
    /// holds it. The folder that holds `target` must exist.
    pub fn acquire(target: &Path) -> Result<Self> {
        let path = lock_path(target);
        crate::output::check_regular_or_new(&path)?;
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&path)
            .with_context(|| format!("cannot open the lock file {}", path.display()))?;
        match fs4::FileExt::try_lock(&file) {
            Ok(()) => {}
            Err(fs4::TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                let holder = holder.trim();
                let who = if holder.chars().all(|c| c.is_ascii_digit()) && !holder.is_empty() {
                    format!("another stf-lab run (process {holder})")
                } else {
                    "another stf-lab run".to_string()
                };
                bail!(
                    "{} is being written by {who}; wait for it to finish or choose another output \
                     (lock file {})",
                    target.display(),
                    path.display()
                );
            }
            Err(fs4::TryLockError::Error(e)) => {
                bail!("cannot lock {}: {e}", path.display())
            }
        }
        // Best effort: the holder's id only makes the refusal's message more useful.
        let _ = file.set_len(0);
        let _ = file.rewind();
        let _ = write!(file, "{}", std::process::id());
        Ok(OutputLock { _file: file })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_on_one_output_is_refused_until_the_first_is_released() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("fit");
        let first = OutputLock::acquire(&target).unwrap();
        let e = OutputLock::acquire(&target).unwrap_err().to_string();
        assert!(e.contains("is being written by another stf-lab run"), "{e}");
        assert!(
            e.contains(&format!("process {}", std::process::id())),
            "{e}"
        );
        drop(first);
        assert!(OutputLock::acquire(&target).is_ok());
        assert!(dir.path().join(".fit.lock").is_file());
    }
}
