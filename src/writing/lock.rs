//! One run at a time per output: an advisory lock (`fs4`, `flock`/`LockFileEx`) on a lock file
//! beside the output, `.<name>.lock`, held until the run ends. A second run into the same
//! output is refused at once with a message naming the process that holds it; the lock goes
//! with the process, so a killed run never leaves the output locked.
//!
//! The lock file is removed when the lock is released, so a run leaves nothing beside its
//! output (not in `/` for `--out /tmp`, not in `pl/` for `--out pl/figures`). Removing it is
//! safe because the holder removes it while still holding the lock, and a run that locks a
//! file checks that it is still the one at the lock's path (else it was removed under it,
//! and it tries again). A lock left by a killed run is taken over and removed in the end.
//!
//! Within one process locks are shared: a campaign unit holds its folder's lock from start to
//! end, and the command it runs locks the same folder again without being refused.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, Weak};

use anyhow::{bail, Context, Result};

use super::{check_regular_or_new, names::sibling, resolve};

/// The lock file of output `target`: `.<name>.lock` in the same folder.
pub fn lock_path(target: &Path) -> PathBuf {
    sibling(target, "lock")
}

/// A lock file held by this process; removed, then unlocked, when the last holder drops it.
#[derive(Debug)]
struct Held {
    path: PathBuf,
    _file: File,
}

impl Drop for Held {
    fn drop(&mut self) {
        // Still locked here: the file closes (and unlocks) after this.
        let _ = std::fs::remove_file(&self.path);
        crate::terminal::interrupt::unstaged(&self.path);
    }
}

/// The locks this process holds, by resolved lock path.
static HELD: Mutex<Vec<(PathBuf, Weak<Held>)>> = Mutex::new(Vec::new());

/// A held lock; released when the last copy is dropped (or when the process ends, however it
/// ends).
#[derive(Clone, Debug)]
pub struct OutputLock {
    _held: Arc<Held>,
}

impl OutputLock {
    /// Lock output `target` (a file or a folder) for this run, or refuse if another run
    /// holds it. The folder that holds `target` must exist.
    pub fn acquire(target: &Path) -> Result<Self> {
        let path = lock_path(target);
        check_regular_or_new(&path)?;
        let key = resolve(&path);
        let mut held = HELD.lock().unwrap_or_else(|e| e.into_inner());
        held.retain(|(_, w)| w.strong_count() > 0);
        if let Some(lock) = held
            .iter()
            .find(|(k, _)| *k == key)
            .and_then(|(_, w)| w.upgrade())
        {
            return Ok(OutputLock { _held: lock });
        }
        let file = lock_file(target, &path)?;
        // An interrupt removes the lock file as it removes staged results (still holding it).
        crate::terminal::interrupt::staged(&path);
        let lock = Arc::new(Held { path, _file: file });
        held.push((key, Arc::downgrade(&lock)));
        Ok(OutputLock { _held: lock })
    }
}

/// Open and lock the lock file `path` of `target`, the one at that path when it is locked.
fn lock_file(target: &Path, path: &Path) -> Result<File> {
    for _ in 0..16 {
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .with_context(|| format!("cannot open the lock file {}", path.display()))?;
        match fs4::FileExt::try_lock(&file) {
            Ok(()) => {}
            Err(fs4::TryLockError::WouldBlock) => {
                let mut holder = String::new();
                let _ = file.read_to_string(&mut holder);
                bail!(
                    "{} is being written by {}; wait for it to finish or choose another output \
                     (lock file {})",
                    target.display(),
                    holder_words(holder.trim()),
                    path.display()
                );
            }
            Err(fs4::TryLockError::Error(e)) => bail!("cannot lock {}: {e}", path.display()),
        }
        if !same_file(&file, path) {
            continue; // removed by its last holder between our open and our lock
        }
        // Best effort: the holder's id only makes the refusal's message more useful.
        let _ = file.set_len(0);
        let _ = file.rewind();
        let _ = write!(file, "{}", std::process::id());
        return Ok(file);
    }
    bail!("cannot lock {}: it keeps being replaced", path.display())
}

/// `another stf-lab run (process N)`.
fn holder_words(holder: &str) -> String {
    if !holder.is_empty() && holder.chars().all(|c| c.is_ascii_digit()) {
        format!("another stf-lab run (process {holder})")
    } else {
        "another stf-lab run".to_string()
    }
}

/// Whether the open `file` is the file now at `path`.
#[cfg(unix)]
fn same_file(file: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_: &File, path: &Path) -> bool {
    path.exists()
}

/// Whether another process holds the lock of `target` now (a lock left by a killed process
/// is not held).
pub fn is_held_elsewhere(target: &Path) -> bool {
    let path = lock_path(target);
    let key = resolve(&path);
    let ours = HELD
        .lock()
        .map(|h| h.iter().any(|(k, w)| *k == key && w.strong_count() > 0))
        .unwrap_or(false);
    if ours {
        return false;
    }
    let Ok(file) = File::open(&path) else {
        return false;
    };
    match fs4::FileExt::try_lock_shared(&file) {
        Ok(()) => {
            let _ = fs4::FileExt::unlock(&file);
            false
        }
        Err(_) => true,
    }
}

/// The process id written in `target`'s lock file, if any.
pub fn holder(target: &Path) -> Option<String> {
    let text = std::fs::read_to_string(lock_path(target)).ok()?;
    let text = text.trim();
    (!text.is_empty() && text.chars().all(|c| c.is_ascii_digit())).then(|| text.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::process::Command;

    #[test]
    fn a_lock_is_shared_within_the_process_and_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("fit");
        let first = OutputLock::acquire(&target).unwrap();
        let again = OutputLock::acquire(&dir.path().join("./fit")).unwrap();
        assert!(dir.path().join(".fit.lock").is_file());
        assert!(!is_held_elsewhere(&target));
        drop(first);
        assert!(
            dir.path().join(".fit.lock").is_file(),
            "still held by `again`"
        );
        drop(again);
        assert!(!dir.path().join(".fit.lock").exists());
    }

    #[test]
    fn a_lock_held_by_another_process_is_refused_and_named() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("fit");
        let path = lock_path(&target);
        // `flock` from util-linux holds the lock while `sleep` runs (`-o`: itself, not the
        // `sleep`); skip without it.
        let Ok(mut child) = Command::new("flock")
            .arg("-o")
            .arg(&path)
            .args(["sleep", "30"])
            .spawn()
        else {
            return;
        };
        while !is_held_elsewhere(&target) {
            if child.try_wait().unwrap().is_some() {
                return; // no usable `flock`
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        std::fs::write(&path, "4242").unwrap();
        let e = OutputLock::acquire(&target).unwrap_err().to_string();
        assert!(
            e.contains("is being written by another stf-lab run (process 4242)"),
            "{e}"
        );
        assert_eq!(holder(&target).as_deref(), Some("4242"));
        child.kill().unwrap();
        child.wait().unwrap();
        assert!(!is_held_elsewhere(&target));
        let lock = OutputLock::acquire(&target).unwrap();
        drop(lock);
        assert!(!path.exists());
    }
}
