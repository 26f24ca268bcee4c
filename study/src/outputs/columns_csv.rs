//! Named columns of numbers written as CSV: `fitted.csv` of `fit` (`t`, the measured signal,
//! one column per model, `f_stf_<label>` or `x_<label>`) and `discovered.csv` of `discover`
//! (`t`, the signal, `<signal>_base`, `<signal>_final`). The header depends on the models, so
//! the table is written record by record with the csv crate (which quotes a name that needs
//! it); numbers carry their own digits ([`crate::digits`]), in Rust's shortest form.

use anyhow::{Context, Result};

use crate::digits::cell;

/// Columns of one table, left to right; rows as long as the shortest column.
#[derive(Clone, Debug, Default)]
pub struct Columns<'a> {
    names: Vec<String>,
    values: Vec<&'a [f64]>,
}

impl<'a> Columns<'a> {
    /// An empty table.
    pub fn new() -> Self {
        Self::default()
    }

    /// The table with the column `name` (its unit is the signal's, SI) added on the right.
    pub fn with(mut self, name: impl Into<String>, values: &'a [f64]) -> Self {
        self.names.push(name.into());
        self.values.push(values);
        self
    }

    /// The CSV text: header, then one line per row.
    pub fn to_csv(&self) -> Result<Vec<u8>> {
        let mut w = csv::Writer::from_writer(Vec::new());
        w.write_record(&self.names)?;
        let rows = self.values.iter().map(|c| c.len()).min().unwrap_or(0);
        for i in 0..rows {
            w.write_record(self.values.iter().map(|c| cell(c[i])))?;
        }
        w.into_inner().context("cannot build a CSV table")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_stop_at_the_shortest_column_and_digits_are_carried() {
        let t = [0.0, 0.005, 0.01];
        let f = [0.1 + 0.2, -1.5];
        let text = Columns::new()
            .with("t", &t)
            .with("f_stf", &f)
            .to_csv()
            .unwrap();
        assert_eq!(
            String::from_utf8(text).unwrap(),
            "t,f_stf\n0,0.3\n0.005,-1.5\n"
        );
    }

    #[test]
    fn a_name_with_a_comma_or_quote_is_quoted() {
        let x = [1.0];
        let text = Columns::new().with("x_a,\"b\"", &x).to_csv().unwrap();
        assert_eq!(String::from_utf8(text).unwrap(), "\"x_a,\"\"b\"\"\"\n1\n");
    }
}
