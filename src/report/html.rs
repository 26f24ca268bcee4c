//! `report.html`: one self-contained page — CSS inline, each figure's SVG inlined (vector, sharp
//! at any zoom; its PNG and SVG files stay beside the page), no script or font from the
//! network — that a reader who never ran the tool can open anywhere. A small inline script lets
//! the reader zoom the time axis of time histories (wheel), pan it (drag) and reset it
//! (double-click) by changing the figure's `viewBox` ([`ZOOM`]); another writes each figure's
//! laid-out size (and any page error) into a hidden `<pre id="layout-check">`, which lets a
//! headless browser test check the page.

use std::fmt::Write as _;
use std::path::Path;

use super::document::{FigureRef, Report, Table};
use super::ReportError;
use crate::writing::atomic::write_atomic;

const STYLE: &str = r#"
body { font-family: "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; color: #222;
       max-width: 1060px; margin: 2em auto; padding: 0 1.2em; line-height: 1.5; }
h1 { font-size: 1.9em; border-bottom: 2px solid #0072b2; padding-bottom: .2em; }
h2 { font-size: 1.4em; margin-top: 2em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 1em 0; font-size: .95em; }
caption { text-align: left; font-weight: bold; padding-bottom: .3em; }
th, td { border: 1px solid #bbb; padding: .3em .7em; }
th { background: #eef3f8; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
tbody tr:nth-child(even) { background: #f8f8f8; }
figure { margin: 1.5em 0; }
figure img, figure svg.figure { display: block; max-width: 100%; height: auto;
                               border: 1px solid #ddd; }
figure svg.zoom { cursor: grab; touch-action: none; }
figure svg.zoomed * { vector-effect: non-scaling-stroke; }
figcaption { margin-top: .4em; font-size: .95em; }
figcaption .files { color: #666; font-size: .9em; }
.warnings { border: 2px solid #d55e00; border-left-width: 8px; background: #fff4e5;
            padding: .5em 1em; margin: 1em 0; }
.warnings h3 { margin: .2em 0 .4em; font-size: 1.1em; color: #a33a00; }
.warnings ul { margin: 0; padding-left: 1.3em; }
.warnings li { margin: .25em 0; }
footer { margin-top: 3em; color: #777; font-size: .85em; border-top: 1px solid #ddd; }
"#;

const LAYOUT_CHECK: &str = r#"
(function () {
  var lines = [];
  function show() {
    var pre = document.getElementById("layout-check");
    if (pre) { pre.textContent = lines.join("\n"); }
  }
  window.addEventListener("error", function (e) { lines.push("error: " + e.message); show(); });
  window.addEventListener("load", function () {
    var figures = document.querySelectorAll("figure img, figure svg.figure");
    figures.forEach(function (el, i) {
      var r = el.getBoundingClientRect();
      var svg = el.tagName.toLowerCase() === "svg";
      var w = svg ? el.width.baseVal.value : el.naturalWidth;
      var h = svg ? el.height.baseVal.value : el.naturalHeight;
      lines.push("figure " + i + " " + el.tagName.toLowerCase() + " " + Math.round(r.width) +
        "x" + Math.round(r.height) + " natural " + Math.round(w || 0) + "x" +
        Math.round(h || 0));
    });
    lines.push("figures " + figures.length);
    show();
  });
})();
"#;

/// Zoom and pan along the time axis of every `svg.zoom`: the wheel scales the `viewBox`'s
/// width around the pointer (1× to 50×), a drag shifts it, a double-click resets it. Only the
/// horizontal extent changes (`preserveAspectRatio="none"`), so the amplitudes keep their
/// scale; each text is squeezed back to its own width about its anchor, and strokes keep
/// their width (`vector-effect`), so labels and lines stay as drawn. The time ticks move with
/// the data, as they are drawn in its coordinates.
const ZOOM: &str = r#"
(function () {
  function setup(svg) {
    var vb = svg.viewBox.baseVal;
    var full = { x: vb.x, y: vb.y, w: vb.width, h: vb.height };
    svg.setAttribute("preserveAspectRatio", "none");
    var texts = Array.prototype.map.call(svg.querySelectorAll("text"), function (t) {
      var x = t.x.baseVal.numberOfItems ? t.x.baseVal.getItem(0).value : 0;
      return { el: t, x: x, own: t.getAttribute("transform") || "" };
    });
    function show(x, w) {
      w = Math.min(Math.max(w, full.w / 50), full.w);
      x = Math.min(Math.max(x, full.x), full.x + full.w - w);
      svg.setAttribute("viewBox", x + " " + full.y + " " + w + " " + full.h);
      var s = w / full.w;
      svg.classList.toggle("zoomed", s < 1);
      texts.forEach(function (t) {
        var squeeze = "translate(" + t.x + " 0) scale(" + s + " 1) translate(" + -t.x + " 0) ";
        t.el.setAttribute("transform", s < 1 ? squeeze + t.own : t.own);
      });
    }
    function at(clientX) {
      var r = svg.getBoundingClientRect();
      return vb.x + (clientX - r.left) / r.width * vb.width;
    }
    svg.addEventListener("wheel", function (e) {
      e.preventDefault();
      var w = Math.min(Math.max(vb.width * Math.exp(e.deltaY * 0.002), full.w / 50), full.w);
      var p = at(e.clientX);
      show(p - (p - vb.x) * w / vb.width, w);
    }, { passive: false });
    var drag = null;
    svg.addEventListener("pointerdown", function (e) {
      drag = { from: e.clientX, x: vb.x };
      try { svg.setPointerCapture(e.pointerId); } catch (err) { /* no such pointer */ }
    });
    svg.addEventListener("pointermove", function (e) {
      if (!drag) { return; }
      var r = svg.getBoundingClientRect();
      show(drag.x - (e.clientX - drag.from) / r.width * vb.width, vb.width);
    });
    svg.addEventListener("pointerup", function () { drag = null; });
    svg.addEventListener("dblclick", function () { show(full.x, full.w); });
  }
  window.addEventListener("DOMContentLoaded", function () {
    document.querySelectorAll("svg.zoom").forEach(setup);
  });
})();
"#;

/// Escape text for HTML content and attribute values.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&#39;")
}

/// A paragraph's text as HTML: escaped, with `code` spans (backticks, as in the Markdown
/// report) set in `<code>`; an unpaired backtick stays as it is.
pub fn inline(text: &str) -> String {
    let parts: Vec<&str> = text.split('`').collect();
    if parts.len() % 2 == 0 {
        return escape(text);
    }
    parts
        .iter()
        .enumerate()
        .map(|(i, part)| {
            if i % 2 == 1 {
                format!("<code>{}</code>", escape(part))
            } else {
                escape(part)
            }
        })
        .collect()
}

fn looks_numeric(cell: &str) -> bool {
    let first = cell.split_whitespace().next();
    first.is_some_and(|w| w.parse::<f64>().is_ok())
}

fn table_html(out: &mut String, table: &Table) {
    out.push_str("<table>\n");
    if !table.caption.is_empty() {
        let _ = writeln!(out, "<caption>{}</caption>", escape(&table.caption));
    }
    out.push_str("<thead><tr>");
    for c in &table.columns {
        let _ = write!(out, "<th>{}</th>", escape(c));
    }
    out.push_str("</tr></thead>\n<tbody>\n");
    for row in &table.rows {
        out.push_str("<tr>");
        for cell in table.cells(row) {
            let class = if looks_numeric(cell) {
                " class=\"num\""
            } else {
                ""
            };
            let _ = write!(out, "<td{class}>{}</td>", escape(cell));
        }
        out.push_str("</tr>\n");
    }
    out.push_str("</tbody>\n</table>\n");
}

fn warnings_html(out: &mut String, warnings: &[String]) {
    if warnings.is_empty() {
        return;
    }
    let _ = writeln!(
        out,
        "<div class=\"warnings\" role=\"alert\">\n<h3>⚠ Warnings: not to be trusted as it \
         stands</h3>\n<ul>"
    );
    for w in warnings {
        let _ = writeln!(out, "<li>{}</li>", escape(w));
    }
    out.push_str("</ul>\n</div>\n");
}

/// The value of attribute `name` in the start tag `tag`.
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let from = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    tag[from..].split('"').next()
}

/// `svg` (a figure's SVG document) as an element of the page: any XML prolog dropped, the
/// figure's class (and `zoom` when zoomable), its caption as the accessible name and its
/// drawn proportions (which a zoom, changing the `viewBox`, must not change) added.
fn inline_svg(svg: &str, caption: &str, zoom: bool) -> Option<String> {
    let at = svg.find("<svg")?;
    let rest = &svg[at + 4..];
    let tag = &rest[..rest.find('>')?];
    // The drawing's size in its own units (the viewBox; the width and height state the
    // print size in mm): shown at that many CSS px, at most the page's width.
    let drawn = attribute(tag, "viewBox")
        .and_then(|b| {
            let v: Vec<f64> = b
                .split_whitespace()
                .filter_map(|n| n.parse().ok())
                .collect();
            (v.len() == 4).then(|| (v[2], v[3]))
        })
        .or_else(|| {
            Some((
                attribute(tag, "width")?.parse().ok()?,
                attribute(tag, "height")?.parse().ok()?,
            ))
        });
    let ratio = match drawn {
        Some((w, h)) if w > 0.0 && h > 0.0 => {
            format!(" style=\"width: {w}px; aspect-ratio: {w} / {h}\"")
        }
        _ => String::new(),
    };
    // An SVG in an HTML page needs no namespace declaration (the page names no address).
    let rest = rest.replacen(" xmlns=\"http://www.w3.org/2000/svg\"", "", 1);
    let class = if zoom { "figure zoom" } else { "figure" };
    Some(format!(
        "<svg class=\"{class}\" role=\"img\" aria-label=\"{}\"{ratio}{rest}",
        escape(caption),
    ))
}

fn file_name(path: &Path) -> String {
    escape(&path.file_name().unwrap_or_default().to_string_lossy())
}

fn figure_html(out: &mut String, number: usize, figure: &FigureRef) -> Result<(), ReportError> {
    let path = &figure.files.svg;
    let svg = std::fs::read_to_string(path).map_err(|source| ReportError::Read {
        path: path.clone(),
        source,
    })?;
    let element =
        inline_svg(&svg, &figure.caption, figure.zoom).ok_or_else(|| ReportError::Read {
            path: path.clone(),
            source: std::io::Error::new(std::io::ErrorKind::InvalidData, "no <svg> element"),
        })?;
    let _ = writeln!(
        out,
        "<figure id=\"figure-{number}\">\n{}",
        element.trim_end()
    );
    let how = if figure.zoom {
        " Wheel over it zooms the time axis, drag pans, double-click resets."
    } else {
        ""
    };
    let _ = writeln!(
        out,
        "<figcaption><b>Figure {number}.</b> {}{how} <span class=\"files\">Files beside this \
         page: {}, {} (raster), {} (the plotted data).</span></figcaption>\n</figure>",
        escape(&figure.caption),
        file_name(&figure.files.svg),
        file_name(&figure.files.png),
        file_name(&figure.files.csv),
    );
    Ok(())
}

/// The HTML text of `report`, with every figure's SVG read and inlined.
pub fn to_html(report: &Report) -> Result<String, ReportError> {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{STYLE}</style>\n<script>{LAYOUT_CHECK}</script>\n\
         <script>{ZOOM}</script>\n</head>\n<body>",
        escape(&report.title)
    );
    let _ = writeln!(out, "<h1>{}</h1>", escape(&report.title));
    for p in &report.intro {
        let _ = writeln!(out, "<p>{}</p>", inline(p));
    }
    let mut number = 0;
    for section in &report.sections {
        let _ = writeln!(out, "<section>\n<h2>{}</h2>", escape(&section.heading));
        for p in &section.paragraphs {
            let _ = writeln!(out, "<p>{}</p>", inline(p));
        }
        warnings_html(&mut out, &section.warnings);
        for table in &section.tables {
            table_html(&mut out, table);
        }
        for figure in &section.figures {
            number += 1;
            figure_html(&mut out, number, figure)?;
        }
        out.push_str("</section>\n");
    }
    let _ = writeln!(
        out,
        "<footer>Written by stf-lab {}. Figures are inlined as vector graphics; their SVG, \
         PNG and CSV files sit beside this page.</footer>\n<pre id=\"layout-check\" hidden></pre>\n</body>\n</html>",
        env!("CARGO_PKG_VERSION")
    );
    Ok(out)
}

/// Write `report` as one self-contained HTML page at `path` (atomically).
pub fn write_html(report: &Report, path: &Path) -> Result<(), ReportError> {
    let html = to_html(report)?;
    if let Some(dir) = path.parent() {
        crate::writing::atomic::ensure_dir(dir)?;
    }
    Ok(write_atomic(path, html.as_bytes())?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::Section;

    #[test]
    fn backticks_become_code_and_the_rest_is_escaped() {
        assert_eq!(inline("a `b<c` d"), "a <code>b&lt;c</code> d");
        assert_eq!(inline("odd ` tick"), "odd ` tick");
    }

    #[test]
    fn escapes_markup_and_right_aligns_numbers() {
        let mut report = Report::new("A <b> & \"c\"");
        let mut s = Section::new("Fit");
        s.tables.push(Table {
            caption: "Parameters".into(),
            columns: vec!["name".into(), "value".into()],
            rows: vec![vec!["K".into(), "1.5e3 N".into()], vec!["<n>".into()]],
        });
        report.sections.push(s);
        let html = to_html(&report).unwrap();
        assert!(html.contains("<h1>A &lt;b&gt; &amp; &quot;c&quot;</h1>"));
        assert!(html.contains("<td class=\"num\">1.5e3 N</td>"));
        assert!(html.contains("<td>&lt;n&gt;</td><td></td>"));
        assert!(!html.contains("http"), "no network reference");
        assert!(!html.contains("class=\"warnings\""), "no warnings, no box");
    }

    #[test]
    fn warnings_stand_in_a_box_above_the_tables() {
        let mut report = Report::new("r");
        let mut s = Section::new("Fits");
        s.warnings
            .push("viscous: the residual is 4.1× the noise floor <sic>".into());
        s.tables.push(Table::default());
        report.sections.push(s);
        let html = to_html(&report).unwrap();
        let b = html.find("<div class=\"warnings\"").unwrap();
        assert!(b < html.find("<table>").unwrap());
        assert!(html.contains("<li>viscous: the residual is 4.1× the noise floor &lt;sic&gt;</li>"));
    }

    #[test]
    fn a_missing_figure_file_is_an_error_naming_it() {
        let mut report = Report::new("r");
        let mut s = Section::new("s");
        s.figures.push(FigureRef::new(
            crate::report::FigureFiles {
                svg: "nowhere/f.svg".into(),
                png: "nowhere/f.png".into(),
                csv: "nowhere/f.csv".into(),
            },
            "c",
        ));
        report.sections.push(s);
        let err = to_html(&report).unwrap_err().to_string();
        assert!(err.contains("nowhere/f.svg"), "{err}");
    }

    #[test]
    fn a_figure_is_its_svg_inlined_with_its_class() {
        let svg = "<?xml version=\"1.0\"?>\n<svg width=\"10\" height=\"5\" \
                   xmlns=\"http://www.w3.org/2000/svg\"><line/></svg>";
        let got = inline_svg(svg, "a \"b\"", true).unwrap();
        assert_eq!(
            got,
            "<svg class=\"figure zoom\" role=\"img\" aria-label=\"a &quot;b&quot;\" \
             style=\"width: 10px; aspect-ratio: 10 / 5\" width=\"10\" height=\"5\"><line/></svg>"
        );
        // A figure sized for print: shown at its drawing's size, not at its 85 mm.
        let svg = "<svg width=\"85mm\" height=\"59.5mm\" viewBox=\"0 0 600 420\"><line/></svg>";
        let got = inline_svg(svg, "p", false).unwrap();
        assert!(
            got.contains("style=\"width: 600px; aspect-ratio: 600 / 420\""),
            "{got}"
        );
        assert!(inline_svg("<png/>", "c", false).is_none());
    }
}
