//! Records as CSV: a header row naming the columns, one sample per row.
//!
//! Cells and names are trimmed of whitespace; extra columns are ignored. Rows are reported as
//! the line numbers an editor shows (the header is line 1).

use super::{ColumnNames, Columns, Record, RecordError};
use std::io::Write;
use std::path::Path;

/// Where each wanted signal sits in a row.
struct Layout {
    t: usize,
    x: usize,
    phi: Option<usize>,
    f_stf: Option<usize>,
    omega: Option<usize>,
    u: Option<usize>,
}

/// Read a record from CSV text.
pub(super) fn read<R: std::io::Read>(
    mut reader: R,
    source: &str,
    names: &ColumnNames,
) -> Result<Record, RecordError> {
    // The whole text is kept so that rows can be reported as editor lines: the csv crate's
    // own line count skips blank lines.
    let mut data = Vec::new();
    reader
        .read_to_end(&mut data)
        .map_err(|e| RecordError::new(source, format!("cannot read: {e}")))?;
    let mut rdr = ::csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .trim(::csv::Trim::All)
        .from_reader(&data[..]);
    let header = rdr
        .headers()
        .map_err(|e| csv_error(source, &data, &e))?
        .clone();
    if header.iter().all(str::is_empty) {
        return Err(RecordError::new(
            source,
            "empty file: expected a header row naming the columns (t, x, phi, …)",
        )
        .at_row(1));
    }
    let layout = layout(source, names, &header)?;

    let mut columns = Columns {
        t: Vec::new(),
        x: Vec::new(),
        phi: layout.phi.map(|_| Vec::new()),
        f_stf: layout.f_stf.map(|_| Vec::new()),
        omega: layout.omega.map(|_| Vec::new()),
        u: layout.u.map(|_| Vec::new()),
    };
    let mut starts: Vec<u64> = Vec::new();
    let mut row = ::csv::StringRecord::new();
    loop {
        match rdr.read_record(&mut row) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => return Err(csv_error(source, &data, &e)),
        }
        let start = row.position().map_or(0, |p| p.byte());
        // Counting lines is O(file): only done for an error.
        let line = || line_of(&data, start);
        if row.len() < header.len() {
            return Err(RecordError::new(
                source,
                format!(
                    "short row: {} cell(s), the header has {}",
                    row.len(),
                    header.len()
                ),
            )
            .at_row(line())
            .in_column(header.get(row.len()).unwrap_or_default()));
        }
        if row.len() > header.len() {
            return Err(RecordError::new(
                source,
                format!(
                    "long row: {} cells, the header has {} (a stray separator?)",
                    row.len(),
                    header.len()
                ),
            )
            .at_row(line()));
        }
        let cell = |index: usize, name: &str| number(source, &line, name, row.get(index));
        columns.t.push(cell(layout.t, &names.t)?);
        columns.x.push(cell(layout.x, &names.x)?);
        let optional = [
            (layout.phi, &names.phi, &mut columns.phi),
            (layout.f_stf, &names.f_stf, &mut columns.f_stf),
            (layout.omega, &names.omega, &mut columns.omega),
            (layout.u, &names.u, &mut columns.u),
        ];
        for (index, name, values) in optional {
            if let (Some(index), Some(values)) = (index, values) {
                values.push(cell(index, name)?);
            }
        }
        starts.push(start);
    }
    if starts.is_empty() {
        return Err(
            RecordError::new(source, "no data rows: the file holds only the header").at_row(2),
        );
    }
    columns.into_record(source, names, &|i| {
        starts.get(i).map_or(i + 2, |&b| line_of(&data, b))
    })
}

/// The 1-based editor line of the record whose parse began at byte `start` (just after the
/// previous record's terminator): newlines before it, plus any blank lines the parser
/// skipped.
fn line_of(data: &[u8], start: u64) -> usize {
    let start = (start as usize).min(data.len());
    let mut line = 1 + data[..start].iter().filter(|&&b| b == b'\n').count();
    let mut rest = &data[start..];
    loop {
        match rest {
            [b'\n', tail @ ..] | [b'\r', b'\n', tail @ ..] => {
                line += 1;
                rest = tail;
            }
            _ => return line,
        }
    }
}

/// Find the wanted columns in the header.
fn layout(
    source: &str,
    names: &ColumnNames,
    header: &::csv::StringRecord,
) -> Result<Layout, RecordError> {
    let find = |name: &str| -> Result<Option<usize>, RecordError> {
        let mut hits = header
            .iter()
            .enumerate()
            .filter(|(_, h)| *h == name)
            .map(|(i, _)| i);
        let first = hits.next();
        if let (Some(a), Some(b)) = (first, hits.next()) {
            return Err(RecordError::new(
                source,
                format!(
                    "the header names this column twice (columns {} and {})",
                    a + 1,
                    b + 1
                ),
            )
            .at_row(1)
            .in_column(name));
        }
        Ok(first)
    };
    let missing = |name: &str, extra: &str| {
        let similar = header
            .iter()
            .find(|h| h.eq_ignore_ascii_case(name))
            .map(|h| format!(" (`{h}` differs only in case; names are case-sensitive)"))
            .unwrap_or_default();
        RecordError::new(
            source,
            format!(
                "missing column `{name}`{extra}{similar}; the header has: {}",
                header.iter().collect::<Vec<_>>().join(", ")
            ),
        )
        .at_row(1)
        .in_column(name)
    };
    let t = find(&names.t)?.ok_or_else(|| missing(&names.t, ""))?;
    let x = find(&names.x)?.ok_or_else(|| missing(&names.x, ""))?;
    let phi = find(&names.phi)?;
    let u = find(&names.u)?;
    if phi.is_none() && u.is_none() {
        return Err(missing(
            &names.phi,
            &format!(" (or `{}` for a force-driven rig)", names.u),
        ));
    }
    Ok(Layout {
        t,
        x,
        phi,
        f_stf: find(&names.f_stf)?,
        omega: find(&names.omega)?,
        u,
    })
}

/// One numeric cell.
fn number(
    source: &str,
    line: &dyn Fn() -> usize,
    name: &str,
    cell: Option<&str>,
) -> Result<f64, RecordError> {
    let at = |message: String| {
        RecordError::new(source, message)
            .at_row(line())
            .in_column(name)
    };
    let text = cell.unwrap_or_default();
    if text.is_empty() {
        return Err(at("empty cell".into()));
    }
    let value: f64 = text
        .parse()
        .map_err(|_| at(format!("not a number: `{text}`")))?;
    if !value.is_finite() {
        return Err(at(format!("not a finite number: `{text}`")));
    }
    Ok(value)
}

/// A CSV-level failure (I/O, invalid UTF-8), with the line where known.
fn csv_error(source: &str, data: &[u8], e: &::csv::Error) -> RecordError {
    let line = match e.kind() {
        ::csv::ErrorKind::Utf8 { pos: Some(p), .. }
        | ::csv::ErrorKind::UnequalLengths { pos: Some(p), .. } => Some(line_of(data, p.byte())),
        _ => e.position().map(|p| line_of(data, p.byte())),
    };
    let message = match e.kind() {
        ::csv::ErrorKind::Io(io) => format!("cannot read: {io}"),
        ::csv::ErrorKind::Utf8 { .. } => "invalid UTF-8 text".to_string(),
        _ => e.to_string(),
    };
    let err = RecordError::new(source, message);
    match line {
        Some(l) => err.at_row(l),
        None => err,
    }
}

/// Shortest text that parses back to exactly `v`, in plain notation for ordinary magnitudes
/// and in exponent notation for very small or large ones.
pub(super) fn format_f64(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-4..1e15).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Write a (validated) record atomically: temporary file in the same directory, then rename.
pub(super) fn write(record: &Record, path: &Path) -> Result<(), RecordError> {
    let target = path.display().to_string();
    let fail = |what: &str, e: std::io::Error| RecordError::new(&target, format!("{what}: {e}"));
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| RecordError::new(&target, "not a file path"))?;
    let temp = dir.join(format!(
        ".{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id()
    ));

    let mut columns: Vec<(&str, &[f64])> = vec![("t", &record.t)];
    if let Some(phi) = &record.phi {
        columns.push(("phi", phi));
    }
    columns.push(("x", &record.x));
    for (label, values) in [
        ("f_stf", &record.f_stf),
        ("omega", &record.omega),
        ("u", &record.u),
    ] {
        if let Some(v) = values {
            columns.push((label, v));
        }
    }

    let written = (|| -> std::io::Result<()> {
        let file = std::fs::File::create(&temp)?;
        let mut out = std::io::BufWriter::new(file);
        let header: Vec<&str> = columns.iter().map(|(label, _)| *label).collect();
        writeln!(out, "{}", header.join(","))?;
        let mut line = String::new();
        for i in 0..record.t.len() {
            line.clear();
            for (k, (_, values)) in columns.iter().enumerate() {
                if k > 0 {
                    line.push(',');
                }
                line.push_str(&format_f64(values.get(i).copied().unwrap_or(f64::NAN)));
            }
            line.push('\n');
            out.write_all(line.as_bytes())?;
        }
        let file = out.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()
    })();
    if let Err(e) = written {
        let _ = std::fs::remove_file(&temp);
        return Err(fail(&format!("cannot write {}", temp.display()), e));
    }
    std::fs::rename(&temp, path).map_err(|e| {
        let _ = std::fs::remove_file(&temp);
        fail("cannot move the written file into place", e)
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::super::{ReadOptions, MEMORY_SOURCE};
    use super::*;
    use rand::{rngs::StdRng, Rng, SeedableRng};

    fn read_str(text: &str) -> Result<Record, RecordError> {
        Record::read_csv_from(text.as_bytes(), "rec.csv")
    }

    /// The error names file, row and column as expected, and its message contains `words`.
    fn expect(text: &str, row: Option<usize>, column: Option<&str>, words: &str) {
        let e = read_str(text).unwrap_err();
        assert_eq!(e.file, "rec.csv", "{e}");
        assert_eq!(e.row, row, "{e}");
        assert_eq!(e.column.as_deref(), column, "{e}");
        assert!(e.message.contains(words), "{e}");
        let shown = e.to_string();
        assert!(shown.starts_with("rec.csv"), "{shown}");
        if let Some(r) = row {
            assert!(shown.contains(&format!("row {r}")), "{shown}");
        }
        if let Some(c) = column {
            assert!(shown.contains(&format!("column `{c}`")), "{shown}");
        }
    }

    #[test]
    fn reads_columns_trims_and_ignores_extras() {
        let r = read_str(" t , note, x ,phi, omega\n0, a, 1e-3, 0.5, 2\n 0.001 ,b,2e-3,0.6,2.1\n")
            .unwrap();
        assert_eq!(r.source, "rec.csv");
        assert_eq!(r.t, vec![0.0, 0.001]);
        assert_eq!(r.x, vec![1e-3, 2e-3]);
        assert_eq!(r.phi, Some(vec![0.5, 0.6]));
        assert_eq!(r.omega, Some(vec![2.0, 2.1]));
        assert_eq!((r.f_stf, r.u), (None, None));
    }

    #[test]
    fn force_driven_rig_needs_u_instead_of_phi() {
        let r = read_str("t,x,u\n0,0,1.5\n1,0,1.6\n").unwrap();
        assert_eq!(r.u, Some(vec![1.5, 1.6]));
        assert!(r.phi.is_none());
    }

    #[test]
    fn custom_column_names() {
        let names = ColumnNames {
            t: "time_s".into(),
            x: "pos".into(),
            ..ColumnNames::default()
        };
        let opts = ReadOptions::default().columns(names);
        let r = opts
            .read_csv_from("time_s,pos,phi\n0,1,2\n1,3,4\n".as_bytes(), "m.csv")
            .unwrap();
        assert_eq!(r.x, vec![1.0, 3.0]);
        let e = opts
            .read_csv_from("time_s,pos,phi\n0,1,2\n0,3,4\n".as_bytes(), "m.csv")
            .unwrap_err();
        assert_eq!(e.column.as_deref(), Some("time_s"));
    }

    #[test]
    fn utf8_bom_is_not_part_of_the_first_name() {
        let r = read_str("\u{feff}t,x,phi\n0,1,2\n").unwrap();
        assert_eq!(r.t, vec![0.0]);
    }

    #[test]
    fn error_missing_column() {
        expect(
            "t,phi\n0,0\n",
            Some(1),
            Some("x"),
            "missing column `x`; the header has: t, phi",
        );
        expect(
            "T,x,phi\n0,0,0\n",
            Some(1),
            Some("t"),
            "differs only in case",
        );
    }

    #[test]
    fn error_missing_phi_and_u() {
        expect(
            "t,x\n0,0\n",
            Some(1),
            Some("phi"),
            "missing column `phi` (or `u` for a force-driven rig)",
        );
    }

    #[test]
    fn error_duplicate_column() {
        expect(
            "t,x,phi,x\n0,0,0,0\n",
            Some(1),
            Some("x"),
            "twice (columns 2 and 4)",
        );
    }

    #[test]
    fn error_non_numeric_cell() {
        expect(
            "t,x,phi\n0,0,0\n0.1,0,0\n0.2,0,abc\n",
            Some(4),
            Some("phi"),
            "not a number: `abc`",
        );
        expect("t,x,phi\n0,,0\n", Some(2), Some("x"), "empty cell");
    }

    #[test]
    fn error_nan_and_infinity() {
        expect(
            "t,x,phi\n0,0,0\n0.1,NaN,0\n",
            Some(3),
            Some("x"),
            "not a finite number: `NaN`",
        );
        expect(
            "t,x,phi\n0,0,0\n0.1,0,0\n0.2,0,-inf\n",
            Some(4),
            Some("phi"),
            "not a finite",
        );
    }

    #[test]
    fn error_short_and_long_rows() {
        expect(
            "t,x,phi\n0,0,0\n0.1,0\n",
            Some(3),
            Some("phi"),
            "short row: 2 cell(s)",
        );
        expect("t,x,phi\n0,0,0,9\n", Some(2), None, "long row: 4 cells");
    }

    #[test]
    fn error_time_not_strictly_increasing() {
        expect(
            "t,x,phi\n0,0,0\n0.1,0,0\n0.1,0,0\n",
            Some(4),
            Some("t"),
            "not strictly increasing",
        );
        expect(
            "t,x,phi\n0,0,0\n-0.1,0,0\n",
            Some(3),
            Some("t"),
            "-0.1 s follows 0 s",
        );
    }

    #[test]
    fn rows_are_editor_lines_even_after_blank_lines() {
        // Line 4 is blank; the bad value is on line 5.
        expect(
            "t,x,phi\n0,0,0\n1,0,0\n\n2,zz,0\n",
            Some(5),
            Some("x"),
            "`zz`",
        );
        expect(
            "t,x,phi\r\n0,0,0\r\n\r\n\r\n1,0,0\r\n0.5,0,0\r\n",
            Some(6),
            Some("t"),
            "follows",
        );
        expect("t,x,phi\n\n0,0,0\n0,0,0\n", Some(4), Some("t"), "follows");
    }

    #[test]
    fn error_empty_file_and_header_only() {
        expect("", Some(1), None, "empty file");
        expect("t,x,phi\n", Some(2), None, "no data rows");
    }

    #[test]
    fn error_invalid_utf8_names_the_line() {
        let bytes = b"t,x,phi\n0,0,0\n1,\xff,0\n";
        let e = Record::read_csv_from(&bytes[..], "rec.csv").unwrap_err();
        assert_eq!(e.row, Some(3), "{e}");
    }

    #[test]
    fn write_then_read_round_trips_exactly() {
        let mut rng = StdRng::seed_from_u64(3);
        let n = 500;
        let t: Vec<f64> = (0..n)
            .map(|i| i as f64 * 1e-3 + 1e-9 * rng.random::<f64>())
            .collect();
        let rand_col = |rng: &mut StdRng| -> Vec<f64> {
            (0..n)
                .map(|i| {
                    let scale = [1e-300, 1e-7, 1e-3, 1.0, 1e6, 1e200][i % 6];
                    (rng.random::<f64>() - 0.5) * scale
                })
                .collect()
        };
        let rec = Record {
            source: MEMORY_SOURCE.into(),
            x: rand_col(&mut rng),
            phi: Some(rand_col(&mut rng)),
            f_stf: Some(rand_col(&mut rng)),
            omega: None,
            u: Some(rand_col(&mut rng)),
            t,
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        rec.write_csv(&path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("t,phi,x,f_stf,u\n"), "{}", &text[..40]);
        let back = Record::read_csv(&path).unwrap();
        assert_eq!(back.source, path.display().to_string());
        assert_eq!(back.t, rec.t);
        assert_eq!(back.x, rec.x);
        assert_eq!(back.phi, rec.phi);
        assert_eq!(back.f_stf, rec.f_stf);
        assert_eq!(back.u, rec.u);
        assert_eq!(back.omega, None);
        // Only the target file is left behind.
        let entries: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(entries.len(), 1);
    }

    #[test]
    fn write_refuses_an_invalid_record_and_leaves_no_file() {
        let rec = Record {
            source: MEMORY_SOURCE.into(),
            t: vec![0.0, 1.0],
            x: vec![0.0, f64::NAN],
            phi: Some(vec![0.0, 0.0]),
            f_stf: None,
            omega: None,
            u: None,
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.csv");
        let e = rec.write_csv(&path).unwrap_err();
        assert_eq!((e.row, e.column.as_deref()), (Some(2), Some("x")));
        assert!(!path.exists());
        let good = Record {
            x: vec![0.0, 1.0],
            ..rec
        };
        let missing_dir = dir.path().join("no_dir/x.csv");
        let e = good.write_csv(&missing_dir).unwrap_err();
        assert!(e.message.contains("cannot write"), "{e}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    /// Reading speed: `cargo test -p stf-core --release -- --ignored --nocapture csv_read_timing`
    #[test]
    #[ignore]
    fn csv_read_timing_150k_rows() {
        let mut text = String::from("t,phi,x,f_stf\n");
        for i in 0..150_000 {
            let t = i as f64 * 1e-3;
            text += &format!(
                "{t},{},{},{}\n",
                0.0235 * t * t,
                0.02 * t.sin(),
                0.1 * t.cos()
            );
        }
        let start = std::time::Instant::now();
        let r = Record::read_csv_from(text.as_bytes(), "big.csv").unwrap();
        println!(
            "150 000 rows × 4 columns: {:.1} ms wall",
            start.elapsed().as_secs_f64() * 1e3
        );
        assert_eq!(r.len(), 150_000);
    }

    #[test]
    fn format_f64_is_shortest_and_exact() {
        for v in [
            0.1,
            -0.0,
            1e-300,
            123456.789,
            5e-324,
            f64::MAX,
            1e15,
            9.99e-5,
        ] {
            let s = format_f64(v);
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
            assert!(s.len() < 26, "{s}");
        }
        assert_eq!(format_f64(0.1), "0.1");
    }
}
