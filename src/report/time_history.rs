//! Time histories: displacement, velocity and acceleration, each in its own panel against the
//! STF force on a second axis, with the force's extrema (those standing above the noise)
//! marked, as in the source study.

use std::path::Path;

use plotters::chart::DualCoordChartContext;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::series_colour;
use super::decimate::{decimate_union, pick, MAX_POINTS_PER_LINE};
use super::envelope::{band, buckets_for, dense, envelope};
use super::extrema::{extrema, noise_delta, ExtremumKind};
use super::figure::{
    axis_desc_style, draw_line, draw_mesh_with, finite_runs, legend_strip, milli, model_entries,
    msg, render, require_finite, same_length, tick_label, tick_style, titled, Draw, FigureFiles,
    Swatch, F_LABEL, SIZE_TALL, T_LABEL,
};
use super::motion_labels::MotionLabels;
use super::plot_range::{exact_range, padded_range};
use super::series_csv::Column;
use super::ReportError;

/// The motion of the trolley over time (SI units: s, m, m/s, m/s²), all of one length.
#[derive(Clone, Copy, Debug)]
pub struct Motion<'a> {
    /// Time, s.
    pub t: &'a [f64],
    /// Displacement, m.
    pub x: &'a [f64],
    /// Velocity, m/s.
    pub v: &'a [f64],
    /// Acceleration, m/s².
    pub a: &'a [f64],
}

struct TimeHistoryPlot {
    t: Vec<f64>,
    panels: [(&'static str, Vec<f64>); 3],
    f: Vec<f64>,
    marks: Vec<(f64, f64, ExtremumKind)>,
}

impl TimeHistoryPlot {
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        index: usize,
    ) -> Result<(), String> {
        let (label, y) = &self.panels[index];
        let no_data = || format!("{label}: no finite value");
        let t_range = exact_range(&self.t).ok_or_else(no_data)?;
        let y_range = padded_range(y).ok_or_else(no_data)?;
        let f_range = padded_range(&self.f).ok_or_else(|| "F_STF: no finite value".to_string())?;
        let mut chart = ChartBuilder::on(area)
            .margin(8)
            .x_label_area_size(if index == 2 { 48 } else { 28 })
            .y_label_area_size(90)
            .right_y_label_area_size(80)
            .build_cartesian_2d(t_range.clone(), y_range.clone())
            .map_err(msg)?
            .set_secondary_coord(t_range.clone(), f_range.clone());
        let desc = ((index == 2).then(|| T_LABEL.into()), label.to_string());
        draw_mesh_with(&mut chart, desc, None, axis_desc_style())?;
        let fs = f_range.end - f_range.start;
        chart
            .configure_secondary_axes()
            .y_desc(F_LABEL)
            .y_label_formatter(&|v| tick_label(*v, fs))
            .axis_desc_style(axis_desc_style())
            .label_style(tick_style())
            .draw()
            .map_err(msg)?;

        self.draw_signals(&mut chart, y)?;
        if self.marks.len() > MAX_MARKS {
            return Ok(());
        }
        chart
            .draw_secondary_series(self.marks.iter().map(|&(t, f, kind)| {
                let style = match kind {
                    ExtremumKind::Max => BLACK.filled(),
                    ExtremumKind::Min => BLACK.stroke_width(2),
                };
                Circle::new((t, f), 4, style)
            }))
            .map_err(msg)?;
        Ok(())
    }

    /// The legend the three panels share: the motion (left axis), the force (right axis) and
    /// the marks of its extrema.
    fn legend_entries(&self) -> Vec<(String, Swatch)> {
        let suffix = if self.is_dense() { " (envelope)" } else { "" };
        let lines = ["motion, left axis", &format!("{F_LABEL}, right axis")];
        let mut entries = model_entries(lines, suffix);
        if !self.marks.is_empty() && self.marks.len() <= MAX_MARKS {
            entries.push(("F_STF maxima".into(), Swatch::Dot(BLACK)));
            entries.push(("minima".into(), Swatch::Ring));
        }
        entries
    }

    /// Hundreds of cycles: each signal is drawn as its envelope.
    fn is_dense(&self) -> bool {
        dense(&self.f) || self.panels.iter().any(|(_, y)| dense(y))
    }

    /// The motion `y` (primary axis) and the force (secondary): lines, or for hundreds of
    /// cycles each signal's envelope (the cycles are in the regime windows).
    fn draw_signals<'a, DB: DrawingBackend + 'a>(
        &self,
        chart: &mut DualCoordChartContext<
            'a,
            DB,
            Cartesian2d<RangedCoordf64, RangedCoordf64>,
            Cartesian2d<RangedCoordf64, RangedCoordf64>,
        >,
        y: &[f64],
    ) -> Result<(), String> {
        let c_motion = series_colour(0);
        let c_force = series_colour(1);
        if self.is_dense() {
            let buckets = buckets_for(y).min(buckets_for(&self.f));
            let y_band = band(&envelope(&self.t, y, buckets));
            chart
                .draw_series([Polygon::new(y_band, c_motion.mix(0.45).filled())])
                .map_err(msg)?;
            let f_band = band(&envelope(&self.t, &self.f, buckets));
            chart
                .draw_secondary_series([Polygon::new(f_band, c_force.mix(0.45).filled())])
                .map_err(msg)?;
        } else {
            for run in finite_runs(&self.t, y) {
                draw_line(chart, run, c_motion.stroke_width(2))?;
            }
            for run in finite_runs(&self.t, &self.f) {
                chart
                    .draw_secondary_series(LineSeries::new(run, c_force.stroke_width(1)))
                    .map_err(msg)?;
            }
        }
        Ok(())
    }
}

/// More extrema than this and they are not marked: they would cover the plot.
const MAX_MARKS: usize = 80;

impl Draw for TimeHistoryPlot {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let root = titled(root, "Motion against the STF force")?;
        let root = legend_strip(&root, &self.legend_entries())?;
        for (i, area) in root.split_evenly((3, 1)).iter().enumerate() {
            self.panel(area, i)?;
        }
        Ok(())
    }
}

/// Draw x (in mm, or mV for x in volts: `labels`), v (mm/s) and a (m/s²) against F_STF over time (three panels, F_STF on
/// the right axis, its extrema above the noise marked) to `out_dir/name.{svg,png,csv}`. Long records are
/// decimated keeping every series' extremes; the CSV holds the plotted samples and the marks.
pub fn time_history(
    out_dir: &Path,
    name: &str,
    motion: &Motion,
    f_stf: &[f64],
    labels: &MotionLabels,
) -> Result<FigureFiles, ReportError> {
    let Motion { t, x, v, a } = *motion;
    same_length("time history: t and x", t, x)?;
    same_length("time history: t and v", t, v)?;
    same_length("time history: t and a", t, a)?;
    same_length("time history: t and F_STF", t, f_stf)?;
    require_finite("time history", &[("t", t), ("x", x), ("F_STF", f_stf)])?;

    // More extrema than a plot can mark are neither drawn nor written.
    let mut marks_full = extrema(f_stf, noise_delta(f_stf));
    if marks_full.len() > MAX_MARKS {
        marks_full.clear();
    }
    let mut keep = decimate_union(&[x, v, a, f_stf], MAX_POINTS_PER_LINE);
    keep.extend(marks_full.iter().map(|e| e.index));
    keep.sort_unstable();
    keep.dedup();

    let plot = TimeHistoryPlot {
        t: pick(t, &keep),
        panels: [
            (labels.x, milli(&pick(x, &keep))),
            (labels.v, milli(&pick(v, &keep))),
            (labels.a, pick(a, &keep)),
        ],
        f: pick(f_stf, &keep),
        marks: marks_full
            .iter()
            .map(|e| (t[e.index], f_stf[e.index], e.kind))
            .collect(),
    };
    let marks = |of: fn(&(f64, f64, ExtremumKind)) -> f64| plot.marks.iter().map(of).collect();
    let columns = vec![
        Column::new("t, s", plot.t.clone()),
        Column::new(labels.x_column, plot.panels[0].1.clone()),
        Column::new(labels.v_column, plot.panels[1].1.clone()),
        Column::new(labels.a_column, plot.panels[2].1.clone()),
        Column::new(F_LABEL, plot.f.clone()),
        Column::new("F_STF extremum t, s", marks(|m| m.0)),
        Column::new("F_STF extremum, N", marks(|m| m.1)),
        Column::new(
            "F_STF extremum kind (1 max, -1 min)",
            marks(|m| match m.2 {
                ExtremumKind::Max => 1.0,
                ExtremumKind::Min => -1.0,
            }),
        ),
    ];
    render(out_dir, name, SIZE_TALL, &plot, &columns)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::figure::SIZE_TALL;
    use crate::report::test_signals::{assert_rendered, column, damped_sine};

    #[test]
    fn renders_a_long_damped_sine_decimated_with_its_extrema() {
        let s = damped_sine(60_000, 10.0);
        let dir = tempfile::tempdir().unwrap();
        let motion = Motion {
            t: &s.t,
            x: &s.x,
            v: &s.v,
            a: &s.a,
        };
        let files =
            time_history(dir.path(), "history", &motion, &s.f, &MotionLabels::LENGTH).unwrap();
        let cols = assert_rendered(&files, SIZE_TALL);
        let t = column(&cols, "t, s");
        let x = column(&cols, "x, mm");
        let f = column(&cols, "F_STF, N");
        assert!(t.len() < s.t.len() && t.len() <= MAX_POINTS_PER_LINE + 100);
        // Every plotted row is a sample of the record (the grid is uniform: index = t / dt).
        let dt = s.t[1] - s.t[0];
        for (k, tk) in t.iter().enumerate() {
            let i = (tk / dt).round() as usize;
            assert_eq!(s.t[i], *tk);
            assert_eq!(s.x[i] * 1e3, x[k]);
            assert_eq!(s.f[i], f[k]);
        }
        let max = |v: &[f64]| v.iter().cloned().fold(f64::MIN, f64::max);
        assert_eq!(max(x), max(&s.x) * 1e3);
        assert_eq!(max(f), max(&s.f));
        // Two force peaks and two troughs per period of 0.5 s over 10 s, less the damped tail
        // lost in the noise: many extrema, alternating, and no more than the true count.
        let kinds = column(&cols, "F_STF extremum kind (1 max, -1 min)");
        assert!(
            kinds.len() > 20 && kinds.len() <= 40,
            "{} extrema",
            kinds.len()
        );
        assert!(kinds.windows(2).all(|w| w[0] == -w[1]));
        // One legend above the panels, naming the marks too (drawn where it covers no data).
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        for label in [
            "motion, left axis",
            "F_STF, N, right axis",
            "F_STF maxima",
            "minima",
        ] {
            assert_eq!(svg.matches(label).count(), 1, "{label}");
        }
    }

    #[test]
    fn mismatched_lengths_are_an_error() {
        let s = damped_sine(100, 1.0);
        let motion = Motion {
            t: &s.t,
            x: &s.x[..50],
            v: &s.v,
            a: &s.a,
        };
        let dir = tempfile::tempdir().unwrap();
        let err = time_history(dir.path(), "h", &motion, &s.f, &MotionLabels::LENGTH).unwrap_err();
        assert!(matches!(err, ReportError::LengthMismatch { .. }), "{err}");
    }
}
