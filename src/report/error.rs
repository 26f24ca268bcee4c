//! The errors of figure and report writing: bad input data, a file that cannot be written, a
//! plot that cannot be drawn.

use std::path::PathBuf;

/// Why a figure or a report could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// Series that must be paired have different lengths.
    #[error("{what}: lengths differ ({left} and {right} samples)")]
    LengthMismatch {
        /// Which series.
        what: String,
        /// Length of the first.
        left: usize,
        /// Length of the second.
        right: usize,
    },
    /// A series has no finite value to plot.
    #[error("{what}: no finite value to plot")]
    NoData {
        /// Which series.
        what: String,
    },
    /// A file or folder could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The output path exists and is not a regular file: a rename would replace a device, a
    /// FIFO, a socket or a folder.
    #[error("{} is not a regular file (a device, FIFO, socket or folder); outputs go only to regular files or new paths", path.display())]
    NotRegularFile {
        /// The output path.
        path: PathBuf,
    },
    /// A file could not be read (a figure to inline in a report).
    #[error("cannot read {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The plotting library failed to draw a figure.
    #[error("cannot draw {}: {message}", path.display())]
    Plot {
        /// The figure file.
        path: PathBuf,
        /// The plotting library's message.
        message: String,
    },
    /// The embedded font could not be registered.
    #[error("the embedded font cannot be loaded")]
    Font,
}

impl From<crate::writing::WriteError> for ReportError {
    fn from(e: crate::writing::WriteError) -> Self {
        match e {
            crate::writing::WriteError::NotRegularFile { path } => Self::NotRegularFile { path },
            crate::writing::WriteError::Io { path, source } => Self::Io { path, source },
        }
    }
}

impl ReportError {
    /// [`ReportError::NoData`] about `what`.
    pub fn no_data(what: impl Into<String>) -> Self {
        Self::NoData { what: what.into() }
    }
}
