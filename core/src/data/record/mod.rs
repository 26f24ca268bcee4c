//! Records: measured (or synthetic) time series of the rig, and reading and writing them.
//!
//! A record holds, in SI units, the time `t` (s, strictly increasing) and the displacement
//! `x` (m); optionally its drive — the rotor angle `phi` (rad, wrapped or unwrapped) and
//! speed `omega` (rad/s), or for a rig driven by a shaker or an actuator the measured drive
//! force `u` (N) — and the STF force `f_stf` (N). A force-level fit needs t, x and `f_stf`
//! only (a damper rig records no drive); a trajectory-level fit simulates the rig driven by
//! its drive, and one without any is a free vibration.
//!
//! Records are read from CSV files with a header row ([`Record::read_csv`]) and from MATLAB
//! `.mat` v5/v7 files with variables of the same names ([`Record::read_mat`]). Extra columns
//! are ignored. A lab's own layout — other column names or column numbers, units (ms, mm,
//! deg, encoder counts, rpm, volts with a gain, …), offsets given or estimated over a rest
//! stretch, a sample rate instead of a time column, `;` or tab separators, decimal commas,
//! lines before the header, no header at all — is described by [`ReadOptions`] (module
//! `layout`), which both readers apply. Bad input is an error naming the file, the row (the
//! editor's line) and the column ([`RecordError`]).
//!
//! ```
//! use stf_core::data::record::{ColumnNames, ReadOptions, Record};
//! let csv = "time, x, phi\n0.0, 0.001, 0.0\n0.001, 0.0012, 0.01\n";
//! let columns = ColumnNames { t: "time".into(), ..ColumnNames::default() };
//! let rec = ReadOptions::default().columns(columns).read_csv_from(csv.as_bytes(), "demo.csv").unwrap();
//! assert_eq!(rec.len(), 2);
//! assert_eq!(rec.phi.as_deref(), Some(&[0.0, 0.01][..]));
//!
//! let bad = "t,x,phi\n0,0,0\n0.001,oops,0\n";
//! let err = Record::read_csv_from(bad.as_bytes(), "bad.csv").unwrap_err();
//! assert_eq!(err.to_string(), "bad.csv:row 3, column `x`: not a number: `oops`");
//! ```

mod csv;
mod csv_rows;
mod csv_write;
mod error;
mod layout;
mod mat;
mod mat_inflate;
mod time_grid;

pub use error::RecordError;
pub use layout::{
    Calibration, Channel, Column, DecimalMark, LayoutError, Offset, ReadOptions, Separator, Signal,
    TimeBase, Unit, DEFAULT_MAX_BYTES,
};

use std::path::Path;

/// The `source` of a record built in memory.
pub const MEMORY_SOURCE: &str = "(memory)";

/// A time series of the rig, in SI units; all present columns have the length of `t`.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// Where the record came from: a file path or `(memory)`.
    pub source: String,
    /// Time, s, strictly increasing.
    pub t: Vec<f64>,
    /// Displacement, m.
    pub x: Vec<f64>,
    /// Rotor angle, rad (wrapped or unwrapped).
    pub phi: Option<Vec<f64>>,
    /// STF force, N.
    pub f_stf: Option<Vec<f64>>,
    /// Rotor speed, rad/s.
    pub omega: Option<Vec<f64>>,
    /// Measured drive force of a shaker rig, N.
    pub u: Option<Vec<f64>>,
}

/// Which column (CSV) or variable (`.mat`) holds each signal. The defaults are the names of
/// the data contract: `t`, `x`, `phi`, `f_stf`, `omega`, `u`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ColumnNames {
    /// Time, s.
    pub t: String,
    /// Displacement, m.
    pub x: String,
    /// Rotor angle, rad.
    pub phi: String,
    /// STF force, N.
    pub f_stf: String,
    /// Rotor speed, rad/s.
    pub omega: String,
    /// Drive force, N.
    pub u: String,
}

impl Default for ColumnNames {
    fn default() -> Self {
        ColumnNames {
            t: "t".into(),
            x: "x".into(),
            phi: "phi".into(),
            f_stf: "f_stf".into(),
            omega: "omega".into(),
            u: "u".into(),
        }
    }
}

impl ReadOptions {
    /// Read a `.csv` or `.mat` file, chosen by the extension (case-insensitive).
    pub fn read(&self, path: &Path) -> Result<Record, RecordError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("csv") => self.read_csv(path),
            Some("mat") => self.read_mat(path),
            other => Err(RecordError::new(
                path.display().to_string(),
                format!(
                    "unknown record file type {}: records are `.csv` (with a header row) or MATLAB `.mat` files",
                    other.map_or("(no extension)".to_string(), |e| format!("`.{e}`"))
                ),
            )),
        }
    }

    /// Read a CSV file laid out as these options say.
    pub fn read_csv(&self, path: &Path) -> Result<Record, RecordError> {
        let source = path.display().to_string();
        self.checked(&source)?;
        crate::data::bounded::check_len(path, self.max_bytes)
            .map_err(|e| RecordError::new(&source, format!("{e} for a record (`max_bytes`)")))?;
        let file = std::fs::File::open(path)
            .map_err(|e| RecordError::new(&source, format!("cannot open: {e}")))?;
        csv::read(file, &source, self)
    }

    /// Read CSV text from `reader`; `source` names it in errors.
    pub fn read_csv_from<R: std::io::Read>(
        &self,
        reader: R,
        source: &str,
    ) -> Result<Record, RecordError> {
        self.checked(source)?;
        csv::read(reader, source, self)
    }

    /// Read a MATLAB `.mat` file (v5/v7; not v4 or v7.3) with a vector variable per signal.
    pub fn read_mat(&self, path: &Path) -> Result<Record, RecordError> {
        self.checked(&path.display().to_string())?;
        mat::read(path, self)
    }

    /// Read the bytes of a MATLAB `.mat` file; `source` names it in errors.
    pub fn read_mat_bytes(&self, bytes: &[u8], source: &str) -> Result<Record, RecordError> {
        self.checked(source)?;
        mat::read_bytes(bytes, source, self)
    }

    /// [`ReadOptions::check`] as an error about reading `source`.
    fn checked(&self, source: &str) -> Result<(), RecordError> {
        self.check().map_err(|e| {
            RecordError::new(
                source,
                format!("cannot be read with this layout (`{}`): {e}", e.setting()),
            )
        })
    }
}

/// Check the signals of a record being assembled (by [`Signal`] index; `t` and `x` present)
/// and make a record: equal lengths, at least one sample, finite values, strictly increasing
/// time, read as the uniform grid it rounds where its stamps are rounded (module
/// `time_grid`). The drive (φ, ω or u) is optional: a force-level fit needs only t, x and the force,
/// and a record without any drive is a free vibration at trajectory level. `labels` name the columns (by [`Signal`] index) and `row_of` turns a
/// 0-based sample index into the row a user sees.
pub(crate) fn into_record(
    raw: layout::Raw,
    source: &str,
    labels: &[String; 6],
    row_of: &dyn Fn(usize) -> usize,
) -> Result<Record, RecordError> {
    let [t, x, phi, f_stf, omega, u] = raw;
    let (t, x) = (t.unwrap_or_default(), x.unwrap_or_default());
    let n = t.len();
    let err = |message: String| RecordError::new(source, message);
    let label = |s: Signal| labels[s.index()].as_str();
    if n == 0 {
        return Err(err("no data: the record has no samples".into()));
    }
    let named = [
        (Signal::T, Some(&t)),
        (Signal::X, Some(&x)),
        (Signal::Phi, phi.as_ref()),
        (Signal::FStf, f_stf.as_ref()),
        (Signal::Omega, omega.as_ref()),
        (Signal::U, u.as_ref()),
    ];
    for (signal, values) in named {
        let Some(values) = values else { continue };
        if values.len() != n {
            return Err(err(format!(
                "has {} values but `{}` has {n}: all signals need the same length",
                values.len(),
                label(Signal::T)
            ))
            .in_column(label(signal)));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(err(format!("not a finite number: `{}`", values[i]))
                .at_row(row_of(i))
                .in_column(label(signal)));
        }
    }
    if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(err(format!(
            "time is not strictly increasing: {} s follows {} s",
            t[i + 1],
            t[i]
        ))
        .at_row(row_of(i + 1))
        .in_column(label(Signal::T)));
    }
    let t = time_grid::regular_within_rounding(&t).unwrap_or(t);
    Ok(Record {
        source: source.to_string(),
        t,
        x,
        phi,
        f_stf,
        omega,
        u,
    })
}

/// The contract's names of the signals, by [`Signal`] index (the labels of a record in
/// memory).
fn contract_labels() -> [String; 6] {
    Signal::ALL.map(|s| s.name().to_string())
}

impl Record {
    /// Read a `.csv` or `.mat` record with the default column names.
    pub fn read(path: &Path) -> Result<Record, RecordError> {
        ReadOptions::default().read(path)
    }

    /// Read a CSV record with the default column names.
    pub fn read_csv(path: &Path) -> Result<Record, RecordError> {
        ReadOptions::default().read_csv(path)
    }

    /// Read CSV text from `reader` with the default column names; `source` names it in errors.
    pub fn read_csv_from<R: std::io::Read>(reader: R, source: &str) -> Result<Record, RecordError> {
        ReadOptions::default().read_csv_from(reader, source)
    }

    /// Read a `.mat` record with the default variable names.
    pub fn read_mat(path: &Path) -> Result<Record, RecordError> {
        ReadOptions::default().read_mat(path)
    }

    /// Check a record (e.g. one built in memory) against the data contract: equal lengths,
    /// at least one sample, finite values, strictly increasing `t`.
    /// Rows in errors are 1-based sample numbers.
    pub fn check(&self) -> Result<(), RecordError> {
        let raw = [
            Some(self.t.clone()),
            Some(self.x.clone()),
            self.phi.clone(),
            self.f_stf.clone(),
            self.omega.clone(),
            self.u.clone(),
        ];
        into_record(raw, &self.source, &contract_labels(), &|i| i + 1).map(|_| ())
    }

    /// Write the record as CSV to `out` with columns `t, phi, x, f_stf, omega, u` (those
    /// present), each number in the shortest form that reads back to the same `f64`. The
    /// record is checked first, so nothing is written for an invalid one. Writing a file
    /// safely (a temporary beside it, then a rename) is the caller's part.
    ///
    /// ```
    /// # use stf_core::data::record::Record;
    /// let rec = Record { source: "memory".into(), t: vec![0.0, 0.5], phi: Some(vec![0.0, 0.1]),
    ///     x: vec![0.0, 1e-3], f_stf: None, omega: None, u: None };
    /// let mut text = Vec::new();
    /// rec.write_csv(&mut text).unwrap();
    /// assert_eq!(String::from_utf8(text).unwrap(), "t,phi,x\n0,0,0\n0.5,0.1,0.001\n");
    /// ```
    pub fn write_csv(&self, mut out: impl std::io::Write) -> Result<(), RecordError> {
        self.check()?;
        csv_write::write(self, &[], &mut out)
    }

    /// [`Record::write_csv`] with further columns after the record's own: measured channels
    /// (a control voltage), each named and as long as `t`.
    pub fn write_csv_with(
        &self,
        extra: &[(&str, &[f64])],
        mut out: impl std::io::Write,
    ) -> Result<(), RecordError> {
        self.check()?;
        if let Some((name, v)) = extra.iter().find(|(_, v)| v.len() != self.t.len()) {
            return Err(RecordError::new(
                &self.source,
                format!(
                    "column `{name}` has {} values for {} times",
                    v.len(),
                    self.t.len()
                ),
            ));
        }
        csv_write::write(self, extra, &mut out)
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether the record has no samples.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The samples with `t0 ≤ t ≤ t1` (empty if none), same source.
    pub fn slice_time(&self, t0: f64, t1: f64) -> Record {
        let start = self.t.partition_point(|&t| t < t0);
        let end = self.t.partition_point(|&t| t <= t1).max(start);
        let cut = |v: &Vec<f64>| v.get(start..end).map(<[f64]>::to_vec).unwrap_or_default();
        Record {
            source: self.source.clone(),
            t: cut(&self.t),
            x: cut(&self.x),
            phi: self.phi.as_ref().map(cut),
            f_stf: self.f_stf.as_ref().map(cut),
            omega: self.omega.as_ref().map(cut),
            u: self.u.as_ref().map(cut),
        }
    }

    /// Mean sample step `(t_last − t_first)/(n − 1)`, s; `None` with fewer than 2 samples.
    /// For a uniformity check use [`crate::numerics::derivative::sample_step`].
    pub fn sample_step(&self) -> Option<f64> {
        let n = self.t.len();
        (n >= 2).then(|| (self.t[n - 1] - self.t[0]) / (n - 1) as f64)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::*;

    fn memory(n: usize) -> Record {
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.5).collect();
        Record {
            source: MEMORY_SOURCE.into(),
            x: t.iter().map(|t| t * 2.0).collect(),
            phi: Some(t.iter().map(|t| t * 3.0).collect()),
            f_stf: None,
            omega: None,
            u: Some(t.iter().map(|t| -t).collect()),
            t,
        }
    }

    #[test]
    fn slice_time_keeps_the_closed_interval_of_every_column() {
        let r = memory(10);
        let s = r.slice_time(1.0, 2.5);
        assert_eq!(s.t, vec![1.0, 1.5, 2.0, 2.5]);
        assert_eq!(s.x, vec![2.0, 3.0, 4.0, 5.0]);
        assert_eq!(s.phi.unwrap(), vec![3.0, 4.5, 6.0, 7.5]);
        assert_eq!(s.u.unwrap(), vec![-1.0, -1.5, -2.0, -2.5]);
        assert!(s.f_stf.is_none());
        assert!(r.slice_time(3.0, 1.0).is_empty());
        assert_eq!(r.slice_time(-10.0, 10.0), r);
    }

    #[test]
    fn len_and_sample_step() {
        let r = memory(5);
        assert_eq!(r.len(), 5);
        assert!(!r.is_empty());
        assert_eq!(r.sample_step(), Some(0.5));
        assert_eq!(memory(1).sample_step(), None);
    }

    #[test]
    fn check_catches_length_mismatch_and_accepts_a_record_without_drive() {
        let mut r = memory(5);
        r.x.pop();
        let e = r.check().unwrap_err();
        assert_eq!(e.column.as_deref(), Some("x"));
        assert_eq!(e.file, MEMORY_SOURCE);
        let mut r = memory(5);
        r.phi = None;
        r.u = None;
        assert!(r.check().is_ok(), "t and x alone are a record");
        let mut r = memory(5);
        r.t[3] = r.t[2];
        let e = r.check().unwrap_err();
        assert_eq!((e.row, e.column.as_deref()), (Some(4), Some("t")));
    }

    #[test]
    fn read_dispatches_on_extension() {
        let e = Record::read(Path::new("data/record.txt")).unwrap_err();
        assert!(e.message.contains("`.txt`"), "{e}");
        let e = Record::read(Path::new("data/does_not_exist.CSV")).unwrap_err();
        assert!(e.message.contains("cannot open"), "{e}");
    }
}
