//! Hysteresis loops: the STF force against displacement, velocity or acceleration, the line
//! coloured by time (viridis) with a colour bar, so the reader sees how the loop drifts.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::viridis;
use super::decimate::{decimate_union, pick, MAX_POINTS_PER_LINE};
use super::figure::{
    axis_desc_style, draw_mesh, finite_runs, msg, render, require_finite, same_length, tick_label,
    tick_style, titled, Draw, FigureFiles, SIZE, T_LABEL, X_LABEL_AREA, Y_LABEL_AREA,
};
use super::plot_range::{exact_range, padded_range};
use super::series_csv::Column;
use super::ReportError;

/// How many colour steps the line and the colour bar use.
const COLOUR_STEPS: usize = 256;
/// Width of the colour bar's strip (bar 28 px, then ticks and the axis label), pixels.
const COLOUR_BAR_WIDTH: u32 = 165;

struct HysteresisPlot {
    label: String,
    f_label: String,
    t: Vec<f64>,
    x: Vec<f64>,
    f: Vec<f64>,
}

impl HysteresisPlot {
    /// The loop cut into runs of consecutive samples, each with the colour of its mid time,
    /// and broken where a sample is not finite (a gap is never bridged by a chord).
    fn coloured_runs(&self, t0: f64, t1: f64) -> Vec<(Vec<(f64, f64)>, RGBColor)> {
        let n = self.t.len();
        let run = n.div_ceil(COLOUR_STEPS).max(1);
        let span = if t1 > t0 { t1 - t0 } else { 1.0 };
        (0..n)
            .step_by(run)
            .flat_map(|start| {
                let end = (start + run + 1).min(n); // overlap one sample: no gaps
                let mid = self.t[(start + end - 1) / 2];
                let colour = viridis((mid - t0) / span);
                finite_runs(&self.x[start..end], &self.f[start..end])
                    .into_iter()
                    .map(move |points| (points, colour))
            })
            .collect()
    }
}

impl Draw for HysteresisPlot {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let no_data = |what: &str| format!("{what}: no finite value");
        let x_range = padded_range(&self.x).ok_or_else(|| no_data(&self.label))?;
        let f_range = padded_range(&self.f).ok_or_else(|| no_data(&self.f_label))?;
        let t_range = exact_range(&self.t).ok_or_else(|| no_data(T_LABEL))?;
        let quantity = self.label.split(',').next().unwrap_or(&self.label);
        let title = format!("F_STF against {quantity}");
        let root = titled(root, &title)?;
        let (width, _) = root.dim_in_pixel();
        let (main, bar) = root.split_horizontally(width.saturating_sub(COLOUR_BAR_WIDTH));

        let mut chart = ChartBuilder::on(&main)
            .margin(10)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(x_range.clone(), f_range.clone())
            .map_err(msg)?;
        draw_mesh(
            &mut chart,
            (self.label.as_str(), self.f_label.as_str()),
            None,
            axis_desc_style(),
        )?;
        let runs = self.coloured_runs(t_range.start, t_range.end);
        chart
            .draw_series(
                runs.into_iter()
                    .map(|(points, colour)| PathElement::new(points, colour.stroke_width(2))),
            )
            .map_err(msg)?;

        // The colour bar: a narrow strip with the time axis on its right, aligned with the
        // plotting area of the main chart (same top margin and bottom label area).
        let t_span = t_range.end - t_range.start;
        let mut colour_bar = ChartBuilder::on(&bar)
            .margin(10)
            .margin_left(15)
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(0)
            .right_y_label_area_size(COLOUR_BAR_WIDTH - 15 - 10 - 28)
            .build_cartesian_2d(0.0..1.0, t_range.clone())
            .map_err(msg)?;
        colour_bar
            .configure_mesh()
            .disable_x_mesh()
            .disable_y_mesh()
            .disable_x_axis()
            .y_desc(T_LABEL)
            .y_label_formatter(&|v| tick_label(*v, t_span))
            .axis_desc_style(axis_desc_style())
            .label_style(tick_style())
            .draw()
            .map_err(msg)?;
        let (t0, t1) = (t_range.start, t_range.end);
        let step = (t1 - t0) / COLOUR_STEPS as f64;
        colour_bar
            .draw_series((0..COLOUR_STEPS).map(|k| {
                let lo = t0 + step * k as f64;
                Rectangle::new(
                    [(0.0, lo), (1.0, lo + step)],
                    viridis((k as f64 + 0.5) / COLOUR_STEPS as f64).filled(),
                )
            }))
            .map_err(msg)?;
        Ok(())
    }
}

/// Draw F_STF against one motion quantity (`against` = its label with unit, e.g.
/// `("x, m", &x)`), the loop coloured by time `t` with a colour bar, to
/// `out_dir/name.{svg,png,csv}`; `force` is F_STF with its label and unit. The CSV holds t,
/// the quantity and F_STF as plotted.
pub fn hysteresis(
    out_dir: &Path,
    name: &str,
    against: (&str, &[f64]),
    force: (&str, &[f64]),
    t: &[f64],
) -> Result<FigureFiles, ReportError> {
    let (label, x) = against;
    let (f_label, f_stf) = force;
    same_length(&format!("hysteresis: {label} and F_STF"), x, f_stf)?;
    same_length("hysteresis: t and F_STF", t, f_stf)?;
    require_finite("hysteresis", &[("t", t), (label, x), ("F_STF", f_stf)])?;
    let keep = decimate_union(&[x, f_stf], MAX_POINTS_PER_LINE);
    let plot = HysteresisPlot {
        label: label.to_string(),
        f_label: f_label.to_string(),
        t: pick(t, &keep),
        x: pick(x, &keep),
        f: pick(f_stf, &keep),
    };
    let columns = vec![
        Column::new("t, s", plot.t.clone()),
        Column::new(label, plot.x.clone()),
        Column::new(f_label, plot.f.clone()),
    ];
    render(out_dir, name, SIZE, &plot, &columns)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::figure::F_LABEL;
    use crate::report::test_signals::{assert_rendered, column, damped_sine};

    #[test]
    fn renders_loops_against_x_v_and_a_with_the_plotted_data() {
        let s = damped_sine(4_000, 3.0);
        let dir = tempfile::tempdir().unwrap();
        for (name, label, y) in [
            ("loop_x", "displacement x, m", &s.x),
            ("loop_v", "velocity v, m/s", &s.v),
            ("loop_a", "acceleration a, m/s²", &s.a),
        ] {
            let files = hysteresis(dir.path(), name, (label, y), (F_LABEL, &s.f), &s.t).unwrap();
            let cols = assert_rendered(&files, SIZE);
            // Short record: nothing decimated, the CSV is the data.
            assert_eq!(column(&cols, "t, s"), &s.t[..]);
            assert_eq!(column(&cols, label), &y[..]);
            assert_eq!(column(&cols, F_LABEL), &s.f[..]);
            // The colour bar is drawn: the SVG has its axis label and many colour steps.
            let svg = std::fs::read_to_string(&files.svg).unwrap();
            assert!(svg.contains(T_LABEL));
            assert!(svg.matches("<rect").count() >= COLOUR_STEPS);
        }
    }

    #[test]
    fn a_gap_breaks_the_loop_instead_of_a_chord() {
        let s = damped_sine(100_000, 20.0);
        let mut a = s.a.clone();
        for v in &mut a[30_000..30_400] {
            *v = f64::NAN;
        }
        let dir = tempfile::tempdir().unwrap();
        let label = "acceleration a, m/s²";
        let files = hysteresis(dir.path(), "loop_a", (label, &a), (F_LABEL, &s.f), &s.t).unwrap();
        let cols = assert_rendered(&files, SIZE);
        let t = column(&cols, "t, s");
        assert!(t.len() <= MAX_POINTS_PER_LINE, "{} rows", t.len());
        let x = column(&cols, label);
        // The gap survives decimation (its first sample, NaN), and no drawn segment joins the
        // samples either side of it.
        let gap = t.iter().position(|&v| v >= s.t[30_000]).unwrap();
        assert!(t[gap] == s.t[30_000] && x[gap].is_nan());
        let plot = HysteresisPlot {
            label: label.into(),
            f_label: F_LABEL.into(),
            t: s.t.clone(),
            x: a.clone(),
            f: s.f.clone(),
        };
        let (before, after) = ((a[29_999], s.f[29_999]), (a[30_400], s.f[30_400]));
        for (points, _) in plot.coloured_runs(0.0, 20.0) {
            for pair in points.windows(2) {
                assert!(
                    !(pair[0] == before && pair[1] == after),
                    "a chord across the gap"
                );
            }
        }
    }

    #[test]
    fn all_nan_input_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let nan = [f64::NAN; 5];
        let t = [0.0, 1.0, 2.0, 3.0, 4.0];
        let err = hysteresis(dir.path(), "h", ("x, m", &nan), (F_LABEL, &t), &t).unwrap_err();
        assert!(matches!(err, ReportError::NoData { .. }), "{err}");
    }
}
