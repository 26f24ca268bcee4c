//! Records as CSV: a header row naming the columns (or none: columns by number), one sample
//! per row.
//!
//! The lines before the header (`skip`) are passed over whatever they hold. Cells are
//! separated by a comma, a semicolon or a tab — told from the header line unless set — and
//! numbers may use a decimal comma. Cells and names are trimmed of whitespace; extra columns
//! are ignored. Rows are reported as the line numbers an editor shows (line 1 is the file's
//! first line, skipped or not).

use super::layout::{self, Raw};
use super::{Column, Columns, DecimalMark, ReadOptions, Record, RecordError, Separator, Signal};
use std::io::Write;
use std::path::Path;

/// The whole text of the file (kept so that rows can be reported as editor lines: the csv
/// crate's own line count skips blank lines) and where the part after `skip` lines begins.
struct Text {
    data: Vec<u8>,
    start: usize,
}

impl Text {
    /// The part the csv parser reads.
    fn body(&self) -> &[u8] {
        self.data.get(self.start..).unwrap_or_default()
    }

    /// The editor line of the record whose parse began at `byte` of the body. Counting
    /// lines is O(file): only done for an error.
    fn line(&self, byte: u64) -> usize {
        line_of(&self.data, self.start as u64 + byte)
    }
}

/// Where a wanted signal sits in a row (0-based) and the column name errors use.
struct Place {
    signal: Signal,
    index: usize,
    label: String,
}

/// The columns found: where each wanted signal sits, and how many cells a row has.
struct Found {
    places: Vec<Place>,
    width: usize,
    /// `header` or `first row`: what fixed the width (for messages).
    by: &'static str,
    /// The line of the header (or the first row).
    line: usize,
}

/// Read a record from CSV text laid out as `opts` says.
pub(super) fn read<R: std::io::Read>(
    mut reader: R,
    source: &str,
    opts: &ReadOptions,
) -> Result<Record, RecordError> {
    let mut data = Vec::new();
    reader
        .read_to_end(&mut data)
        .map_err(|e| RecordError::new(source, format!("cannot read: {e}")))?;
    let lines = data.split(|&b| b == b'\n').count();
    let start = skip_lines(&data, opts.skip).ok_or_else(|| {
        RecordError::new(
            source,
            format!(
                "`skip` = {} passes over the whole file ({lines} line(s))",
                opts.skip
            ),
        )
    })?;
    let text = Text { data, start };
    let delimiter = delimiter(source, opts, &text)?;
    let mut rdr = ::csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(::csv::Trim::All)
        .delimiter(delimiter)
        .from_reader(text.body());
    let mut row = ::csv::StringRecord::new();
    let mut found = if opts.header {
        Some(read_header(source, opts, &text, &mut rdr, &mut row)?)
    } else {
        None
    };
    let mut raw: Raw = Default::default();
    let mut starts: Vec<u64> = Vec::new();
    while next_row(source, &text, &mut rdr, &mut row)? {
        let start = row.position().map_or(0, |p| p.byte());
        let line = || text.line(start);
        if found.is_none() {
            found = Some(resolve(source, opts, None, row.len(), line())?);
        }
        let Some(found) = &found else { continue };
        if starts.is_empty() {
            for p in &found.places {
                raw[p.signal.index()] = Some(Vec::new());
            }
        }
        check_width(source, found, &row, line)?;
        for p in &found.places {
            let value = number(source, &line, &p.label, row.get(p.index), opts.decimal)?;
            if let Some(values) = raw[p.signal.index()].as_mut() {
                values.push(value);
            }
        }
        starts.push(start);
    }
    if starts.is_empty() {
        let message = if opts.header {
            "no data rows: the file holds only the header"
        } else {
            "empty file: no data rows"
        };
        let after = found.map_or(opts.skip + 1, |f| f.line + 1);
        return Err(RecordError::new(source, message).at_row(after));
    }
    let mut labels = Signal::ALL.map(|s| s.name().to_string());
    for p in found.iter().flat_map(|f| &f.places) {
        labels[p.signal.index()].clone_from(&p.label);
    }
    let row_of = |i: usize| starts.get(i).map_or(i + 1, |&b| text.line(b));
    let raw = layout::apply(opts, raw, source, &labels, &row_of)?;
    Columns(raw).into_record(source, &labels, &row_of)
}

/// The byte where line `n + 1` begins, if the text has that many line ends.
fn skip_lines(data: &[u8], n: usize) -> Option<usize> {
    let mut at = 0;
    for _ in 0..n {
        at += data.get(at..)?.iter().position(|&b| b == b'\n')? + 1;
    }
    Some(at)
}

/// The separator: as set, or told from the first non-blank line (a tab, else a semicolon,
/// else a comma).
fn delimiter(source: &str, opts: &ReadOptions, text: &Text) -> Result<u8, RecordError> {
    match opts.separator {
        Separator::Comma => return Ok(b','),
        Separator::Semicolon => return Ok(b';'),
        Separator::Tab => return Ok(b'\t'),
        Separator::Auto => {}
    }
    let Some((index, first)) = text
        .body()
        .split(|&b| b == b'\n')
        .enumerate()
        .find(|(_, l)| l.iter().any(|b| !b.is_ascii_whitespace()))
    else {
        return Ok(b','); // nothing to read: the reader says so
    };
    if first.contains(&b'\t') {
        Ok(b'\t')
    } else if first.contains(&b';') {
        Ok(b';')
    } else if opts.decimal == DecimalMark::Comma {
        Err(RecordError::new(
            source,
            "cannot tell the separator: the line has no tab or semicolon, and commas are the \
             decimal mark; set `separator`",
        )
        .at_row(opts.skip + index + 1))
    } else {
        Ok(b',')
    }
}

/// The next row into `row`; `false` at the end.
fn next_row(
    source: &str,
    text: &Text,
    rdr: &mut ::csv::Reader<&[u8]>,
    row: &mut ::csv::StringRecord,
) -> Result<bool, RecordError> {
    rdr.read_record(row)
        .map_err(|e| csv_error(source, text, &e))
}

/// Read the header row and find the wanted columns in it.
fn read_header(
    source: &str,
    opts: &ReadOptions,
    text: &Text,
    rdr: &mut ::csv::Reader<&[u8]>,
    row: &mut ::csv::StringRecord,
) -> Result<Found, RecordError> {
    let got = next_row(source, text, rdr, row)?;
    let line = row
        .position()
        .map_or(opts.skip + 1, |p| text.line(p.byte()));
    if !got || row.iter().all(str::is_empty) {
        let what = if opts.skip > 0 {
            format!("nothing after the {} skipped line(s)", opts.skip)
        } else {
            "empty file".to_string()
        };
        return Err(RecordError::new(
            source,
            format!("{what}: expected a header row naming the columns (t, x, phi, …)"),
        )
        .at_row(line.max(opts.skip + 1)));
    }
    resolve(source, opts, Some(row), row.len(), line)
}

/// Find the wanted columns, by name in the header or by number; `line` is the header's (or
/// the first row's) line.
fn resolve(
    source: &str,
    opts: &ReadOptions,
    header: Option<&::csv::StringRecord>,
    width: usize,
    line: usize,
) -> Result<Found, RecordError> {
    let by = if header.is_some() {
        "header"
    } else {
        "first row"
    };
    let mut places = Vec::new();
    for (signal, ch) in opts.wanted() {
        let place = match (&ch.column, header) {
            (Column::Number(k), _) => {
                if *k == 0 || *k > width {
                    return Err(RecordError::new(
                        source,
                        format!("`{signal}` is in column {k}, but the {by} has {width} column(s)"),
                    )
                    .at_row(line)
                    .in_column(k.to_string()));
                }
                let name = header.and_then(|h| h.get(k - 1)).filter(|n| !n.is_empty());
                Some((k - 1, name.map_or_else(|| k.to_string(), str::to_string)))
            }
            (Column::Name(name), Some(h)) => {
                find(source, h, name, line)?.map(|index| (index, name.clone()))
            }
            (Column::Name(_), None) => None,
        };
        let must = opts.needs(signal);
        match place {
            Some((index, label)) => places.push(Place {
                signal,
                index,
                label,
            }),
            None if must => return Err(missing(source, opts, signal, header, line, "")),
            None => {}
        }
    }
    if !places
        .iter()
        .any(|p| matches!(p.signal, Signal::Phi | Signal::U))
    {
        let extra = format!(
            " (or `{}` for a force-driven rig)",
            column_name(opts, Signal::U)
        );
        return Err(missing(source, opts, Signal::Phi, header, line, &extra));
    }
    Ok(Found {
        places,
        width,
        by,
        line,
    })
}

/// How the layout names `signal`'s column.
fn column_name(opts: &ReadOptions, signal: Signal) -> String {
    match &opts.channel(signal).column {
        Column::Name(name) => name.clone(),
        Column::Number(k) => k.to_string(),
    }
}

/// `signal`'s column is not in the file.
fn missing(
    source: &str,
    opts: &ReadOptions,
    signal: Signal,
    header: Option<&::csv::StringRecord>,
    line: usize,
    extra: &str,
) -> RecordError {
    let name = column_name(opts, signal);
    let err = |message: String| {
        RecordError::new(source, message)
            .at_row(line)
            .in_column(name.as_str())
    };
    let Some(header) = header else {
        return err(format!(
            "no column for `{signal}`{extra}: a file without a header row takes columns by \
             number, e.g. columns = {{ {signal} = 2 }}"
        ));
    };
    let similar = header
        .iter()
        .find(|h| h.eq_ignore_ascii_case(&name))
        .map(|h| format!(" (`{h}` differs only in case; names are case-sensitive)"))
        .unwrap_or_default();
    err(format!(
        "missing column `{name}`{extra}{similar}; the header has: {}",
        header.iter().collect::<Vec<_>>().join(", ")
    ))
}

/// The column called `name`, if the header has it (twice is an error).
fn find(
    source: &str,
    header: &::csv::StringRecord,
    name: &str,
    line: usize,
) -> Result<Option<usize>, RecordError> {
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
        .at_row(line)
        .in_column(name));
    }
    Ok(first)
}

/// A row must have as many cells as the header (or the first row).
fn check_width(
    source: &str,
    found: &Found,
    row: &::csv::StringRecord,
    line: impl Fn() -> usize,
) -> Result<(), RecordError> {
    let (n, width, by) = (row.len(), found.width, found.by);
    if n < width {
        let column = found
            .places
            .iter()
            .find(|p| p.index == n)
            .map_or_else(|| (n + 1).to_string(), |p| p.label.clone());
        return Err(RecordError::new(
            source,
            format!("short row: {n} cell(s), the {by} has {width}"),
        )
        .at_row(line())
        .in_column(column));
    }
    if n > width {
        return Err(RecordError::new(
            source,
            format!("long row: {n} cells, the {by} has {width} (a stray separator?)"),
        )
        .at_row(line()));
    }
    Ok(())
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

/// One numeric cell, with a decimal point or (`DecimalMark::Comma`) a decimal comma.
fn number(
    source: &str,
    line: &dyn Fn() -> usize,
    name: &str,
    cell: Option<&str>,
    decimal: DecimalMark,
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
    let parsed = match decimal {
        DecimalMark::Point => text.parse::<f64>().ok(),
        DecimalMark::Comma if text.contains('.') => None,
        DecimalMark::Comma => text.replace(',', ".").parse::<f64>().ok(),
    };
    let value = parsed.ok_or_else(|| match decimal {
        DecimalMark::Point => at(format!("not a number: `{text}`")),
        DecimalMark::Comma => at(format!(
            "not a number: `{text}` (the decimal mark is a comma)"
        )),
    })?;
    if !value.is_finite() {
        return Err(at(format!("not a finite number: `{text}`")));
    }
    Ok(value)
}

/// A CSV-level failure (I/O, invalid UTF-8), with the line where known.
fn csv_error(source: &str, text: &Text, e: &::csv::Error) -> RecordError {
    let line = match e.kind() {
        ::csv::ErrorKind::Utf8 { pos: Some(p), .. }
        | ::csv::ErrorKind::UnequalLengths { pos: Some(p), .. } => Some(text.line(p.byte())),
        _ => e.position().map(|p| text.line(p.byte())),
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
    use super::super::{ColumnNames, ReadOptions, MEMORY_SOURCE};
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

    use super::super::{Column, DecimalMark, Offset, Separator, Signal, Unit};

    /// Read `text` with `opts`, expecting an error at `row`, `column`, containing `words`.
    fn expect_with(
        opts: &ReadOptions,
        text: &str,
        row: Option<usize>,
        column: Option<&str>,
        words: &str,
    ) {
        let e = opts.read_csv_from(text.as_bytes(), "lab.csv").unwrap_err();
        assert_eq!((e.row, e.column.as_deref()), (row, column), "{e}");
        assert!(e.message.contains(words), "{e}");
    }

    #[test]
    fn semicolons_tabs_and_decimal_commas() {
        let comma = ReadOptions::default().decimal(DecimalMark::Comma);
        let r = comma
            .read_csv_from("t;x;phi\n0;1,5;2,25\n0,5;-1e-3;3\n".as_bytes(), "lab.csv")
            .unwrap();
        assert_eq!((r.t, r.x), (vec![0.0, 0.5], vec![1.5, -1e-3]));
        assert_eq!(r.phi.unwrap(), [2.25, 3.0]);
        let r = comma
            .read_csv_from("t\tx\tphi\n0\t1,5\t2\n".as_bytes(), "lab.csv")
            .unwrap();
        assert_eq!(r.x, [1.5]);
        let r = Record::read_csv_from("t;x;phi\n0;1.5;2\n".as_bytes(), "lab.csv").unwrap();
        assert_eq!(r.x, [1.5]);
        let set = ReadOptions::default().separator(Separator::Semicolon);
        let r = set
            .read_csv_from("t;x;a,b;phi\n0;1;2;3\n".as_bytes(), "lab.csv")
            .unwrap();
        assert_eq!(r.len(), 1);
        // A decimal point in a decimal-comma file, on editor line 4 after a blank line.
        expect_with(
            &comma,
            "t;x;phi\n0;1,5;2\n\n1;2.5;2\n",
            Some(4),
            Some("x"),
            "decimal mark is a comma",
        );
        expect_with(
            &comma,
            "t x phi\n0 1,5 2\n",
            Some(1),
            None,
            "cannot tell the separator",
        );
    }

    #[test]
    fn skipped_lines_keep_editor_line_numbers() {
        let opts = ReadOptions::default().skip(2).decimal(DecimalMark::Comma);
        let text = "Rig 7; 2024-05-02\n\"quoted, stuff\nt;x;phi\n0;0;0\n0,1;zz;0\n";
        expect_with(&opts, text, Some(5), Some("x"), "not a number: `zz`");
        let text = "a\nb\nt;x;phi\n0;0;0\n0;0;0\n";
        expect_with(&opts, text, Some(5), Some("t"), "not strictly increasing");
        expect_with(
            &opts,
            "a\nb\nt;x\n0;0\n",
            Some(3),
            Some("phi"),
            "missing column `phi`",
        );
        expect_with(&opts, "a\nb\nt;x;phi\n", Some(4), None, "no data rows");
        expect_with(
            &opts,
            "a\nb\n",
            Some(3),
            None,
            "nothing after the 2 skipped line(s)",
        );
        expect_with(
            &opts,
            "a\n",
            None,
            None,
            "`skip` = 2 passes over the whole file",
        );
        let r = opts
            .read_csv_from("x;y\n# c\nt;x;phi\n0;1;2\n".as_bytes(), "lab.csv")
            .unwrap();
        assert_eq!(r.x, [1.0]);
    }

    #[test]
    fn columns_by_number_with_or_without_a_header() {
        let opts = ReadOptions::default()
            .column(Signal::X, Column::Number(3))
            .column(Signal::U, Column::Number(2));
        let r = opts
            .read_csv_from("t,drive,disp\n0,5,1\n1,6,2\n".as_bytes(), "lab.csv")
            .unwrap();
        assert_eq!((r.x, r.u.unwrap()), (vec![1.0, 2.0], vec![5.0, 6.0]));
        expect_with(
            &opts,
            "t,drive,disp\n0,5,zz\n",
            Some(2),
            Some("disp"),
            "`zz`",
        );
        let bare = opts
            .clone()
            .header(false)
            .column(Signal::T, Column::Number(1));
        let r = bare
            .read_csv_from("\n0,5,1\n1,6,2\n".as_bytes(), "lab.csv")
            .unwrap();
        assert_eq!(r.t, [0.0, 1.0]);
        expect_with(
            &bare,
            "0,5,1\n1,6\n",
            Some(2),
            Some("3"),
            "short row: 2 cell(s), the first row has 3",
        );
        expect_with(
            &bare,
            "0,5\n",
            Some(1),
            Some("3"),
            "`x` is in column 3, but the first row has 2",
        );
        let no_drive = ReadOptions::default()
            .header(false)
            .column(Signal::T, Column::Number(1))
            .column(Signal::X, Column::Number(2));
        expect_with(
            &no_drive,
            "0,5\n",
            Some(1),
            Some("phi"),
            "takes columns by number",
        );
    }

    #[test]
    fn a_rate_replaces_the_time_column_and_rest_offsets_apply() {
        let opts = ReadOptions::default()
            .rate(100.0, 2.0)
            .unit(Signal::X, Unit::Millimetre)
            .offset(Signal::X, Offset::Rest)
            .unit(Signal::Phi, Unit::Counts { per_rev: 4.0 })
            .offset(Signal::Phi, Offset::Value(1.0))
            .rest(2.0, 2.015);
        let r = opts
            .read_csv_from("x,phi\n1,1\n3,2\n7,5\n".as_bytes(), "lab.csv")
            .unwrap();
        assert_eq!(r.t, [2.0, 2.01, 2.02]);
        assert_eq!(r.x, [-1e-3, 1e-3, 5e-3]);
        let phi = r.phi.unwrap();
        assert!(
            (phi[2] - 2.0 * std::f64::consts::PI).abs() < 1e-12,
            "{phi:?}"
        );
        let bad = opts.clone().rest(9.0, 10.0);
        expect_with(&bad, "x,phi\n1,1\n", None, Some("x"), "holds no samples");
        let e = ReadOptions::default()
            .rate(-1.0, 0.0)
            .read_csv_from("x,phi\n1,1\n".as_bytes(), "lab.csv")
            .unwrap_err();
        assert!(
            e.to_string()
                .starts_with("lab.csv: cannot be read with this layout (`rate`)"),
            "{e}"
        );
    }

    proptest::proptest! {
        /// Any text read with any layout is a record or an error, never a panic.
        #[test]
        fn any_text_with_any_layout_never_panics(
            text in "[0-9a-z,;.\t\n\r\" -]{0,200}",
            skip in 0usize..4,
            header: bool,
            comma: bool,
            separator in 0usize..4,
            x in 0usize..5,
            rate: bool,
        ) {
            let mut opts = ReadOptions::default()
                .skip(skip)
                .header(header)
                .separator([Separator::Auto, Separator::Comma, Separator::Semicolon, Separator::Tab][separator])
                .column(Signal::X, Column::Number(x))
                .offset(Signal::X, Offset::Rest)
                .rest(0.0, 1.0);
            if comma {
                opts = opts.decimal(DecimalMark::Comma);
            }
            opts = if rate {
                opts.rate(10.0, 0.0)
            } else {
                opts.column(Signal::T, Column::Number(1))
            };
            let _ = opts.read_csv_from(text.as_bytes(), "p.csv");
        }
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
