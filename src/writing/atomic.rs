//! The one way a file is written: its content goes to a temporary file beside the target
//! (same folder, [`super::names`]' pattern), is synced, then renamed over the target —
//! `tempfile`'s `NamedTempFile::persist`, which also removes the temporary when a write
//! fails. A crash never leaves a half-written file under the final name, and what it leaves
//! is recognised and removed by the next run. A target that exists and is not a regular file
//! (a device, FIFO, socket or folder, or a link to one) is refused: the rename would put a
//! file in its place. Each write holds [`crate::terminal::interrupt::writing`], so an interrupt waits
//! for it and none starts once an interrupt is handled.
//!
//! Records, results, figures, reports, campaign tables, scripts and logs are all written
//! here: [`write_atomic`] for bytes, [`write_with`] for a writer that streams (a record:
//! `stf_core` writes to any `impl Write`), [`AtomicFile`] for a file filled by someone else
//! (a child process's log) and put in place later.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use super::names::{temporary, Role};

/// Why a file could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// The target exists and is not a regular file.
    #[error("{} is not a regular file (a device, FIFO, socket or folder); outputs go only to regular files or new paths", path.display())]
    NotRegularFile {
        /// The target.
        path: PathBuf,
    },
    /// Creating, writing, syncing or renaming failed.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The target (or the folder being created).
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

impl WriteError {
    fn io(path: &Path) -> impl Fn(std::io::Error) -> WriteError + '_ {
        move |source| WriteError::Io {
            path: path.to_path_buf(),
            source,
        }
    }
}

/// The folder holding `path` (`.` for a bare name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// A file being written beside its target under a temporary name; [`AtomicFile::commit`]
/// syncs it and renames it over the target; dropped without that, it is removed.
#[derive(Debug)]
pub struct AtomicFile {
    file: tempfile::NamedTempFile,
    target: PathBuf,
}

impl AtomicFile {
    /// Create the temporary file of `target` (refused if `target` is not a regular file or
    /// new).
    pub fn create(target: &Path) -> Result<Self, WriteError> {
        let _w = crate::terminal::interrupt::writing();
        Self::create_unguarded(target)
    }

    fn create_unguarded(target: &Path) -> Result<Self, WriteError> {
        if std::fs::metadata(target).is_ok_and(|m| !m.is_file()) {
            return Err(WriteError::NotRegularFile {
                path: target.to_path_buf(),
            });
        }
        let mut last = None;
        // A name left by a killed process with the same id is skipped.
        for _ in 0..8 {
            let tmp = temporary(target, Role::New);
            let name = tmp
                .file_name()
                .map(|n| n.to_os_string())
                .unwrap_or_default();
            let mut builder = tempfile::Builder::new();
            builder.prefix(&name).rand_bytes(0);
            // A result file, not a secret: the mode a plain `File::create` gives (0o666 less
            // the umask), not the temporary file's 0o600.
            #[cfg(unix)]
            builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
            match builder.tempfile_in(folder_of(target)) {
                Ok(file) => {
                    return Ok(AtomicFile {
                        file,
                        target: target.to_path_buf(),
                    })
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => last = Some(e),
                Err(e) => return Err(WriteError::io(target)(e)),
            }
        }
        Err(WriteError::io(target)(last.unwrap_or_else(|| {
            std::io::ErrorKind::AlreadyExists.into()
        })))
    }

    /// The file being written.
    pub fn as_file(&self) -> &File {
        self.file.as_file()
    }

    /// Where it is being written.
    pub fn path(&self) -> &Path {
        self.file.path()
    }

    /// Sync the file and rename it over its target.
    pub fn commit(self) -> Result<(), WriteError> {
        let _w = crate::terminal::interrupt::writing();
        self.commit_unguarded()
    }

    fn commit_unguarded(self) -> Result<(), WriteError> {
        let io = WriteError::io(&self.target);
        self.file.as_file().sync_all().map_err(&io)?;
        if std::fs::metadata(&self.target).is_ok_and(|m| !m.is_file()) {
            return Err(WriteError::NotRegularFile {
                path: self.target.clone(),
            });
        }
        self.file
            .persist(&self.target)
            .map(|_| ())
            .map_err(|e| io(e.error))
    }
}

/// Write `path` atomically from `fill`, which writes the content to a buffered writer.
pub fn write_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), WriteError> {
    super::failpoint(&format!("write:{}", super::names::file_name(path)));
    let _w = crate::terminal::interrupt::writing();
    write_unguarded(path, fill)
}

/// [`write_with`] without the interrupt guard: for a caller that holds it already.
pub(super) fn write_unguarded(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), WriteError> {
    let staged = AtomicFile::create_unguarded(path)?;
    {
        let mut out = BufWriter::with_capacity(1 << 16, staged.as_file());
        fill(&mut out)
            .and_then(|()| out.flush())
            .map_err(WriteError::io(path))?;
    }
    staged.commit_unguarded()
}

/// Write `bytes` to `path` atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    write_with(path, |out| out.write_all(bytes))
}

/// Create `dir` (and its parents) if missing.
pub fn ensure_dir(dir: &Path) -> Result<(), WriteError> {
    if dir.as_os_str().is_empty() {
        return Ok(());
    }
    let _w = crate::terminal::interrupt::writing();
    std::fs::create_dir_all(dir).map_err(WriteError::io(dir))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut n: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        n.sort();
        n
    }

    #[cfg(unix)]
    #[test]
    fn a_written_file_has_the_mode_a_plain_create_gives() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("plain.txt");
        std::fs::write(&plain, b"x").unwrap();
        let ours = dir.path().join("ours.txt");
        write_atomic(&ours, b"x").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&ours), mode(&plain));
    }

    #[test]
    fn replaces_content_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.csv");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        assert_eq!(names(dir.path()), ["a.csv"]);
    }

    #[test]
    fn a_failed_fill_leaves_the_old_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("rec.csv");
        write_atomic(&p, b"old").unwrap();
        let e = write_with(&p, |out| {
            out.write_all(b"half")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert!(e.to_string().contains("rec.csv") && e.to_string().contains("disk full"));
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(names(dir.path()), ["rec.csv"]);
    }

    #[test]
    fn refuses_to_replace_what_is_not_a_regular_file() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        let e = write_atomic(&sub, b"x").unwrap_err();
        assert!(matches!(e, WriteError::NotRegularFile { .. }), "{e}");
        assert!(sub.is_dir());
    }

    #[test]
    fn a_file_filled_elsewhere_goes_in_whole_or_not_at_all() {
        let dir = tempfile::tempdir().unwrap();
        let log = dir.path().join("001-r.log");
        std::fs::write(&log, "last run\n").unwrap();
        let staged = AtomicFile::create(&log).unwrap();
        let name = staged
            .path()
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        assert!(
            super::super::names::is_temporary_of(&name, "001-r.log"),
            "{name}"
        );
        staged.as_file().write_all(b"this run\n").unwrap();
        assert_eq!(std::fs::read_to_string(&log).unwrap(), "last run\n");
        staged.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&log).unwrap(), "this run\n");
        drop(AtomicFile::create(&log).unwrap());
        assert_eq!(names(dir.path()), ["001-r.log"]);
    }
}
