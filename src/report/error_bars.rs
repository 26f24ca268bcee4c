//! A fitted value against a condition, with error bars: one marker per record at its
//! condition's value, a vertical bar of ±1 standard error, one colour per series (the
//! records that share the other conditions). Series sharing an x are nudged apart by a small
//! fraction of the x span so their bars do not hide one another; the CSV holds the true x.
//! A fitted curve (a law through the points) may be drawn over them, in black.
//! The bars are drawn as plain paths (plotters' `ErrorBar` needs a feature this build does
//! not enable, and two lines are all it is).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::series_colour;
use super::figure::{
    axis_desc_style, draw_mesh, legend_strip, msg, one_panel, render, titled, Draw, FigureFiles,
    Swatch, SIZE,
};
use super::plot_range::{finite_bounds, padded_range};
use super::series_csv::Column;
use super::ReportError;

/// One point: condition value, fitted value, its standard error (NaN: no bar).
pub type ErrorPoint = (f64, f64, f64);

/// A series of points under one legend label.
#[derive(Clone, Debug)]
pub struct ErrorSeries {
    /// Legend label (e.g. `F0 = 0.035`).
    pub label: String,
    /// Its points.
    pub points: Vec<ErrorPoint>,
}

/// A curve drawn over the points (a fitted law), under its legend label.
#[derive(Clone, Debug)]
pub struct Curve {
    /// Legend label.
    pub label: String,
    /// Its points, in x order.
    pub points: Vec<(f64, f64)>,
}

struct ErrorBarPlot<'a> {
    title: &'a str,
    x_label: &'a str,
    y_label: &'a str,
    series: &'a [ErrorSeries],
    curve: Option<&'a Curve>,
}

impl ErrorBarPlot<'_> {
    /// The x and y ranges: every point with its bar.
    fn ranges(&self) -> Option<(std::ops::Range<f64>, std::ops::Range<f64>)> {
        let curve = self.curve.map_or(&[][..], |c| &c.points[..]);
        let mut xs: Vec<f64> = self.points().map(|p| p.0).collect();
        xs.extend(curve.iter().map(|p| p.0));
        let mut ys: Vec<f64> = self
            .points()
            .flat_map(|(_, y, e)| {
                let e = if e.is_finite() { e } else { 0.0 };
                [y - e, y + e]
            })
            .collect();
        ys.extend(curve.iter().map(|p| p.1));
        Some((padded_range(&xs)?, padded_range(&ys)?))
    }

    fn points(&self) -> impl Iterator<Item = ErrorPoint> + '_ {
        self.series.iter().flat_map(|s| s.points.iter().copied())
    }
}

impl Draw for ErrorBarPlot<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let (xr, yr) = self.ranges().ok_or("no finite point")?;
        let x_span = xr.end - xr.start;
        let root = titled(root, self.title)?;
        let mut legend: Vec<(String, Swatch)> = self
            .series
            .iter()
            .enumerate()
            .map(|(i, s)| (s.label.clone(), Swatch::Dot(series_colour(i))))
            .collect();
        if let Some(c) = self.curve {
            legend.push((c.label.clone(), Swatch::Line(BLACK, 2)));
        }
        let root = legend_strip(&root, &legend)?;
        let mut chart = one_panel(&root).build_cartesian_2d(xr, yr).map_err(msg)?;
        let desc = (self.x_label, self.y_label);
        draw_mesh(&mut chart, desc, None, axis_desc_style())?;
        if let Some(c) = self.curve {
            let points: Vec<(f64, f64)> = c
                .points
                .iter()
                .copied()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .collect();
            chart
                .draw_series(LineSeries::new(points, BLACK.stroke_width(2)))
                .map_err(msg)?;
        }
        let n = self.series.len();
        for (i, s) in self.series.iter().enumerate() {
            let colour = series_colour(i);
            let nudge = (i as f64 - (n as f64 - 1.0) / 2.0) * 0.012 * x_span;
            let points: Vec<ErrorPoint> = s
                .points
                .iter()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .map(|&(x, y, e)| (x + nudge, y, e))
                .collect();
            let cap = 0.006 * x_span;
            let bars = points
                .iter()
                .filter(|p| p.2.is_finite())
                .flat_map(|&(x, y, e)| {
                    let style = colour.stroke_width(2);
                    [
                        PathElement::new(vec![(x, y - e), (x, y + e)], style),
                        PathElement::new(vec![(x - cap, y - e), (x + cap, y - e)], style),
                        PathElement::new(vec![(x - cap, y + e), (x + cap, y + e)], style),
                    ]
                });
            chart.draw_series(bars).map_err(msg)?;
            chart
                .draw_series(
                    points
                        .iter()
                        .map(|&(x, y, _)| Circle::new((x, y), 5, colour.filled())),
                )
                .map_err(msg)?;
        }
        Ok(())
    }
}

/// Draw `series` (points with ±1 standard error bars) against the condition `x_label` to
/// `out_dir/name.{svg,png,csv}`; the CSV has per series its x, value and standard error.
pub fn error_bars(
    out_dir: &Path,
    name: &str,
    title: &str,
    labels: (&str, &str),
    series: &[ErrorSeries],
) -> Result<FigureFiles, ReportError> {
    error_bars_with_curve(out_dir, name, title, labels, series, None)
}

/// [`error_bars`] with `curve` drawn over the points; the CSV gains its x and y columns.
pub fn error_bars_with_curve(
    out_dir: &Path,
    name: &str,
    title: &str,
    (x_label, y_label): (&str, &str),
    series: &[ErrorSeries],
    curve: Option<&Curve>,
) -> Result<FigureFiles, ReportError> {
    let all = series.iter().flat_map(|s| s.points.iter());
    if finite_bounds(all.map(|p| &p.1)).is_none() {
        return Err(ReportError::NoData {
            what: format!("{title}: no finite value"),
        });
    }
    let plot = ErrorBarPlot {
        title,
        x_label,
        y_label,
        series,
        curve,
    };
    let mut columns: Vec<Column> = series
        .iter()
        .flat_map(|s| {
            let of = |f: fn(&ErrorPoint) -> f64| s.points.iter().map(f).collect::<Vec<f64>>();
            [
                Column::new(format!("{}: {x_label}", s.label), of(|p| p.0)),
                Column::new(format!("{}: {y_label}", s.label), of(|p| p.1)),
                Column::new(format!("{}: standard error", s.label), of(|p| p.2)),
            ]
        })
        .collect();
    if let Some(c) = curve {
        let of = |f: fn(&(f64, f64)) -> f64| c.points.iter().map(f).collect::<Vec<f64>>();
        columns.push(Column::new(format!("{}: {x_label}", c.label), of(|p| p.0)));
        columns.push(Column::new(format!("{}: {y_label}", c.label), of(|p| p.1)));
    }
    render(out_dir, name, SIZE, &plot, &columns)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_points_with_bars_and_their_csv() {
        let dir = tempfile::tempdir().unwrap();
        let series = vec![
            ErrorSeries {
                label: "F0 = 0.035".into(),
                points: vec![(0.36, 2.5, 0.4), (0.40, 4.2, 0.3), (0.44, 7.2, f64::NAN)],
            },
            ErrorSeries {
                label: "F0 = 0.06".into(),
                points: vec![(0.36, 2.1, 0.05), (0.40, 4.0, 0.06)],
            },
        ];
        let files = error_bars(
            dir.path(),
            "k",
            "power_law K against concentration",
            ("concentration", "K"),
            &series,
        )
        .unwrap();
        crate::report::test_signals::assert_prints_well(&files, SIZE);
        let csv = std::fs::read_to_string(&files.csv).unwrap();
        assert!(
            csv.starts_with("F0 = 0.035: concentration,F0 = 0.035: K,"),
            "{csv}"
        );
        assert_eq!(csv.lines().count(), 4, "{csv}");
        let none = error_bars(dir.path(), "n", "t", ("x", "y"), &[]);
        assert!(none.is_err());
    }

    /// Values whose bars span 4.6–5.4 (K against concentration) get three labelled ticks on
    /// their axis at least, not the one `5` of plotters' step of 0.5.
    #[test]
    fn a_narrow_range_of_values_gets_three_labelled_ticks_at_least() {
        let dir = tempfile::tempdir().unwrap();
        let series = vec![ErrorSeries {
            label: "F0 = 0.035".into(),
            points: vec![(0.36, 5.0, 0.4), (0.40, 5.02, 0.38)],
        }];
        let files = error_bars(dir.path(), "k", "K", ("concentration", "K"), &series).unwrap();
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        let y_ticks: Vec<f64> = svg
            .split('\n')
            .filter_map(|l| l.trim().parse::<f64>().ok())
            .filter(|v| (4.5..5.5).contains(v))
            .collect();
        assert!(y_ticks.len() >= 3, "{y_ticks:?}");
        crate::report::test_signals::assert_prints_well(&files, SIZE);
    }

    #[test]
    fn a_curve_is_drawn_over_the_points_and_kept_in_the_csv() {
        let dir = tempfile::tempdir().unwrap();
        let series = vec![ErrorSeries {
            label: "records".into(),
            points: vec![(1.0, 1.1, 0.1), (2.0, 3.9, 0.2)],
        }];
        let curve = Curve {
            label: "law".into(),
            points: (0..11)
                .map(|i| (1.0 + 0.1 * i as f64, 1.0 + 0.3 * i as f64))
                .collect(),
        };
        let files =
            error_bars_with_curve(dir.path(), "c", "t", ("x", "y"), &series, Some(&curve)).unwrap();
        let csv = std::fs::read_to_string(&files.csv).unwrap();
        assert!(
            csv.lines().next().unwrap().ends_with(",law: x,law: y"),
            "{csv}"
        );
        assert_eq!(csv.lines().count(), 12, "{csv}");
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        assert!(svg.contains("law"), "the curve's legend");
        crate::report::test_signals::assert_prints_well(&files, SIZE);
    }
}
