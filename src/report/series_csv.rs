//! The CSV of a figure: one column per plotted quantity, headed by its name and unit
//! (`"t, s"`), holding exactly the samples drawn. Columns may differ in length (the raw and the
//! smoothed frequency response, the marked extrema); shorter ones end in empty cells.

use std::path::Path;

use super::atomic::write_atomic;
use super::ReportError;

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
}

fn quote(field: &str) -> String {
    if field.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", field.replace('"', "\"\""))
    } else {
        field.to_string()
    }
}

/// The CSV text of `columns` (numbers in Rust's shortest exact form).
pub fn to_csv(columns: &[Column]) -> String {
    let mut out = String::new();
    let header: Vec<String> = columns.iter().map(|c| quote(&c.name)).collect();
    out.push_str(&header.join(","));
    out.push('\n');
    let rows = columns.iter().map(|c| c.values.len()).max().unwrap_or(0);
    for r in 0..rows {
        let cells: Vec<String> = columns
            .iter()
            .map(|c| c.values.get(r).map(|v| v.to_string()).unwrap_or_default())
            .collect();
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    out
}

/// Write `columns` to `path` atomically.
pub fn write_csv(path: &Path, columns: &[Column]) -> Result<(), ReportError> {
    write_atomic(path, to_csv(columns).as_bytes())
}

fn split_record(line: &str) -> Vec<String> {
    let mut fields = Vec::new();
    let mut field = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(std::mem::take(&mut field)),
            _ => field.push(c),
        }
    }
    fields.push(field);
    fields
}

/// Read a figure CSV back into columns (empty cells end a column). For tests and for users
/// who post-process figures; numbers that do not parse are read as NaN.
pub fn read_csv_columns(path: &Path) -> Result<Vec<Column>, ReportError> {
    let text = std::fs::read_to_string(path).map_err(|source| ReportError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let mut lines = text.lines();
    let mut columns: Vec<Column> = lines
        .next()
        .map(split_record)
        .unwrap_or_default()
        .into_iter()
        .map(|name| Column::new(name, Vec::new()))
        .collect();
    for line in lines {
        for (col, cell) in columns.iter_mut().zip(split_record(line)) {
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
