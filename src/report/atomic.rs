//! Atomic file writes: the content goes to a temporary file beside the target (same folder,
//! same extension, so format-sniffing writers such as the PNG encoder still work), synced, then
//! renamed over the target — `tempfile`'s `NamedTempFile::persist`, which also removes the
//! temporary when a write fails. A crash never leaves a half-written file under the final
//! name; the temporary's name (`.name.<pid>-<n>.tmp.ext`) is one that a later run recognises
//! as stale ([`crate::output::is_temporary_name`]). A target that exists and is not a regular
//! file (a device, FIFO, socket or folder, or a link to one) is refused: the rename would put a
//! file in its place.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use super::ReportError;

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// A fresh temporary path beside `path` that keeps its extension: `.name.<pid>-<n>.tmp.ext`.
pub fn temporary_sibling(path: &Path) -> PathBuf {
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let ext = path
        .extension()
        .map(|e| format!(".{}", e.to_string_lossy()))
        .unwrap_or_default();
    path.with_file_name(format!(".{stem}.{}-{n}.tmp{ext}", std::process::id()))
}

/// Write `bytes` to `path` atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), ReportError> {
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        return Err(ReportError::NotRegularFile {
            path: path.to_path_buf(),
        });
    }
    let tmp = temporary_sibling(path);
    let io = |source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = tmp
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    let mut builder = tempfile::Builder::new();
    builder.prefix(&name).rand_bytes(0);
    // A result file, not a secret: the mode a plain `File::create` gives (0o666 less the
    // umask), not the temporary file's 0o600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut file = builder.tempfile_in(dir).map_err(io)?;
    file.write_all(bytes).map_err(io)?;
    file.as_file().sync_all().map_err(io)?;
    file.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

/// Create `dir` (and its parents) if missing.
pub fn ensure_dir(dir: &Path) -> Result<(), ReportError> {
    if dir.as_os_str().is_empty() {
        return Ok(());
    }
    std::fs::create_dir_all(dir).map_err(|source| ReportError::Io {
        path: dir.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn refuses_to_replace_what_is_not_a_regular_file() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        let e = write_atomic(&sub, b"x").unwrap_err();
        assert!(matches!(e, ReportError::NotRegularFile { .. }), "{e}");
        assert!(sub.is_dir());
    }

    #[test]
    fn temporary_sibling_keeps_folder_and_extension() {
        let p = Path::new("/some/dir/fig.png");
        let a = temporary_sibling(p);
        let b = temporary_sibling(p);
        assert_eq!(a.parent(), p.parent());
        assert_eq!(a.extension().unwrap(), "png");
        assert_ne!(a, b);
    }
}
