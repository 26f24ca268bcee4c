//! The content of a report, independent of its format: a title, an introduction, and sections
//! of paragraphs, tables and figures. [`write_html`](super::write_html) and
//! [`write_markdown`](super::write_markdown) render it.

use super::FigureFiles;

/// A report: what was done, the numbers, the figures.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Report {
    /// Page title.
    pub title: String,
    /// Paragraphs before the first section (plain text).
    pub intro: Vec<String>,
    /// The sections, in order.
    pub sections: Vec<Section>,
}

impl Report {
    /// An empty report with a title.
    pub fn new(title: impl Into<String>) -> Self {
        Self {
            title: title.into(),
            ..Self::default()
        }
    }
}

/// A section: heading, then paragraphs, warnings, tables and figures in that order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Section {
    /// Heading.
    pub heading: String,
    /// Paragraphs (plain text).
    pub paragraphs: Vec<String>,
    /// Warnings (plain text, one sentence each), shown prominently just above the tables.
    pub warnings: Vec<String>,
    /// Tables.
    pub tables: Vec<Table>,
    /// Figures.
    pub figures: Vec<FigureRef>,
}

impl Section {
    /// An empty section with a heading.
    pub fn new(heading: impl Into<String>) -> Self {
        Self {
            heading: heading.into(),
            ..Self::default()
        }
    }
}

/// A table of text cells (format numbers before: the report does not).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    /// Caption above the table (may be empty).
    pub caption: String,
    /// Column headers, with units.
    pub columns: Vec<String>,
    /// Rows; a short row is padded with empty cells.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with its caption and column headers.
    pub fn new(caption: impl Into<String>, columns: &[&str]) -> Self {
        Table {
            caption: caption.into(),
            columns: columns.iter().map(|c| c.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// The number of columns: the header's or the longest row's, whichever is wider.
    pub fn width(&self) -> usize {
        let rows = self.rows.iter().map(Vec::len);
        rows.chain([self.columns.len()]).max().unwrap_or(0)
    }

    /// The cells of `row` (or of the header), padded with empty cells to [`Table::width`].
    pub fn cells<'a>(&self, row: &'a [String]) -> impl Iterator<Item = &'a str> {
        (0..self.width()).map(move |i| row.get(i).map_or("", String::as_str))
    }

    /// The same table with `rows`.
    pub fn with_rows(mut self, rows: Vec<Vec<String>>) -> Self {
        self.rows = rows;
        self
    }
}

/// A figure in a report: its files and a caption saying what it shows.
#[derive(Clone, Debug, PartialEq)]
pub struct FigureRef {
    /// The files written by a figure function.
    pub files: FigureFiles,
    /// What the figure shows, for a reader who never ran the tool.
    pub caption: String,
    /// A time history the page lets the reader zoom (wheel) and pan (drag) along its time
    /// axis.
    pub zoom: bool,
}

impl FigureRef {
    /// A figure with a caption.
    pub fn new(files: FigureFiles, caption: impl Into<String>) -> Self {
        Self {
            files,
            caption: caption.into(),
            zoom: false,
        }
    }

    /// The same figure, zoomable and pannable along its time axis in the HTML page.
    pub fn zoomable(mut self) -> Self {
        self.zoom = true;
        self
    }
}
