//! A few cycles of each regime side by side, as the source study shows them: one column per
//! window (pre-resonance, resonance, post-resonance), the STF force over time on top and the
//! hysteresis loops F–x, F–v, F–a under it, each fitted model's force drawn over the measured
//! one (a thin grey line under them). A long record squeezed into one plot is a solid band; a window of
//! a few cycles shows the loops' shapes.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::series_colour;
use super::decimate::{decimate_ranges, pick};
use super::figure::{
    draw_mesh, draw_runs, legend_strip, model_entries_flagged, msg, render, same_as_earlier,
    same_length, small_panel, tick_style, titled, Draw, FigureFiles, Swatch, MEASURED_LINE,
    MEASURED_WIDTH, ONE_COLUMN, TWO_COLUMNS,
};
use super::motion_labels::MotionLabels;
use super::plot_range::{exact_range, padded_range};
use super::series_csv::Column;
use super::ReportError;

/// A window of the record: a name (the regime) and its samples `start..end`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RegimeWindow {
    /// What the window shows, e.g. `resonance, ω 6.1–6.4 rad/s`.
    pub name: String,
    /// First sample.
    pub start: usize,
    /// One past the last sample.
    pub end: usize,
}

/// The series the windows are cut from, all of one length: motion in the units people read
/// (x in mm, v in mm/s, a in m/s²; mV, mV/s and V/s² for x in volts: `labels`), the measured
/// STF force and each model's (N).
#[derive(Clone, Copy, Debug)]
pub struct WindowSeries<'a> {
    /// Time, s.
    pub t: &'a [f64],
    /// Displacement, mm.
    pub x_mm: &'a [f64],
    /// Velocity, mm/s.
    pub v_mm: &'a [f64],
    /// Acceleration, m/s².
    pub a: &'a [f64],
    /// Measured STF force, N.
    pub f: &'a [f64],
    /// Each model's fitted force, N: `(label, force)`.
    pub models: &'a [(&'a str, &'a [f64])],
    /// The axis labels and CSV columns of x, v and a, in the record's units.
    pub labels: MotionLabels,
    /// The figure's title, in words that fit the rig (a rotor's regimes, or thirds of a record).
    pub title: &'a str,
}

/// The most samples a window keeps (its series decimated together, every extreme kept).
pub const MAX_POINTS_PER_WINDOW: usize = 4_000;

/// Height of one row of a window figure's panels, pixels (plus [`WINDOW_GRID_MARGIN`]).
const WINDOW_ROW_HEIGHT: u32 = 300;
/// Height of a window figure's title and legend, pixels.
const WINDOW_GRID_MARGIN: u32 = 100;

/// The windows a figure draws, cut from a record's series by [`cut_windows`].
pub(super) struct WindowCut {
    /// Each window of at least two samples within the record, with the samples it draws
    /// (increasing indices into the series).
    pub windows: Vec<(RegimeWindow, Vec<usize>)>,
    /// Every window's samples drawn, window after window: the CSV's rows.
    rows: Vec<usize>,
    /// The CSV's columns: the window's number, the time, s, and those pushed
    /// ([`WindowCut::push_column`]).
    pub columns: Vec<Column>,
    /// The figure's width × height, pixels: a column wide for one window, two for more, a
    /// row of panels [`WINDOW_ROW_HEIGHT`] high.
    pub size: (u32, u32),
}

impl WindowCut {
    /// Add the CSV column `name` of `series`' samples drawn.
    pub fn push_column(&mut self, name: impl Into<String>, series: &[f64]) {
        self.columns
            .push(Column::new(name, pick(series, &self.rows)));
    }
}

/// Cut `windows` from the `series` (each named, for the error when its length is not that of
/// `t`) for a `figure` of `panel_rows` rows of panels: the windows of at least two samples
/// within the record, the series decimated together within each (every extreme kept). No
/// such window is an error.
pub(super) fn cut_windows(
    figure: &str,
    t: &[f64],
    series: &[(String, &[f64])],
    windows: &[RegimeWindow],
    panel_rows: usize,
) -> Result<WindowCut, ReportError> {
    for (what, v) in series {
        same_length(&format!("{figure}: t and {what}"), t, v)?;
    }
    let windows: Vec<RegimeWindow> = windows
        .iter()
        .filter(|w| w.start + 2 <= w.end && w.end <= t.len())
        .cloned()
        .collect();
    if windows.is_empty() {
        return Err(ReportError::no_data(format!(
            "{figure}: no window of at least two samples"
        )));
    }
    let all: Vec<&[f64]> = series.iter().map(|(_, v)| *v).collect();
    let ranges: Vec<_> = windows.iter().map(|w| w.start..w.end).collect();
    let kept = decimate_ranges(&all, &ranges, MAX_POINTS_PER_WINDOW * windows.len());
    let rows: Vec<usize> = kept.iter().flatten().copied().collect();
    let columns = vec![
        Column::numbered("window", kept.iter().map(Vec::len)),
        Column::new("t, s", pick(t, &rows)),
    ];
    let width = if windows.len() > 1 {
        TWO_COLUMNS
    } else {
        ONE_COLUMN
    };
    let height = WINDOW_ROW_HEIGHT * panel_rows as u32 + WINDOW_GRID_MARGIN;
    Ok(WindowCut {
        windows: windows.into_iter().zip(kept).collect(),
        rows,
        columns,
        size: (width, height),
    })
}

struct WindowsPlot<'a> {
    series: WindowSeries<'a>,
    /// Each window with the samples it draws (increasing indices into the series).
    windows: Vec<(RegimeWindow, Vec<usize>)>,
}

impl WindowsPlot<'_> {
    /// One panel: the measured force and each model's against `x` over the window's kept
    /// samples `rows`.
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        (w, rows): &(RegimeWindow, Vec<usize>),
        (x_label, x): (&str, &[f64]),
        caption: Option<&str>,
    ) -> Result<(), String> {
        let s = &self.series;
        let x = pick(x, rows);
        let f = pick(s.f, rows);
        let models: Vec<Vec<f64>> = s.models.iter().map(|(_, m)| pick(m, rows)).collect();
        let all_f = f.iter().chain(models.iter().flatten());
        let no_data = || format!("{}: no finite value", w.name);
        let f_range = padded_range(all_f).ok_or_else(no_data)?;
        let x_range = if x_label.starts_with("time") {
            exact_range(&x)
        } else {
            padded_range(&x)
        }
        .ok_or_else(no_data)?;
        let mut chart = small_panel(area, caption)
            .build_cartesian_2d(x_range.clone(), f_range.clone())
            .map_err(msg)?;
        draw_mesh(
            &mut chart,
            (x_label, self.series.labels.force),
            Some((5, 6)),
            tick_style(),
        )?;
        draw_runs(
            &mut chart,
            (&x, &f),
            MEASURED_LINE.stroke_width(MEASURED_WIDTH),
        )?;
        for (i, m) in models.iter().enumerate() {
            draw_runs(&mut chart, (&x, m), series_colour(i).stroke_width(2))?;
        }
        Ok(())
    }

    /// The legend the panels share, above them: the measured force and each model's.
    fn legend_entries(&self) -> Vec<(String, Swatch)> {
        let measured = ("measured".to_string(), Swatch::Line(MEASURED_LINE, 2));
        let labels: Vec<&str> = self.series.models.iter().map(|(l, _)| *l).collect();
        let rows: Vec<usize> = self.windows.iter().flat_map(|(_, r)| r.clone()).collect();
        let drawn: Vec<Vec<f64>> = self
            .series
            .models
            .iter()
            .map(|(_, m)| pick(m, &rows))
            .collect();
        let curves: Vec<&[f64]> = drawn.iter().map(Vec::as_slice).collect();
        let models = model_entries_flagged(&labels, &same_as_earlier(&curves), "");
        std::iter::once(measured).chain(models).collect()
    }
}

impl Draw for WindowsPlot<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let s = &self.series;
        let root = legend_strip(&titled(root, s.title)?, &self.legend_entries())?;
        let rows: [(&str, &[f64]); 4] = [
            ("time t, s", s.t),
            (s.labels.x, s.x_mm),
            (s.labels.v, s.v_mm),
            (s.labels.a, s.a),
        ];
        let cells = root.split_evenly((rows.len(), self.windows.len()));
        for (k, cell) in cells.iter().enumerate() {
            let (row, col) = (k / self.windows.len(), k % self.windows.len());
            let w = &self.windows[col];
            let caption = (row == 0).then_some(w.0.name.as_str());
            self.panel(cell, w, rows[row], caption)?;
        }
        Ok(())
    }
}

/// Draw each window of `series` (a column each: F_STF over time, then against x, v and a,
/// every model over the measured force) to `out_dir/name.{svg,png,csv}`. The CSV holds the
/// window's number with the samples drawn.
pub fn regime_windows(
    out_dir: &Path,
    name: &str,
    series: &WindowSeries,
    windows: &[RegimeWindow],
) -> Result<FigureFiles, ReportError> {
    let s = series;
    let mut named: Vec<(String, &[f64])> = vec![
        ("x".into(), s.x_mm),
        ("v".into(), s.v_mm),
        ("a".into(), s.a),
        ("F_STF".into(), s.f),
    ];
    named.extend(s.models.iter().map(|(label, m)| (label.to_string(), *m)));
    let mut cut = cut_windows("regime windows", s.t, &named, windows, 4)?;
    cut.push_column(s.labels.x_column, s.x_mm);
    cut.push_column(s.labels.v_column, s.v_mm);
    cut.push_column(s.labels.a_column, s.a);
    let unit = s.labels.force_unit;
    cut.push_column(format!("F_STF measured, {unit}"), s.f);
    for (label, m) in s.models {
        cut.push_column(format!("F_STF {label}, {unit}"), m);
    }
    let plot = WindowsPlot {
        series: *s,
        windows: cut.windows,
    };
    render(out_dir, name, cut.size, &plot, &cut.columns)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::test_signals::{assert_rendered, column, damped_sine};

    #[test]
    fn draws_each_window_with_the_models_and_writes_the_samples_drawn() {
        let s = damped_sine(3_000, 6.0);
        let mm = |v: &[f64]| v.iter().map(|x| x * 1e3).collect::<Vec<f64>>();
        let (x, v) = (mm(&s.x), mm(&s.v));
        let model: Vec<f64> = s.v.iter().map(|v| 20.0 * v + 400.0 * v * v.abs()).collect();
        let models = [("power law", model.as_slice())];
        let series = WindowSeries {
            t: &s.t,
            x_mm: &x,
            v_mm: &v,
            a: &s.a,
            f: &s.f,
            models: &models,
            labels: MotionLabels::LENGTH,
            title: "A few cycles of each regime",
        };
        let windows = [
            RegimeWindow {
                name: "early".into(),
                start: 0,
                end: 500,
            },
            RegimeWindow {
                name: "late".into(),
                start: 2_000,
                end: 2_750,
            },
            RegimeWindow {
                name: "empty".into(),
                start: 10,
                end: 10,
            },
        ];
        let dir = tempfile::tempdir().unwrap();
        let files = regime_windows(dir.path(), "windows", &series, &windows).unwrap();
        let cols = assert_rendered(&files, (TWO_COLUMNS, 1300));
        let t = column(&cols, "t, s");
        assert_eq!(t.len(), 1_250);
        assert_eq!(t[500], s.t[2_000]);
        assert_eq!(column(&cols, "window")[500], 2.0);
        assert_eq!(column(&cols, "F_STF power law, N")[0], model[0]);
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        assert!(svg.contains("\nearly\n") && svg.contains("\nlate\n"));
        assert!(!svg.contains("\nempty\n"));
    }

    #[test]
    fn model_loops_are_drawn_over_the_measured_ones_which_are_thin_and_grey() {
        let s = damped_sine(3_000, 6.0);
        let mm = |v: &[f64]| v.iter().map(|x| x * 1e3).collect::<Vec<f64>>();
        let (x, v) = (mm(&s.x), mm(&s.v));
        let a: Vec<f64> = s.v.iter().map(|v| 20.0 * v + 400.0 * v * v.abs()).collect();
        let b: Vec<f64> = s.v.iter().map(|v| 30.0 * v).collect();
        let models = [("power law", a.as_slice()), ("linear", b.as_slice())];
        let series = WindowSeries {
            t: &s.t,
            x_mm: &x,
            v_mm: &v,
            a: &s.a,
            f: &s.f,
            models: &models,
            labels: MotionLabels::LENGTH,
            title: "A few cycles of each regime",
        };
        let windows: Vec<RegimeWindow> = [(0, 500), (1_000, 1_500), (2_000, 2_750)]
            .iter()
            .map(|&(start, end)| RegimeWindow {
                name: format!("from {start}"),
                start,
                end,
            })
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let files = regime_windows(dir.path(), "windows", &series, &windows).unwrap();
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        // Data lines: the measured force 1 px grey, each model's 2 px in its colour (the
        // legend's marks are wider and left out).
        use crate::report::test_signals::{hex, stroke_order};
        let kinds = [
            ("#6E6E6E".to_string(), 1),
            (hex(series_colour(0)), 2),
            (hex(series_colour(1)), 2),
        ];
        // In each of the 12 panels the measured line first, then the models over it in turn.
        let order = stroke_order(&svg, &kinds);
        assert_eq!(order, [0, 1, 2].repeat(12), "drawing order by kind");
    }

    #[test]
    fn a_window_of_a_million_samples_is_drawn_decimated_with_its_peaks() {
        let s = damped_sine(1_000_000, 20.0);
        let mm = |v: &[f64]| v.iter().map(|x| x * 1e3).collect::<Vec<f64>>();
        let (x, v) = (mm(&s.x), mm(&s.v));
        let mut f = s.f.clone();
        f[400_001] = 5.0;
        let models = [("linear", s.v.as_slice())];
        let series = WindowSeries {
            t: &s.t,
            x_mm: &x,
            v_mm: &v,
            a: &s.a,
            f: &f,
            models: &models,
            labels: MotionLabels::LENGTH,
            title: "A few cycles of each regime",
        };
        let windows = [RegimeWindow {
            name: "all".into(),
            start: 0,
            end: 1_000_000,
        }];
        let dir = tempfile::tempdir().unwrap();
        let files = regime_windows(dir.path(), "windows", &series, &windows).unwrap();
        let cols = assert_rendered(&files, (ONE_COLUMN, 1300));
        let t = column(&cols, "t, s");
        assert!(t.len() <= MAX_POINTS_PER_WINDOW, "{} rows", t.len());
        let measured = column(&cols, "F_STF measured, N");
        assert!(measured.contains(&5.0));
        let x_max = x.iter().copied().fold(f64::MIN, f64::max);
        assert!(column(&cols, "x, mm").contains(&x_max));
    }
}
