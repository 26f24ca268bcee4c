//! `report.md`: the same report for a terminal or a lab notebook — headings, pipe tables, and
//! figures linked by their path relative to the Markdown file. Markdown viewers render HTML
//! found in the text, and the text quotes file names, column names and model names: `<`, `>`
//! and `&` are written as entities outside code spans, as `report.html` escapes them.

use std::fmt::Write as _;
use std::path::{Component, Path, PathBuf};

use super::document::{Report, Table};
use super::ReportError;
use crate::writing::atomic::{ensure_dir, write_atomic};

/// Text for the Markdown report: HTML's `&`, `<`, `>` as entities, except inside backtick
/// code spans (shown literally there); an unpaired backtick leaves the whole text escaped.
pub fn md_text(text: &str) -> String {
    let parts: Vec<&str> = text.split('`').collect();
    let paired = parts.len() % 2 == 1;
    parts
        .iter()
        .enumerate()
        .map(|(i, part)| {
            if paired && i % 2 == 1 {
                part.to_string()
            } else {
                part.replace('&', "&amp;")
                    .replace('<', "&lt;")
                    .replace('>', "&gt;")
            }
        })
        .collect::<Vec<_>>()
        .join("`")
}

fn cell(text: &str) -> String {
    md_text(text).replace('|', "\\|").replace(['\n', '\r'], " ")
}

fn table_md(out: &mut String, table: &Table) {
    if !table.caption.is_empty() {
        let _ = writeln!(out, "**{}**\n", md_text(&table.caption));
    }
    for (i, row) in std::iter::once(&table.columns)
        .chain(&table.rows)
        .enumerate()
    {
        let cells: Vec<String> = table.cells(row).map(cell).collect();
        let _ = writeln!(out, "| {} |", cells.join(" | "));
        if i == 0 {
            let _ = writeln!(out, "|{}", " --- |".repeat(table.width()));
        }
    }
    out.push('\n');
}

/// `target` relative to folder `base` (both made absolute first), with `/` separators.
pub fn relative_link(target: &Path, base: &Path) -> String {
    let absolute =
        |p: &Path| -> PathBuf { std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf()) };
    let (t, b) = (absolute(target), absolute(base));
    let tc: Vec<Component> = t.components().collect();
    let bc: Vec<Component> = b.components().collect();
    let common = tc.iter().zip(&bc).take_while(|(a, b)| a == b).count();
    let mut parts: Vec<String> = vec!["..".to_string(); bc.len() - common];
    parts.extend(
        tc[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    parts.join("/")
}

/// The Markdown text of `report`, figure links relative to folder `base`.
pub fn to_markdown(report: &Report, base: &Path) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# {}\n", md_text(&report.title));
    for p in &report.intro {
        let _ = writeln!(out, "{}\n", md_text(p));
    }
    let mut number = 0;
    for section in &report.sections {
        let _ = writeln!(out, "## {}\n", md_text(&section.heading));
        for p in &section.paragraphs {
            let _ = writeln!(out, "{}\n", md_text(p));
        }
        if !section.warnings.is_empty() {
            let _ = writeln!(out, "> **⚠ Warnings: not to be trusted as it stands**\n>");
            for w in &section.warnings {
                let _ = writeln!(out, "> - {}", md_text(w).replace(['\n', '\r'], " "));
            }
            out.push('\n');
        }
        for table in &section.tables {
            table_md(&mut out, table);
        }
        for figure in &section.figures {
            number += 1;
            let f = &figure.files;
            let [png, svg, csv] = [&f.png, &f.svg, &f.csv].map(|p| relative_link(p, base));
            let _ = writeln!(
                out,
                "![Figure {number}: {}]({png})\n\n*Figure {number}.* {} (vector: [{svg}]({svg}), data: [{csv}]({csv}))\n",
                cell(&figure.caption),
                md_text(&figure.caption),
            );
        }
    }
    out
}

/// Write `report` as Markdown at `path` (atomically), figures linked relative to it.
pub fn write_markdown(report: &Report, path: &Path) -> Result<(), ReportError> {
    let dir = path.parent().unwrap_or(Path::new(""));
    ensure_dir(dir)?;
    Ok(write_atomic(path, to_markdown(report, dir).as_bytes())?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::{FigureFiles, FigureRef, Section};

    #[test]
    fn html_from_names_is_escaped_outside_code_spans() {
        assert_eq!(
            md_text("Fit: <script>alert(1)</script>.toml & `a<b`"),
            "Fit: &lt;script&gt;alert(1)&lt;/script&gt;.toml &amp; `a<b`"
        );
        assert_eq!(md_text("odd ` <b>"), "odd ` &lt;b&gt;");
        let mut report = Report::new("Fit: <img src=x onerror=alert(1)>.toml");
        let mut s = Section::new("Fits");
        s.tables.push(Table {
            caption: "<b>".into(),
            columns: vec!["<i>".into()],
            rows: vec![vec!["<u>|".into()]],
        });
        report.sections.push(s);
        let md = to_markdown(&report, Path::new("/out"));
        assert!(!md.contains('<'), "{md}");
        assert!(md.contains("| &lt;u&gt;\\| |"), "{md}");
    }

    #[test]
    fn links_are_relative_to_the_markdown_file() {
        assert_eq!(
            relative_link(Path::new("/out/figures/a.png"), Path::new("/out")),
            "figures/a.png"
        );
        assert_eq!(
            relative_link(Path::new("/data/a.png"), Path::new("/out/run")),
            "../../data/a.png"
        );
    }

    #[test]
    fn writes_headings_tables_and_figure_links() {
        let dir = tempfile::tempdir().unwrap();
        let mut report = Report::new("Fit");
        report.intro.push("Intro.".into());
        let mut s = Section::new("Parameters");
        s.tables.push(Table {
            caption: String::new(),
            columns: vec!["name".into(), "value, N".into()],
            rows: vec![vec!["a|b".into(), "1".into()]],
        });
        s.figures.push(FigureRef::new(
            FigureFiles {
                svg: dir.path().join("fig/h.svg"),
                png: dir.path().join("fig/h.png"),
                csv: dir.path().join("fig/h.csv"),
            },
            "A loop.",
        ));
        report.sections.push(s);
        let path = dir.path().join("report.md");
        write_markdown(&report, &path).unwrap();
        let md = std::fs::read_to_string(&path).unwrap();
        assert!(md.starts_with("# Fit\n\nIntro.\n\n## Parameters\n"), "{md}");
        assert!(
            md.contains("| name | value, N |\n| --- | --- |\n| a\\|b | 1 |"),
            "{md}"
        );
        assert!(md.contains("![Figure 1: A loop.](fig/h.png)"), "{md}");
        assert!(md.contains("[fig/h.csv](fig/h.csv)"), "{md}");
    }
}
