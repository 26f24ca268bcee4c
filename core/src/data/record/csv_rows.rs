//! The rows of a CSV file, one at a time, each with the editor line it starts on.
//!
//! The file is read a line at a time (never whole) and each line is fed to `csv_core`'s
//! parser, so quoting works as in the `csv` crate, a quoted cell may span lines, and the row's
//! line is the editor's: blank lines are counted, not lost (the `csv` crate's own line count
//! cannot say on which line a row after blank lines starts, hence this thin layer over its
//! core parser). What is read is capped: the whole file at `ReadOptions::max_bytes`, a line
//! at [`MAX_LINE`], so a wrong path such as `/dev/zero` is an error, not a full memory.

use std::io::{BufRead, Read};

use csv_core::ReadRecordResult;

use super::RecordError;
use crate::data::bounded::byte_size;

/// The longest line read, bytes: far beyond any record's row (1 MiB).
pub(super) const MAX_LINE: usize = 1 << 20;

/// The UTF-8 byte-order mark some programs put before the first line.
const BOM: &[u8] = b"\xef\xbb\xbf";

/// A CSV source read a line, and handed out a row, at a time.
pub(super) struct Rows<'s, R> {
    input: std::io::BufReader<std::io::Take<R>>,
    source: &'s str,
    limit: u64,
    read: u64,
    parser: csv_core::Reader,
    /// The current line, its terminator replaced by a single `\n`.
    line: Vec<u8>,
    /// How much of `line` the parser has taken.
    pos: usize,
    /// The current line's number (1-based; 0 before the first).
    number: usize,
    /// The current row's cells, back to back, and where each ends.
    cells: Vec<u8>,
    ends: Vec<usize>,
    width: usize,
}

impl<'s, R: Read> Rows<'s, R> {
    /// Rows of `input`, refusing it past `limit` bytes; `source` names it in errors.
    pub(super) fn new(input: R, source: &'s str, limit: u64) -> Self {
        Rows {
            input: std::io::BufReader::with_capacity(1 << 16, input.take(limit.saturating_add(1))),
            source,
            limit,
            read: 0,
            parser: csv_core::Reader::new(),
            line: Vec::new(),
            pos: 0,
            number: 0,
            cells: vec![0; 256],
            ends: vec![0; 16],
            width: 0,
        }
    }

    /// Parse cells separated by `delimiter` from now on.
    pub(super) fn delimiter(&mut self, delimiter: u8) {
        self.parser = csv_core::ReaderBuilder::new().delimiter(delimiter).build();
    }

    /// The next line as text (for skipping and for telling the separator); `None` at the end.
    /// The line is kept: the next row begins with it.
    pub(super) fn next_line(&mut self) -> Result<Option<(usize, &[u8])>, RecordError> {
        if !self.read_line()? {
            return Ok(None);
        }
        Ok(Some((self.number, &self.line[..self.line.len() - 1])))
    }

    /// Pass over the current line without parsing it.
    pub(super) fn skip_line(&mut self) {
        self.pos = self.line.len();
    }

    /// The current line's number.
    pub(super) fn line_number(&self) -> usize {
        self.number
    }

    /// Read the next line into `line`; `false` at the end of the input.
    fn read_line(&mut self) -> Result<bool, RecordError> {
        self.line.clear();
        self.pos = 0;
        let got = (&mut self.input)
            .take(MAX_LINE as u64 + 1)
            .read_until(b'\n', &mut self.line)
            .map_err(|e| RecordError::new(self.source, format!("cannot read: {e}")))?;
        if got == 0 {
            return Ok(false);
        }
        self.read += got as u64;
        self.number += 1;
        if self.read > self.limit {
            return Err(RecordError::new(
                self.source,
                format!(
                    "the file holds more than the limit of {} for a record (`max_bytes`)",
                    byte_size(self.limit)
                ),
            ));
        }
        let ended = self.line.last() == Some(&b'\n');
        if !ended && self.line.len() > MAX_LINE {
            return Err(RecordError::new(
                self.source,
                format!(
                    "the line is longer than {}: not the text of a record",
                    byte_size(MAX_LINE as u64)
                ),
            )
            .at_row(self.number));
        }
        if ended {
            self.line.pop();
            if self.line.last() == Some(&b'\r') {
                self.line.pop();
            }
        }
        if self.number == 1 && self.line.starts_with(BOM) {
            self.line.drain(..BOM.len());
        }
        self.line.push(b'\n');
        Ok(true)
    }

    /// Read the next row; `Some(line it starts on)`, or `None` at the end. Blank lines
    /// between rows are passed over.
    pub(super) fn next_row(&mut self) -> Result<Option<usize>, RecordError> {
        let (mut out, mut end) = (0, 0);
        let mut start = None;
        loop {
            let at_end = self.pos == self.line.len();
            if start.is_none() && (at_end || &self.line[self.pos..] == b"\n") {
                if !self.read_line()? {
                    return Ok(None);
                }
                continue;
            }
            // Where the input has ended (inside a quoted cell) the parser is fed nothing and
            // closes the row.
            let eof = at_end && !self.read_line()?;
            let input: &[u8] = if eof { &[] } else { &self.line[self.pos..] };
            start.get_or_insert(self.number); // a no-op at the end: the row has begun
            let (result, used, o, e) =
                self.parser
                    .read_record(input, &mut self.cells[out..], &mut self.ends[end..]);
            self.pos += used;
            (out, end) = (out + o, end + e);
            match result {
                ReadRecordResult::OutputFull => self.cells.resize(2 * self.cells.len(), 0),
                ReadRecordResult::OutputEndsFull => self.ends.resize(2 * self.ends.len(), 0),
                ReadRecordResult::Record => return self.row(end, start),
                ReadRecordResult::InputEmpty if !eof => {}
                _ => return Ok(None),
            }
        }
    }

    fn row(&mut self, width: usize, start: Option<usize>) -> Result<Option<usize>, RecordError> {
        self.width = width;
        Ok(Some(start.unwrap_or(self.number)))
    }

    /// Cells in the current row.
    pub(super) fn width(&self) -> usize {
        self.width
    }

    /// Cell `i` of the current row, trimmed of whitespace.
    pub(super) fn cell(&self, i: usize) -> Option<&[u8]> {
        if i >= self.width {
            return None;
        }
        let start = if i == 0 { 0 } else { self.ends[i - 1] };
        Some(self.cells[start..self.ends[i]].trim_ascii())
    }

    /// The current row's cells as text (a header).
    pub(super) fn texts(&self, line: usize) -> Result<Vec<String>, RecordError> {
        (0..self.width)
            .map(|i| {
                let cell = self.cell(i).unwrap_or_default();
                std::str::from_utf8(cell)
                    .map(str::to_string)
                    .map_err(|_| RecordError::new(self.source, "invalid UTF-8 text").at_row(line))
            })
            .collect()
    }
}

/// The editor line of each row, kept as the first row's line and the rows after which the
/// lines jump (blank lines, cells over several lines): no memory per row.
#[derive(Default)]
pub(super) struct RowLines {
    rows: usize,
    /// `(row index, its line)` where a row is not on the line after its predecessor's.
    jumps: Vec<(usize, usize)>,
}

impl RowLines {
    /// Note the next row's line.
    pub(super) fn push(&mut self, line: usize) {
        if self.rows == 0 || self.line(self.rows - 1) + 1 != line {
            self.jumps.push((self.rows, line));
        }
        self.rows += 1;
    }

    /// Rows noted.
    pub(super) fn len(&self) -> usize {
        self.rows
    }

    /// The line of row `i` (0-based).
    pub(super) fn line(&self, i: usize) -> usize {
        let k = self.jumps.partition_point(|&(row, _)| row <= i);
        match k.checked_sub(1).and_then(|k| self.jumps.get(k)) {
            Some(&(row, line)) => line + (i - row),
            None => i + 1,
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::*;

    fn rows(text: &str) -> Vec<(usize, Vec<String>)> {
        let mut r = Rows::new(text.as_bytes(), "t.csv", 1 << 20);
        r.delimiter(b',');
        let mut out = Vec::new();
        while let Some(line) = r.next_row().unwrap() {
            out.push((line, r.texts(line).unwrap()));
        }
        out
    }

    #[test]
    fn rows_carry_editor_lines_across_blank_lines_crlf_and_quoted_newlines() {
        let got = rows("a,b\n\n\r\n1, 2 \r\n\"x\ny\",3\n4,5");
        let want: Vec<(usize, Vec<String>)> = vec![
            (1, vec!["a".into(), "b".into()]),
            (4, vec!["1".into(), "2".into()]),
            (5, vec!["x\ny".into(), "3".into()]),
            (7, vec!["4".into(), "5".into()]),
        ];
        assert_eq!(got, want);
        assert_eq!(rows("\"open,1\n"), vec![(1, vec!["open,1".into()])]);
    }

    #[test]
    fn row_lines_store_only_the_jumps() {
        let mut lines = RowLines::default();
        for line in [2, 3, 4, 7, 8, 12] {
            lines.push(line);
        }
        assert_eq!(lines.jumps, vec![(0, 2), (3, 7), (5, 12)]);
        let all: Vec<usize> = (0..lines.len()).map(|i| lines.line(i)).collect();
        assert_eq!(all, [2, 3, 4, 7, 8, 12]);
    }

    #[test]
    fn a_line_without_end_is_refused_at_the_line_cap() {
        let mut r = Rows::new(std::io::repeat(b'0'), "zero.csv", u64::MAX);
        let e = r.next_row().unwrap_err();
        assert_eq!(e.row, Some(1));
        assert!(e.message.contains("longer than 1048576 bytes"), "{e}");
    }

    #[test]
    fn a_file_past_the_byte_cap_is_refused() {
        let text = "t,x,phi\n".repeat(100);
        let mut r = Rows::new(text.as_bytes(), "big.csv", 500);
        r.delimiter(b',');
        let e = loop {
            match r.next_row() {
                Ok(Some(_)) => {}
                Ok(None) => panic!("read past the cap"),
                Err(e) => break e,
            }
        };
        assert_eq!(
            e.to_string(),
            "big.csv: the file holds more than the limit of 500 bytes for a record (`max_bytes`)"
        );
    }
}
