//! Rendering a figure to its three files: the drawing code runs on the SVG backend, the PNG is
//! that SVG rasterised ([`super::raster`]), and the CSV holds the columns the drawing used. Also the text styles shared by all
//! figures, so they look alike.

use std::path::{Path, PathBuf};

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::series_colour;
use super::font::{ensure_registered, FAMILY};
use super::raster::svg_to_png;
use super::series_csv::{write_csv, Column};
use super::ReportError;
use crate::writing::atomic::{ensure_dir, write_atomic};

/// The files of one figure.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FigureFiles {
    /// Vector image.
    pub svg: PathBuf,
    /// Raster image (what reports inline).
    pub png: PathBuf,
    /// Every plotted series, one column per quantity, headed with its unit.
    pub csv: PathBuf,
}

/// The STF force axis of a record in newtons (the figures take the record's own from
/// [`super::MotionLabels::force`]).
#[cfg(test)]
pub const F_LABEL: &str = "F_STF, N";
/// The time axis, as every figure labels it.
pub const T_LABEL: &str = "time t, s";
/// The band of a measured signal's envelope: light grey under the models' lines.
pub const MEASURED_GREY: RGBColor = RGBColor(170, 170, 170);
/// A measured signal drawn as a line: thin and mid-grey, under the models' lines, so a fit
/// is never hidden behind the data and the data's noise stays readable.
pub const MEASURED_LINE: RGBColor = RGBColor(110, 110, 110);
/// Width of a measured signal's line, pixels (the models' lines are 2).
pub const MEASURED_WIDTH: u32 = 1;

/// Millimetres of print per pixel of a figure: 600 px print 85 mm wide (one journal column),
/// 1 200 px 170 mm (two columns). Every figure is drawn at this one scale, so its text sizes,
/// in pixels, are the same printed size in every figure; the SVG carries its physical width
/// (`width="85mm"`) and the PNG is drawn at twice the pixels ([`super::raster`]).
pub const MM_PER_PX: f64 = 85.0 / 600.0;
/// Width of a one-column figure (85 mm), pixels.
pub const ONE_COLUMN: u32 = 600;
/// Width of a two-column figure (170 mm), pixels.
pub const TWO_COLUMNS: u32 = 1200;
/// The smallest text a figure may carry, printed at [`MM_PER_PX`]: 8 pt.
pub const MIN_TEXT_PT: f64 = 8.0;

/// Width × height of a one-panel figure, pixels: one column (85 × 60 mm). Loops, error bars.
pub const SIZE: (u32, u32) = (ONE_COLUMN, 420);
/// Width × height of a wide one-panel figure, pixels: two columns (170 × 71 mm). Signals over
/// time (their cycles need the room), the frequency response (its regimes' names), errors by
/// regime (its groups' names).
pub const SIZE_WIDE: (u32, u32) = (TWO_COLUMNS, 500);
/// Width × height of the time history's four stacked panels, pixels: two columns (170 ×
/// 142 mm).
pub const SIZE_TALL: (u32, u32) = (TWO_COLUMNS, 1000);

/// The builder of a one-panel chart filling `root`: the margins and label areas every
/// full-width figure uses.
pub fn one_panel<'a, 'b, DB: DrawingBackend>(
    root: &'a DrawingArea<DB, Shift>,
) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(root);
    builder
        .margin(10)
        .margin_right(30)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA);
    builder
}

/// Height under a chart for its tick labels and the x axis's description, pixels.
pub const X_LABEL_AREA: u32 = 62;
/// Width left of a chart for its tick labels and the y axis's description, pixels.
pub const Y_LABEL_AREA: u32 = 104;

/// How many tick labels an axis `pixels` long carries: one per `spacing` pixels, 3 to 10, so
/// labels at print size never crowd.
fn tick_count(pixels: u32, spacing: u32) -> usize {
    (pixels / spacing).clamp(3, 10) as usize
}

/// The number of labels to ask plotters for on an axis over `range`, `wanted` or more: raised
/// until its round steps give three ticks at least (over 4.6–5.4, four labels step by 0.5 and
/// label only `5`; five step by 0.2).
fn at_least_three_ticks(range: std::ops::Range<f64>, wanted: usize) -> usize {
    let coord = plotters::coord::types::RangedCoordf64::from(range);
    (wanted..wanted + 10)
        .find(|&n| coord.key_points(n).len() >= 3)
        .unwrap_or(wanted)
}

/// A chart on plain `f64` axes.
pub type Chart2d<'a, DB> = ChartContext<
    'a,
    DB,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// Draw `chart`'s mesh: the axes described as `desc` (x, y) in `desc_style`, ticks labelled
/// to the digits each axis's range needs ([`tick_label`]), `labels` ticks (x, y) if given
/// (else plotters' default), and no light grid lines.
pub fn draw_mesh<DB: DrawingBackend>(
    chart: &mut Chart2d<'_, DB>,
    desc: (impl Into<String>, impl Into<String>),
    labels: Option<(usize, usize)>,
    desc_style: TextStyle,
) -> Result<(), String> {
    let desc = (Some(desc.0.into()), desc.1.into());
    draw_mesh_with(chart, desc, labels, desc_style)
}

/// [`draw_mesh`], the x axis described only if `desc.0` is given.
pub fn draw_mesh_with<DB: DrawingBackend>(
    chart: &mut Chart2d<'_, DB>,
    desc: (Option<String>, String),
    labels: Option<(usize, usize)>,
    desc_style: TextStyle,
) -> Result<(), String> {
    let (x, y) = (chart.x_range(), chart.y_range());
    let (xs, ys) = (x.end - x.start, y.end - y.start);
    let (w, h) = chart.plotting_area().dim_in_pixel();
    let labels = labels.unwrap_or((tick_count(w, 120), tick_count(h, 60)));
    let labels = (
        at_least_three_ticks(x.clone(), labels.0),
        at_least_three_ticks(y.clone(), labels.1),
    );
    let x_ticks = |v: &f64| tick_label(*v, xs);
    let y_ticks = |v: &f64| tick_label(*v, ys);
    let mut mesh = chart.configure_mesh();
    if let Some(x_desc) = desc.0 {
        mesh.x_desc(x_desc);
    }
    mesh.y_desc(desc.1)
        .x_label_formatter(&x_ticks)
        .y_label_formatter(&y_ticks)
        .axis_desc_style(desc_style)
        .label_style(tick_style())
        .light_line_style(WHITE.mix(0.0))
        .x_labels(labels.0)
        .y_labels(labels.1);
    mesh.draw().map_err(msg)
}

// Text sizes as plotters takes them: its SVG writes `font-size` = size / 1.24, so 26 is 21 px,
// 8.4 pt at [`MM_PER_PX`]; 25 would be the least for 8 pt.

/// Title text style (9.7 pt printed).
pub fn title_style() -> TextStyle<'static> {
    TextStyle::from((FAMILY, 30).into_font())
}
/// Axis description (quantity and unit) style (8.7 pt printed).
pub fn axis_desc_style() -> TextStyle<'static> {
    TextStyle::from((FAMILY, 27).into_font())
}
/// Tick label style (8.4 pt printed).
pub fn tick_style() -> TextStyle<'static> {
    TextStyle::from((FAMILY, 26).into_font())
}
/// Legend text style (8.4 pt printed).
pub fn legend_style() -> TextStyle<'static> {
    TextStyle::from((FAMILY, 26).into_font())
}

/// Draw `chart`'s legend at `position` in the house style (legend text, a white box with a
/// black border).
pub fn draw_legend<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    position: SeriesLabelPosition,
) -> Result<(), String>
where
    DB: DrawingBackend + 'a,
    CT: plotters::coord::CoordTranslate,
{
    chart
        .configure_series_labels()
        .position(position)
        .label_font(legend_style())
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(msg)
}

/// The mark beside a legend strip's label.
#[derive(Clone, Copy, Debug)]
pub enum Swatch {
    /// A short line of a colour and width, pixels.
    Line(RGBColor, u32),
    /// A filled dot of a colour.
    Dot(RGBColor),
    /// A black ring.
    Ring,
}

/// Height of one row of a legend strip, pixels.
const STRIP_ROW: i32 = 34;

/// Draw a legend across the top of `area`, its entries left to right, centred, in as many
/// rows as the width needs, and return the area below it: for figures whose legend would
/// cover their data (every line spans the whole time axis) or whose panels share one.
pub fn legend_strip<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, Swatch)],
) -> Result<DrawingArea<DB, Shift>, String> {
    const MARK: i32 = 24;
    const GAP: i32 = 28;
    let style = legend_style();
    let widths: Vec<i32> = entries
        .iter()
        .map(|(label, _)| {
            area.estimate_text_size(label, &style)
                .map(|(w, _)| MARK + 6 + w as i32)
        })
        .collect::<Result<_, _>>()
        .map_err(msg)?;
    let width = area.dim_in_pixel().0 as i32 - 40;
    let mut rows: Vec<Vec<usize>> = vec![Vec::new()];
    let mut used = 0;
    for (i, w) in widths.iter().enumerate() {
        let row = rows.last_mut().expect("one row at least");
        if !row.is_empty() && used + GAP + w > width {
            rows.push(vec![i]);
            used = *w;
        } else {
            used += if row.is_empty() { *w } else { GAP + w };
            row.push(i);
        }
    }
    let height = STRIP_ROW * rows.len() as i32 + 4;
    let (strip, rest) = area.split_vertically(height);
    let text = style.pos(plotters::style::text_anchor::Pos::new(
        plotters::style::text_anchor::HPos::Left,
        plotters::style::text_anchor::VPos::Center,
    ));
    for (r, row) in rows.iter().enumerate() {
        let total: i32 = row.iter().map(|&i| widths[i]).sum::<i32>() + GAP * (row.len() as i32 - 1);
        let mut x = ((strip.dim_in_pixel().0 as i32 - total) / 2).max(0);
        let y = STRIP_ROW * r as i32 + STRIP_ROW / 2 + 2;
        for &i in row {
            let (label, swatch) = &entries[i];
            match *swatch {
                Swatch::Line(colour, w) => strip.draw(&PathElement::new(
                    vec![(x, y), (x + MARK, y)],
                    colour.stroke_width(w),
                )),
                Swatch::Dot(colour) => {
                    strip.draw(&Circle::new((x + MARK / 2, y), 4, colour.filled()))
                }
                Swatch::Ring => {
                    strip.draw(&Circle::new((x + MARK / 2, y), 4, BLACK.stroke_width(2)))
                }
            }
            .map_err(msg)?;
            strip
                .draw(&Text::new(label.clone(), (x + MARK + 6, y), text.clone()))
                .map_err(msg)?;
            x += widths[i] + GAP;
        }
    }
    Ok(rest)
}

/// Turn any plotting error into its message.
pub fn msg<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// `root` under the figure's `title`, in the title style, broken at spaces into as many
/// centred lines as the width needs (a title is never clipped): the area below it.
pub fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<DrawingArea<DB, Shift>, String> {
    let style = title_style();
    let width = root.dim_in_pixel().0.saturating_sub(20);
    let fits = |line: &str| {
        root.estimate_text_size(line, &style)
            .map(|(w, _)| w <= width)
            .map_err(msg)
    };
    let mut lines: Vec<String> = Vec::new();
    for word in title.split(' ') {
        match lines.last_mut() {
            Some(line) if fits(&format!("{line} {word}"))? => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    let line_height = root.estimate_text_size("Ag", &style).map_err(msg)?.1 as i32 + 6;
    let (strip, rest) = root.split_vertically(line_height * lines.len() as i32 + 10);
    let centre = strip.dim_in_pixel().0 as i32 / 2;
    let text = style.pos(plotters::style::text_anchor::Pos::new(
        plotters::style::text_anchor::HPos::Center,
        plotters::style::text_anchor::VPos::Top,
    ));
    for (i, line) in lines.into_iter().enumerate() {
        let at = (centre, 6 + line_height * i as i32);
        strip
            .draw(&Text::new(line, at, text.clone()))
            .map_err(msg)?;
    }
    Ok(rest)
}

/// The builder of one small panel of a grid of panels, `caption` above it if given.
pub fn small_panel<'a, 'b, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: Option<&str>,
) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(area);
    builder
        .margin(8)
        .margin_right(22)
        .x_label_area_size(X_LABEL_AREA - 4)
        .y_label_area_size(Y_LABEL_AREA - 14);
    if let Some(c) = caption {
        builder.caption(heading_within(c, area.dim_in_pixel().0), legend_style());
    }
    builder
}

/// A panel's heading `name` as it fits `width` px: whole when it does, else without the
/// reason between its regime and its ω span (`pre-resonance: force negligible, ω 4.1–4.2
/// rad/s` → `pre-resonance, ω 4.1–4.2 rad/s`; the report's text gives the reason).
pub fn heading_within(name: &str, width: u32) -> String {
    let fits = |s: &str| {
        legend_style()
            .font
            .box_size(s)
            .map_or(true, |(w, _)| w + 16 <= width)
    };
    if fits(name) {
        return name.to_string();
    }
    match (name.find(": "), name.rfind(", ω")) {
        (Some(a), Some(b)) if a < b => format!("{}{}", &name[..a], &name[b..]),
        _ => name.to_string(),
    }
}

/// Draw a line through `points` on `chart` in `style`.
pub fn draw_line<DB: DrawingBackend>(
    chart: &mut Chart2d<'_, DB>,
    points: impl IntoIterator<Item = (f64, f64)>,
    style: ShapeStyle,
) -> Result<(), String> {
    chart
        .draw_series(LineSeries::new(points, style))
        .map_err(msg)?;
    Ok(())
}

/// The runs of consecutive samples whose x and y are both finite: a line is drawn through
/// each run apart, so it never bridges a gap (a non-finite sample) with a chord.
pub fn finite_runs(x: &[f64], y: &[f64]) -> Vec<Vec<(f64, f64)>> {
    let mut runs = vec![Vec::new()];
    for (a, b) in x.iter().zip(y) {
        if a.is_finite() && b.is_finite() {
            runs.last_mut().expect("one run at least").push((*a, *b));
        } else if runs.last().is_some_and(|r| !r.is_empty()) {
            runs.push(Vec::new());
        }
    }
    runs.retain(|r| !r.is_empty());
    runs
}

/// Draw `y` against `x` on `chart` in `style`, broken where either is not finite.
pub fn draw_runs<DB: DrawingBackend>(
    chart: &mut Chart2d<'_, DB>,
    (x, y): (&[f64], &[f64]),
    style: ShapeStyle,
) -> Result<(), String> {
    for run in finite_runs(x, y) {
        draw_line(chart, run, style)?;
    }
    Ok(())
}

/// The legend entries of model lines: each label, with `suffix`, in its series colour.
pub fn model_entries<'a>(
    labels: impl IntoIterator<Item = &'a str>,
    suffix: &str,
) -> Vec<(String, Swatch)> {
    let entry = |(i, label)| {
        (
            format!("{label}{suffix}"),
            Swatch::Line(series_colour(i), 3),
        )
    };
    labels.into_iter().enumerate().map(entry).collect()
}

/// For each of `series`, the first earlier one it draws over (every value within a thousandth
/// of their common range of the other's): a curve drawn exactly over another hides it, and the
/// legend must say so.
pub fn same_as_earlier(series: &[&[f64]]) -> Vec<Option<usize>> {
    let range = super::plot_range::finite_bounds(
        &series
            .iter()
            .flat_map(|s| s.iter().copied())
            .collect::<Vec<f64>>(),
    )
    .map_or(0.0, |(lo, hi)| hi - lo);
    let close = |a: &[f64], b: &[f64]| {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(x, y)| (x.is_nan() && y.is_nan()) || (x - y).abs() <= 1e-3 * range)
    };
    (0..series.len())
        .map(|i| (0..i).find(|&j| close(series[i], series[j])))
        .collect()
}

/// [`model_entries`] with each label whose curve lies on an earlier one's (`same`, from
/// [`same_as_earlier`]) flagged `(= earlier, drawn over it)`: the later curve is drawn on top.
pub fn model_entries_flagged(
    labels: &[&str],
    same: &[Option<usize>],
    suffix: &str,
) -> Vec<(String, Swatch)> {
    let mut entries = model_entries(labels.iter().copied(), suffix);
    for (entry, same) in entries.iter_mut().zip(same) {
        if let Some(j) = same {
            entry.0 = format!("{} (= {}, drawn over it)", entry.0, labels[*j]);
        }
    }
    entries
}

/// A figure that can draw itself on any plotters backend.
pub trait Draw {
    /// Draw on `root` (already filled white).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String>;
}

fn draw_on<DB: DrawingBackend>(backend: DB, plot: &impl Draw) -> Result<(), String> {
    let root = backend.into_drawing_area();
    root.fill(&WHITE).map_err(msg)?;
    plot.draw(&root)?;
    root.present().map_err(msg)
}

/// Write `out_dir/name.{svg,png,csv}`: the SVG and PNG drawn by `plot` at `size`, the CSV
/// from `columns`. Each file is written atomically.
pub fn render(
    out_dir: &Path,
    name: &str,
    size: (u32, u32),
    plot: &impl Draw,
    columns: &[Column],
) -> Result<FigureFiles, ReportError> {
    ensure_registered()?;
    ensure_dir(out_dir)?;
    let files = FigureFiles {
        svg: out_dir.join(format!("{name}.svg")),
        png: out_dir.join(format!("{name}.png")),
        csv: out_dir.join(format!("{name}.csv")),
    };

    let failed = |path: &PathBuf| {
        let path = path.clone();
        move |message| ReportError::Plot { path, message }
    };
    let mut svg = String::new();
    draw_on(SVGBackend::with_string(&mut svg, size), plot).map_err(failed(&files.svg))?;
    let svg = with_print_size(&svg, size);
    write_atomic(&files.svg, svg.as_bytes())?;

    let png = svg_to_png(&svg).map_err(failed(&files.png))?;
    write_atomic(&files.png, &png)?;

    write_csv(&files.csv, columns)?;
    Ok(files)
}

/// `svg` (as plotters writes it: `width="W" height="H" viewBox="0 0 W H"`) with its width and
/// height in millimetres at [`MM_PER_PX`], so it prints at its column's width; the drawing's
/// own units (the viewBox) stay pixels.
fn with_print_size(svg: &str, (w, h): (u32, u32)) -> String {
    let mm = |px: u32| format!("{}mm", tick_label(f64::from(px) * MM_PER_PX, 1.0));
    svg.replacen(
        &format!("width=\"{w}\" height=\"{h}\""),
        &format!("width=\"{}\" height=\"{}\"", mm(w), mm(h)),
        1,
    )
}

/// Check that two series have the same length.
pub fn same_length(what: &str, a: &[f64], b: &[f64]) -> Result<(), ReportError> {
    if a.len() == b.len() {
        return Ok(());
    }
    Err(ReportError::LengthMismatch {
        what: what.to_string(),
        left: a.len(),
        right: b.len(),
    })
}

/// Refuse a figure (`figure`, as its errors name it) when one of `series` (`(what, values)`)
/// has no finite value.
pub fn require_finite(figure: &str, series: &[(&str, &[f64])]) -> Result<(), ReportError> {
    match series
        .iter()
        .find(|(_, s)| !s.iter().any(|v| v.is_finite()))
    {
        Some((what, _)) => Err(ReportError::no_data(format!("{figure}: {what}"))),
        None => Ok(()),
    }
}

/// Metres (per second) in millimetres (per second), the unit the rig's motion is read in.
pub fn milli(values: &[f64]) -> Vec<f64> {
    values.iter().map(|v| v * 1e3).collect()
}

/// The finite (x, y) pairs of two series, for drawing.
pub fn finite_points(x: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    x.iter()
        .zip(y)
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .map(|(a, b)| (*a, *b))
        .collect()
}

/// A tick label for `v` on an axis spanning `span`: as many decimals as ticks 1/200 of
/// the span apart need, trailing zeros dropped, and never `-0` (a tick at zero computed as
/// −1e-17 read "-0.0").
pub fn tick_label(v: f64, span: f64) -> String {
    let step = (span.abs() / 200.0).max(f64::MIN_POSITIVE);
    let decimals = (-step.log10().floor()).clamp(0.0, 12.0) as usize;
    let mut s = format!("{v:.decimals$}");
    if s.contains('.') {
        s = s.trim_end_matches('0').trim_end_matches('.').to_string();
    }
    if s == "-0" {
        s = "0".into();
    }
    s
}

#[cfg(test)]
mod tests {
    use super::{ensure_registered, finite_runs, heading_within, tick_label};

    #[test]
    fn a_heading_too_wide_for_its_panel_drops_its_reason_not_its_span() {
        ensure_registered().unwrap();
        let name = "pre-resonance: force negligible, ω 4.55–4.82 rad/s";
        assert_eq!(heading_within(name, 2_000), name);
        assert_eq!(
            heading_within(name, 500),
            "pre-resonance, ω 4.55–4.82 rad/s"
        );
        assert_eq!(heading_within("resonance", 10), "resonance");
    }

    #[test]
    fn an_axis_gets_three_ticks_at_least() {
        use plotters::prelude::Ranged;
        let ticks = |range: std::ops::Range<f64>, n| {
            plotters::coord::types::RangedCoordf64::from(range).key_points(n)
        };
        // Four labels over 4.6–5.4 step by 0.5: the one tick `5`.
        assert_eq!(ticks(4.6..5.4, 4), [5.0]);
        let n = super::at_least_three_ticks(4.6..5.4, 4);
        assert!(ticks(4.6..5.4, n).len() >= 3, "{n}");
        // An axis with enough ticks keeps its count.
        assert_eq!(super::at_least_three_ticks(0.0..10.0, 4), 4);
    }

    #[test]
    fn the_svg_carries_its_print_width_in_millimetres() {
        let svg = r#"<svg width="600" height="420" viewBox="0 0 600 420" xmlns="x">"#;
        assert_eq!(
            super::with_print_size(svg, (600, 420)),
            r#"<svg width="85mm" height="59.5mm" viewBox="0 0 600 420" xmlns="x">"#
        );
    }

    #[test]
    fn curves_on_earlier_ones_are_found() {
        let a = [0.0, 1.0, 2.0];
        let b = [0.0, 1.0005, 2.0];
        let c = [0.0, 1.5, 2.0];
        assert_eq!(
            super::same_as_earlier(&[&a, &c, &b]),
            vec![None, None, Some(0)]
        );
        let labels = ["power_law", "viscous", "power_law#2"];
        let entries = super::model_entries_flagged(&labels, &[None, None, Some(0)], "");
        assert_eq!(entries[2].0, "power_law#2 (= power_law, drawn over it)");
    }

    #[test]
    fn runs_break_at_gaps_and_drop_empty_ones() {
        let nan = f64::NAN;
        let x = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let y = [1.0, nan, nan, 2.0, 3.0, 4.0, nan];
        assert_eq!(
            finite_runs(&x, &y),
            vec![vec![(0.0, 1.0)], vec![(3.0, 2.0), (4.0, 3.0), (5.0, 4.0)]]
        );
    }

    #[test]
    fn tick_labels_have_the_digits_the_axis_needs_and_no_negative_zero() {
        assert_eq!(tick_label(-1e-17, 0.8), "0");
        assert_eq!(tick_label(-0.0, 60.0), "0");
        assert_eq!(tick_label(0.30000000000000004, 0.8), "0.3");
        assert_eq!(tick_label(0.25, 0.8), "0.25");
        assert_eq!(tick_label(-30.0, 66.0), "-30");
        assert_eq!(tick_label(12.5, 66.0), "12.5");
        assert_eq!(tick_label(150.0, 300.0), "150");
        assert_eq!(tick_label(0.0015, 0.01), "0.0015");
    }
}
