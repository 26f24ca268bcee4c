//! The CSV of a figure: one column per plotted quantity, headed by its name and unit
//! (`"t, s"`), holding exactly the samples drawn. Columns may differ in length (the raw and the
//! smoothed frequency response, the marked extrema); shorter ones end in empty cells.

use std::path::Path;

use super::ReportError;
use crate::writing::atomic::write_atomic;

/// A named column of numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    /// Header: quantity and unit, e.g. `"x, m"`.
    pub name: String,
    /// The values, top to bottom.
    pub values: Vec<f64>,
}

impl Column {
    /// A column from a name and values.
    pub fn new(name: impl Into<String>, values: Vec<f64>) -> Self {
        Self {
            name: name.into(),
            values,
        }
    }

    /// A column numbering consecutive groups of rows from 1, the groups `lengths` rows long.
    pub fn numbered(name: &str, lengths: impl Iterator<Item = usize>) -> Self {
        let numbers = lengths
            .enumerate()
            .flat_map(|(k, n)| std::iter::repeat_n((k + 1) as f64, n));
        Self::new(name, numbers.collect())
    }
}

/// The CSV text of `columns` (numbers in Rust's shortest exact form, the samples drawn exactly,
/// a negative zero as `0`: [`stf_core::digits::exact`]; quoting by `csv`).
pub fn to_csv(columns: &[Column]) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let rows = columns.iter().map(|c| c.values.len()).max().unwrap_or(0);
    let written = w
        .write_record(columns.iter().map(|c| c.name.as_str()))
        .and_then(|()| {
            (0..rows).try_for_each(|r| {
                w.write_record(columns.iter().map(|c| {
                    c.values
                        .get(r)
                        .map(|&v| stf_core::digits::exact(v))
                        .unwrap_or_default()
                }))
            })
        });
    // Writing into memory cannot fail.
    debug_assert!(written.is_ok());
    let bytes = w.into_inner().unwrap_or_default();
    String::from_utf8(bytes).unwrap_or_default()
}

/// Write `columns` to `path` atomically.
pub fn write_csv(path: &Path, columns: &[Column]) -> Result<(), ReportError> {
    Ok(write_atomic(path, to_csv(columns).as_bytes())?)
}

/// Read a figure CSV back into columns (empty cells end a column). For tests and for users
/// who post-process figures; numbers that do not parse are read as NaN.
pub fn read_csv_columns(path: &Path) -> Result<Vec<Column>, ReportError> {
    let text = std::fs::read_to_string(path).map_err(|source| ReportError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let mut reader = csv::ReaderBuilder::new()
        .flexible(true)
        .from_reader(text.as_bytes());
    let unreadable = |e: csv::Error| ReportError::Read {
        path: path.to_path_buf(),
        source: std::io::Error::new(std::io::ErrorKind::InvalidData, e.to_string()),
    };
    let mut columns: Vec<Column> = reader
        .headers()
        .map_err(unreadable)?
        .iter()
        .map(|name| Column::new(name, Vec::new()))
        .collect();
    for row in reader.records() {
        let row = row.map_err(unreadable)?;
        for (col, cell) in columns.iter_mut().zip(row.iter()) {
            if !cell.is_empty() {
                col.values.push(cell.parse().unwrap_or(f64::NAN));
            }
        }
    }
    Ok(columns)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_names_with_commas_and_ragged_columns() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fig.csv");
        let columns = vec![
            Column::new("t, s", vec![0.0, 0.1, 0.2, 1e-300]),
            Column::new("say \"F\", N", vec![-1.5, 2.0]),
        ];
        write_csv(&path, &columns).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.starts_with("\"t, s\",\"say \"\"F\"\", N\"\n"),
            "{text}"
        );
        assert_eq!(read_csv_columns(&path).unwrap(), columns);
    }
}
