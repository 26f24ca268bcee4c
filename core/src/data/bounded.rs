//! Reading outside input with a cap on its size: a file (or stream) larger than the cap is
//! refused with its size and the cap instead of being read into memory whole.
//!
//! Every reader of outside input — records, experiment files, scripts — goes through
//! [`read_file`] or [`read_to_end`] (or, streaming, counts what it has read against the same
//! kind of cap), so that a mistaken path such as `/dev/zero`, or a file far larger than any
//! record, ends in a clear error instead of exhausting the machine's memory. The cap is
//! checked twice: against the file's length before reading (a regular file is refused at
//! once) and while reading (a device or pipe that does not end is stopped one byte past it).

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
    let mut data = Vec::new();
    reader
        .take(limit.saturating_add(1))
        .read_to_end(&mut data)?;
    if data.len() as u64 > limit {
        return Err(BoundedError::TooLarge { size: None, limit });
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

/// Read the file at `path`, refusing it when it holds more than `limit` bytes.
pub fn read_file(path: &Path, limit: u64) -> Result<Vec<u8>, BoundedError> {
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
