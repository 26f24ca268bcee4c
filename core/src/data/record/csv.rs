//! Records as CSV: a header row naming the columns (or none: columns by number), one sample
//! per row.
//!
//! The lines before the header (`skip`) are passed over whatever they hold. Cells are
//! separated by a comma, a semicolon or a tab — told from the header line unless set — and
//! numbers may use a decimal comma. Cells and names are trimmed of whitespace; extra columns
//! are ignored. Rows are reported as the line numbers an editor shows (line 1 is the file's
//! first line, skipped or not).
//!
//! The file is streamed: rows go straight into the columns (`csv_rows`), so reading takes
//! about the columns' own memory (at most twice it while they grow), whatever the text's size.

use super::csv_rows::{RowLines, Rows};
use super::layout::{self, Raw};
use super::{Column, DecimalMark, ReadOptions, Record, RecordError, Separator, Signal};

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
    reader: R,
    source: &str,
    opts: &ReadOptions,
) -> Result<Record, RecordError> {
    let mut rows = Rows::new(reader, source, opts.max_bytes);
    skip_lines(source, opts, &mut rows)?;
    let delimiter = delimiter(source, opts, &mut rows)?;
    rows.delimiter(delimiter);
    let mut found = if opts.header {
        Some(read_header(source, opts, &mut rows)?)
    } else {
        None
    };
    let mut raw: Raw = Default::default();
    let mut lines = RowLines::default();
    let mut scratch = String::new();
    while let Some(line) = rows.next_row()? {
        if found.is_none() {
            found = Some(resolve(source, opts, None, rows.width(), line)?);
        }
        let Some(found) = &found else { continue };
        check_width(source, found, rows.width(), line)?;
        for p in &found.places {
            let cell = rows.cell(p.index).unwrap_or_default();
            let value = number(source, line, &p.label, cell, opts.decimal, &mut scratch)?;
            raw[p.signal.index()]
                .get_or_insert_with(Vec::new)
                .push(value);
        }
        lines.push(line);
    }
    if lines.len() == 0 {
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
    let row_of = |i: usize| lines.line(i);
    let raw = layout::apply(opts, raw, source, &labels, &row_of)?;
    super::into_record(raw, source, &labels, &row_of)
}

/// Pass over the `skip` lines before the header, whatever they hold.
fn skip_lines<R: std::io::Read>(
    source: &str,
    opts: &ReadOptions,
    rows: &mut Rows<R>,
) -> Result<(), RecordError> {
    for _ in 0..opts.skip {
        if rows.next_line()?.is_none() {
            return Err(RecordError::new(
                source,
                format!(
                    "`skip` = {} passes over the whole file ({} line(s))",
                    opts.skip,
                    rows.line_number()
                ),
            ));
        }
        rows.skip_line();
    }
    Ok(())
}

/// The separator: as set, or told from the first non-blank line (a tab, else a semicolon,
/// else a comma). The lines looked at are left for the rows.
fn delimiter<R: std::io::Read>(
    source: &str,
    opts: &ReadOptions,
    rows: &mut Rows<R>,
) -> Result<u8, RecordError> {
    match opts.separator {
        Separator::Comma => return Ok(b','),
        Separator::Semicolon => return Ok(b';'),
        Separator::Tab => return Ok(b'\t'),
        Separator::Auto => {}
    }
    let (line, first) = loop {
        match rows.next_line()? {
            None => return Ok(b','), // nothing to read: the reader says so
            Some((line, text)) if text.iter().any(|b| !b.is_ascii_whitespace()) => {
                break (line, text)
            }
            Some(_) => {}
        }
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
        .at_row(line))
    } else {
        Ok(b',')
    }
}

/// Read the header row and find the wanted columns in it.
fn read_header<R: std::io::Read>(
    source: &str,
    opts: &ReadOptions,
    rows: &mut Rows<R>,
) -> Result<Found, RecordError> {
    let got = rows.next_row()?;
    let line = got.unwrap_or(rows.line_number() + 1);
    let header = got.map(|line| rows.texts(line)).transpose()?;
    let header = header.unwrap_or_default();
    if header.iter().all(String::is_empty) {
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
    resolve(source, opts, Some(&header), header.len(), line)
}

/// Find the wanted columns, by name in the header or by number; `line` is the header's (or
/// the first row's) line.
fn resolve(
    source: &str,
    opts: &ReadOptions,
    header: Option<&[String]>,
    width: usize,
    line: usize,
) -> Result<Found, RecordError> {
    let by = header.map_or("first row", |_| "header");
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
                Some((k - 1, name.map_or_else(|| k.to_string(), String::clone)))
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
            None if must => return Err(missing(source, opts, signal, header, line)),
            None => {}
        }
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
    header: Option<&[String]>,
    line: usize,
) -> RecordError {
    let name = column_name(opts, signal);
    let err = |message: String| {
        RecordError::new(source, message)
            .at_row(line)
            .in_column(name.as_str())
    };
    let Some(header) = header else {
        return err(format!(
            "no column for `{signal}`: a file without a header row takes columns by \
             number, e.g. columns = {{ {signal} = 2 }}"
        ));
    };
    let similar = header
        .iter()
        .find(|h| h.eq_ignore_ascii_case(&name))
        .map(|h| format!(" (`{h}` differs only in case; names are case-sensitive)"))
        .unwrap_or_default();
    err(format!(
        "missing column `{name}`{similar}; the header has: {}",
        header.join(", ")
    ))
}

/// The column called `name`, if the header has it (twice is an error).
fn find(
    source: &str,
    header: &[String],
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
fn check_width(source: &str, found: &Found, n: usize, line: usize) -> Result<(), RecordError> {
    let (width, by) = (found.width, found.by);
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
        .at_row(line)
        .in_column(column));
    }
    if n > width {
        return Err(RecordError::new(
            source,
            format!("long row: {n} cells, the {by} has {width} (a stray separator?)"),
        )
        .at_row(line));
    }
    Ok(())
}

/// One numeric cell, with a decimal point or (`DecimalMark::Comma`) a decimal comma;
/// `scratch` holds the cell with its comma made a point.
fn number(
    source: &str,
    line: usize,
    name: &str,
    cell: &[u8],
    decimal: DecimalMark,
    scratch: &mut String,
) -> Result<f64, RecordError> {
    let at = |message: String| {
        RecordError::new(source, message)
            .at_row(line)
            .in_column(name)
    };
    let Ok(text) = std::str::from_utf8(cell) else {
        return Err(at("invalid UTF-8 text".into()));
    };
    if text.is_empty() {
        return Err(at("empty cell".into()));
    }
    let parsed = match decimal {
        DecimalMark::Point => text.parse::<f64>().ok(),
        DecimalMark::Comma if text.contains('.') => None,
        DecimalMark::Comma => {
            scratch.clear();
            scratch.extend(text.chars().map(|c| if c == ',' { '.' } else { c }));
            scratch.parse::<f64>().ok()
        }
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

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::super::{ColumnNames, ReadOptions, MEMORY_SOURCE};
    use super::*;
    use rand::{rngs::StdRng, Rng, SeedableRng};
    use std::path::Path;

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
    fn force_driven_rig_reads_u_instead_of_phi() {
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
    fn a_record_without_drive_is_read() {
        // A damper rig records t, x and the force only.
        let r = read_str("t,x,f_stf\n0,0,1.5\n1,0.1,1.6\n").unwrap();
        assert_eq!(r.f_stf, Some(vec![1.5, 1.6]));
        assert!(r.phi.is_none() && r.u.is_none() && r.omega.is_none());
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
            "a\nb\nt;phi\n0;0\n",
            Some(3),
            Some("x"),
            "missing column `x`",
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
        let r = no_drive
            .read_csv_from("0,5\n".as_bytes(), "lab.csv")
            .unwrap();
        assert_eq!((r.t, r.x), (vec![0.0], vec![5.0]));
        // A named signal (by default, by name) cannot be found without a header.
        expect_with(
            &no_drive.column(Signal::Phi, Column::Name("angle".into())),
            "0,5\n",
            None,
            None,
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
        rec.write_csv(std::fs::File::create(&path).unwrap())
            .unwrap();
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
    fn awkward_floats_round_trip_through_a_file_bit_for_bit() {
        let awkward = [
            -0.0,
            0.0,
            0.1,
            5e-324,
            -2.225073858507201e-308,
            f64::MIN_POSITIVE,
            1e300,
            -f64::MAX,
            1.0 / 3.0,
            9.999999999999998e15,
            -(97_135_501_438_217.0 + 0.625), // a tie between two shortest texts
            1e-5,
        ];
        let n = awkward.len();
        let rec = Record {
            source: MEMORY_SOURCE.into(),
            t: (0..n).map(|i| i as f64).collect(),
            x: awkward.to_vec(),
            phi: Some(awkward.iter().rev().copied().collect()),
            f_stf: Some(awkward.iter().map(|v| -v).collect()),
            omega: None,
            u: None,
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("awkward.csv");
        rec.write_csv(std::fs::File::create(&path).unwrap())
            .unwrap();
        let back = Record::read_csv(&path).unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back.x), bits(&rec.x));
        assert_eq!(
            bits(back.phi.as_deref().unwrap()),
            bits(rec.phi.as_deref().unwrap())
        );
        assert_eq!(
            bits(back.f_stf.as_deref().unwrap()),
            bits(rec.f_stf.as_deref().unwrap())
        );
    }

    #[test]
    fn write_refuses_an_invalid_record_and_names_a_failed_write() {
        let rec = Record {
            source: MEMORY_SOURCE.into(),
            t: vec![0.0, 1.0],
            x: vec![0.0, f64::NAN],
            phi: Some(vec![0.0, 0.0]),
            f_stf: None,
            omega: None,
            u: None,
        };
        let mut written = Vec::new();
        let e = rec.write_csv(&mut written).unwrap_err();
        assert_eq!((e.row, e.column.as_deref()), (Some(2), Some("x")));
        assert!(written.is_empty());
        let good = Record {
            x: vec![0.0, 1.0],
            ..rec
        };
        // A writer that fails (a full disk) is an error naming the record.
        struct Full;
        impl std::io::Write for Full {
            fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
                Err(std::io::Error::other("no space left"))
            }
            fn flush(&mut self) -> std::io::Result<()> {
                Ok(())
            }
        }
        let e = good.write_csv(Full).unwrap_err();
        assert!(
            e.message.contains("cannot write") && e.message.contains("no space left"),
            "{e}"
        );
    }

    #[test]
    fn a_file_over_max_bytes_is_refused_with_its_size_and_the_limit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.csv");
        let text = "t,x,phi\n0,0,0\n1,0,0\n";
        std::fs::write(&path, text).unwrap();
        let exact = ReadOptions::default().max_bytes(text.len() as u64);
        assert_eq!(exact.read_csv(&path).unwrap().len(), 2);
        let e = exact
            .max_bytes(text.len() as u64 - 1)
            .read_csv(&path)
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{}: is {} bytes, over the limit of {} bytes for a record (`max_bytes`)",
                path.display(),
                text.len(),
                text.len() - 1
            )
        );
        // A stream has no length to check first: it is stopped one byte past the cap.
        let e = ReadOptions::default()
            .max_bytes(10)
            .read_csv_from(text.as_bytes(), "pipe.csv")
            .unwrap_err();
        assert!(e.message.contains("more than the limit of 10 bytes"), "{e}");
    }

    #[cfg(unix)]
    #[test]
    fn dev_zero_as_a_record_is_an_error_not_a_full_memory() {
        let e = Record::read_csv(Path::new("/dev/zero")).unwrap_err();
        assert_eq!((e.file.as_str(), e.row), ("/dev/zero", Some(1)), "{e}");
        assert!(
            e.message.contains("line is longer than 1048576 bytes"),
            "{e}"
        );
        let e = Record::read(Path::new("/dev/zero")).unwrap_err();
        assert!(e.message.contains("unknown record file type"), "{e}");
        let e = ReadOptions::default()
            .max_bytes(1 << 16)
            .read_mat(Path::new("/dev/zero"))
            .unwrap_err();
        assert!(
            e.message
                .contains("holds more than the limit of 65536 bytes"),
            "{e}"
        );
    }

    /// The columns of a plain comma-separated text with a header, parsed the simplest way.
    fn naive_columns(text: &str) -> Vec<(String, Vec<f64>)> {
        let mut lines = text.lines();
        let names = lines.next().unwrap().split(',');
        let mut columns: Vec<(String, Vec<f64>)> =
            names.map(|n| (n.trim().to_string(), Vec::new())).collect();
        for line in lines {
            for (cell, (_, values)) in line.split(',').zip(columns.iter_mut()) {
                values.push(cell.trim().parse().unwrap());
            }
        }
        columns
    }

    #[test]
    fn streaming_reads_the_bundled_records_and_writing_them_gives_the_same_bytes() {
        let records = Path::new(env!("CARGO_MANIFEST_DIR")).join("../experiments/records");
        let dir = tempfile::tempdir().unwrap();
        let mut seen = 0;
        for entry in std::fs::read_dir(&records).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().and_then(|e| e.to_str()) != Some("csv") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let rec = Record::read_csv(&path).unwrap();
            for (name, values) in naive_columns(&text) {
                let read = match name.as_str() {
                    "t" => Some(&rec.t),
                    "x" => Some(&rec.x),
                    "phi" => rec.phi.as_ref(),
                    "f_stf" => rec.f_stf.as_ref(),
                    "omega" => rec.omega.as_ref(),
                    "u" => rec.u.as_ref(),
                    _ => None,
                };
                // Bit for bit: `-0` stays `-0`.
                let bits = |v: &Vec<f64>| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    read.map(bits),
                    Some(bits(&values)),
                    "{} column {name}",
                    path.display()
                );
            }
            let copy = dir.path().join("copy.csv");
            rec.write_csv(std::fs::File::create(&copy).unwrap())
                .unwrap();
            assert!(
                std::fs::read(&copy).unwrap() == text.as_bytes(),
                "{}",
                path.display()
            );
            seen += 1;
        }
        assert!(seen >= 5, "{seen} records");
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
}
