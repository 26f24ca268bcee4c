//! Why a record could not be read or written: the file, the row and the column, and what is
//! wrong there.

use derive_setters::Setters;
use thiserror::Error;

/// A record could not be read, checked or written.
///
/// Displays as `file:row N, column `x`: message`, leaving out the parts that do not apply.
/// For CSV files, `row` is the line number a user sees in an editor (the header is line 1,
/// the first data row is line 2); for `.mat` files it is the 1-based element of the vector;
/// for records in memory, the 1-based sample.
#[derive(Debug, Clone, PartialEq, Eq, Error, Setters)]
#[error("{file}{}{}: {message}", row_part(*row), column_part(column.as_deref()))]
pub struct RecordError {
    /// File path, or `(memory)`.
    #[setters(skip)]
    pub file: String,
    /// Row (see above), if the problem has one; set by `at_row`.
    #[setters(strip_option, rename = "at_row")]
    pub row: Option<usize>,
    /// Column (or `.mat` variable) name, if the problem has one; set by `in_column`.
    #[setters(strip_option, into, rename = "in_column")]
    pub column: Option<String>,
    /// What is wrong.
    #[setters(skip)]
    pub message: String,
}

impl RecordError {
    /// An error in `file` with `message`, no row, no column.
    pub fn new(file: impl Into<String>, message: impl Into<String>) -> Self {
        RecordError {
            file: file.into(),
            row: None,
            column: None,
            message: message.into(),
        }
    }
}

fn row_part(row: Option<usize>) -> String {
    row.map(|r| format!(":row {r}")).unwrap_or_default()
}

fn column_part(column: Option<&str>) -> String {
    column
        .map(|c| format!(", column `{c}`"))
        .unwrap_or_default()
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::*;

    #[test]
    fn display_names_file_row_and_column() {
        let e = RecordError::new("a.csv", "not a number: `x`")
            .at_row(7)
            .in_column("phi");
        assert_eq!(
            e.to_string(),
            "a.csv:row 7, column `phi`: not a number: `x`"
        );
        assert_eq!(
            RecordError::new("a.csv", "empty").to_string(),
            "a.csv: empty"
        );
        assert_eq!(
            RecordError::new("a.mat", "missing")
                .in_column("t")
                .to_string(),
            "a.mat, column `t`: missing"
        );
    }
}
