//! Reading outside input with a cap on its size: a file (or stream) larger than the cap is
//! refused with its size and the cap instead of being read into memory whole.
//!
//! Every reader of outside input — records, experiment files, scripts — goes through
//! [`read_file`] or [`read_to_end`] (or, streaming, counts what it has read against the same
//! kind of cap), so that a mistaken path such as `/dev/zero`, or a file far larger than any
//! record, ends in a clear error instead of exhausting the machine's memory. The cap is
//! checked twice: against the file's length before reading (a regular file is refused at
//! once) and while reading (a device or pipe that does not end is stopped one byte past it).
//! A cap raised past the memory this machine has available ([`crate::data::memory`]) is
//! lowered to it, so a raised `max_bytes` cannot make a read abort the process.

use std::io::Read;
use std::path::Path;

use thiserror::Error;

/// A capped read failed.
#[derive(Debug, Error)]
pub enum BoundedError {
    /// The input is larger than the cap.
    #[error("{}", too_large(*size, *limit))]
    TooLarge {
        /// The input's size in bytes, when known (a regular file); `None` for a stream that
        /// ran past the cap.
        size: Option<u64>,
        /// The cap, bytes.
        limit: u64,
    },
    /// The input is larger than the memory available to read it into, under a cap raised
    /// past that memory.
    #[error(
        "holds more than the {} of memory this machine has available (the cap, {}, is more \
         than the machine can hold)",
        super::memory::gigabytes(*available as f64),
        byte_size(*limit)
    )]
    NoMemory {
        /// Memory available, bytes.
        available: u64,
        /// The cap asked for, bytes.
        limit: u64,
    },
    /// The input could not be read.
    #[error("cannot read: {0}")]
    Io(#[from] std::io::Error),
}

/// `is N bytes, over the limit of M bytes` (or `holds more than …` for a stream).
fn too_large(size: Option<u64>, limit: u64) -> String {
    match size {
        Some(size) => format!(
            "is {}, over the limit of {}",
            byte_size(size),
            byte_size(limit)
        ),
        None => format!("holds more than the limit of {}", byte_size(limit)),
    }
}

/// A size for messages: exact bytes, and MB when it is large.
pub fn byte_size(bytes: u64) -> String {
    if bytes >= 1_000_000 {
        format!("{bytes} bytes ({:.1} MB)", bytes as f64 / 1e6)
    } else {
        format!("{bytes} bytes")
    }
}

/// Read all of `reader`, refusing it once it holds more than `limit` bytes (at most
/// `limit + 1` bytes are read).
pub fn read_to_end<R: Read>(reader: R, limit: u64) -> Result<Vec<u8>, BoundedError> {
    read_within(reader, limit, super::memory::available())
}

/// [`read_to_end`] on a machine with `available` bytes of memory (if known): a cap above half
/// of it (what a growing buffer may need twice over) is lowered to that half.
fn read_within<R: Read>(
    reader: R,
    limit: u64,
    available: Option<u64>,
) -> Result<Vec<u8>, BoundedError> {
    let room = available.map_or(u64::MAX, |a| a / 2);
    let cap = limit.min(room);
    let mut data = Vec::new();
    reader.take(cap.saturating_add(1)).read_to_end(&mut data)?;
    if data.len() as u64 > cap {
        return Err(match available {
            Some(available) if cap < limit => BoundedError::NoMemory { available, limit },
            _ => BoundedError::TooLarge { size: None, limit },
        });
    }
    Ok(data)
}

/// The size of the file at `path` if it is a regular file larger than `limit`: such a file
/// is refused before anything is read.
pub fn check_len(path: &Path, limit: u64) -> Result<(), BoundedError> {
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_file() && meta.len() > limit => Err(BoundedError::TooLarge {
            size: Some(meta.len()),
            limit,
        }),
        _ => Ok(()),
    }
}

/// What is at `path` (following links) when it is neither a regular file nor a device: a
/// folder, a FIFO or a socket. A FIFO is named before it is opened, since opening one waits
/// for a writer that may never come.
pub fn not_readable_kind(path: &Path) -> Option<&'static str> {
    let kind = std::fs::metadata(path).ok()?.file_type();
    if kind.is_dir() {
        return Some("a folder");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if kind.is_socket() {
            return Some("a socket");
        }
    }
    None
}

/// Why the path a record is read from is not one: `None` for a regular file; else "no such
/// record: PATH" or "PATH is a folder, not a record file" (a FIFO, socket or device likewise,
/// `/dev/zero` included).
pub fn record_path_problem(path: &Path) -> Option<String> {
    let Ok(meta) = std::fs::metadata(path) else {
        return Some(format!(
            "no such record: {}{}",
            path.display(),
            crate::names::nearby_file(path)
        ));
    };
    if meta.is_file() {
        return None;
    }
    let what = not_readable_kind(path).unwrap_or("a device");
    Some(format!("{} is {what}, not a record file", path.display()))
}

/// Read the file at `path`, refusing it when it holds more than `limit` bytes, and a folder,
/// FIFO or socket at once ([`not_readable_kind`]: reading a FIFO could wait forever).
pub fn read_file(path: &Path, limit: u64) -> Result<Vec<u8>, BoundedError> {
    if let Some(what) = not_readable_kind(path) {
        return Err(BoundedError::Io(std::io::Error::other(format!(
            "it is {what}, not a file"
        ))));
    }
    check_len(path, limit)?;
    read_to_end(std::fs::File::open(path)?, limit)
}

/// [`read_file`] as UTF-8 text.
pub fn read_file_to_string(path: &Path, limit: u64) -> Result<String, BoundedError> {
    let bytes = read_file(path, limit)?;
    String::from_utf8(bytes).map_err(|e| {
        BoundedError::Io(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        ))
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::*;

    #[test]
    fn a_stream_past_the_cap_is_refused_after_reading_one_byte_more() {
        let endless = std::io::repeat(0u8);
        let e = read_to_end(endless, 1000).unwrap_err();
        assert!(matches!(
            e,
            BoundedError::TooLarge {
                size: None,
                limit: 1000
            }
        ));
        assert_eq!(e.to_string(), "holds more than the limit of 1000 bytes");
        assert_eq!(read_to_end(&[7u8; 1000][..], 1000).unwrap().len(), 1000);
    }

    #[test]
    fn a_file_over_the_cap_is_refused_with_its_size_before_reading() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.toml");
        std::fs::write(&path, vec![b'#'; 2_000_001]).unwrap();
        let e = read_file(&path, 2_000_000).unwrap_err();
        assert!(matches!(
            e,
            BoundedError::TooLarge {
                size: Some(2_000_001),
                ..
            }
        ));
        assert_eq!(
            e.to_string(),
            "is 2000001 bytes (2.0 MB), over the limit of 2000000 bytes (2.0 MB)"
        );
        assert_eq!(
            read_file_to_string(&path, 2_000_001).unwrap().len(),
            2_000_001
        );
    }

    #[test]
    fn a_cap_raised_past_the_machine_s_memory_stops_at_half_of_it() {
        // As if the machine had 10 kB free: /dev/zero under a cap of 10¹⁵ bytes stops at 5 kB.
        let endless = std::io::repeat(0u8);
        let e = read_within(endless, 1_000_000_000_000_000, Some(10_000)).unwrap_err();
        assert!(
            matches!(
                e,
                BoundedError::NoMemory {
                    available: 10_000,
                    limit: 1_000_000_000_000_000
                }
            ),
            "{e}"
        );
        assert!(
            e.to_string()
                .starts_with("holds more than the 0 MB of memory"),
            "{e}"
        );
        assert_eq!(
            read_within(&[1u8; 5000][..], u64::MAX, Some(10_000))
                .unwrap()
                .len(),
            5000
        );
    }

    #[cfg(unix)]
    #[test]
    fn folders_fifos_and_devices_are_named_and_a_fifo_is_never_opened() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("pipe");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        // No writer: opening it would block this test forever.
        let e = read_file(&fifo, 1000).unwrap_err();
        assert_eq!(
            e.to_string(),
            "cannot read: it is a FIFO (named pipe), not a file"
        );
        let e = read_file(dir.path(), 1000).unwrap_err();
        assert_eq!(e.to_string(), "cannot read: it is a folder, not a file");
        let shown = |p: &Path| record_path_problem(p).unwrap();
        assert!(shown(&fifo).ends_with("pipe is a FIFO (named pipe), not a record file"));
        assert!(shown(dir.path()).ends_with(" is a folder, not a record file"));
        assert_eq!(
            shown(Path::new("/dev/zero")),
            "/dev/zero is a device, not a record file"
        );
        assert_eq!(
            shown(Path::new("/no/such.csv")),
            "no such record: /no/such.csv"
        );
        let file = dir.path().join("r.csv");
        std::fs::write(&file, "t,x\n").unwrap();
        assert_eq!(record_path_problem(&file), None);
    }

    #[cfg(unix)]
    #[test]
    fn dev_zero_is_refused_at_the_cap() {
        let e = read_file(Path::new("/dev/zero"), 4096).unwrap_err();
        assert!(
            matches!(
                e,
                BoundedError::TooLarge {
                    size: None,
                    limit: 4096
                }
            ),
            "{e}"
        );
    }
}
