//! Time histories: displacement, velocity, acceleration and the STF force, each in its own
//! panel, stacked on one time axis (a panel per quantity: two axes on one panel overlap and
//! their envelopes blend), with the force's extrema (those standing above the noise) marked,
//! as in the source study. Without a measured force, the three motion panels alone.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::series_colour;
use super::decimate::{decimate_union, pick, MAX_POINTS_PER_LINE};
use super::envelope::{band, buckets_for, dense, envelope};
use super::extrema::{extrema, noise_delta, ExtremumKind};
use super::figure::{
    axis_desc_style, draw_line, draw_mesh_with, finite_runs, legend_strip, milli, msg, render,
    require_finite, same_length, titled, Chart2d, Draw, FigureFiles, Swatch, SIZE_TALL, T_LABEL,
    X_LABEL_AREA, Y_LABEL_AREA,
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
    /// Top to bottom: the three motion quantities, then the STF force if it is measured.
    panels: Vec<(&'static str, Vec<f64>)>,
    /// Whether the last panel is the STF force.
    force: bool,
    marks: Vec<(f64, f64, ExtremumKind)>,
}

impl TimeHistoryPlot {
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        index: usize,
    ) -> Result<(), String> {
        let (label, y) = &self.panels[index];
        let last = index == self.panels.len() - 1;
        let no_data = || format!("{label}: no finite value");
        let t_range = exact_range(&self.t).ok_or_else(no_data)?;
        let y_range = padded_range(y).ok_or_else(no_data)?;
        let mut chart = ChartBuilder::on(area)
            .margin(6)
            .margin_right(30)
            .x_label_area_size(if last { X_LABEL_AREA } else { 34 })
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(t_range, y_range)
            .map_err(msg)?;
        let desc = (last.then(|| T_LABEL.into()), label.to_string());
        let (w, h) = chart.plotting_area().dim_in_pixel();
        let ticks = (
            (w / 120).clamp(3, 10) as usize,
            (h / 36).clamp(3, 6) as usize,
        );
        draw_mesh_with(&mut chart, desc, Some(ticks), axis_desc_style())?;
        let colour = series_colour(usize::from(last && self.force));
        self.draw_signal(&mut chart, y, colour)?;
        if !last || self.marks.len() > MAX_MARKS {
            return Ok(());
        }
        chart
            .draw_series(self.marks.iter().map(|&(t, f, kind)| {
                let style = match kind {
                    ExtremumKind::Max => BLACK.filled(),
                    ExtremumKind::Min => BLACK.stroke_width(2),
                };
                Circle::new((t, f), 4, style)
            }))
            .map_err(msg)?;
        Ok(())
    }

    /// The legend above the panels, if there is anything to say: the marks of the force's
    /// extrema, and that signals are drawn as envelopes.
    fn legend_entries(&self) -> Vec<(String, Swatch)> {
        let mut entries = Vec::new();
        if self.is_dense() {
            let what = "each signal's envelope (its cycles are in the regime windows)";
            entries.push((what.into(), Swatch::Line(series_colour(0), 3)));
        }
        if !self.marks.is_empty() && self.marks.len() <= MAX_MARKS {
            entries.push(("F_STF maxima".into(), Swatch::Dot(BLACK)));
            entries.push(("minima".into(), Swatch::Ring));
        }
        entries
    }

    /// Hundreds of cycles: each signal is drawn as its envelope.
    fn is_dense(&self) -> bool {
        self.panels.iter().any(|(_, y)| dense(y))
    }

    /// One signal `y`: a line, or for hundreds of cycles its envelope.
    fn draw_signal<DB: DrawingBackend>(
        &self,
        chart: &mut Chart2d<'_, DB>,
        y: &[f64],
        colour: RGBColor,
    ) -> Result<(), String> {
        if self.is_dense() {
            let buckets = self.panels.iter().map(|(_, y)| buckets_for(y)).min();
            let y_band = band(&envelope(&self.t, y, buckets.unwrap_or(1)));
            chart
                .draw_series([Polygon::new(y_band, colour.mix(0.6).filled())])
                .map_err(msg)?;
        } else {
            for run in finite_runs(&self.t, y) {
                draw_line(chart, run, colour.stroke_width(2))?;
            }
        }
        Ok(())
    }
}

/// More extrema than this and they are not marked: they would cover the plot.
const MAX_MARKS: usize = 80;

impl Draw for TimeHistoryPlot {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let title = if self.force {
            "Motion and STF force over time"
        } else {
            "Motion over time"
        };
        let root = titled(root, title)?;
        let entries = self.legend_entries();
        let root = if entries.is_empty() {
            root
        } else {
            legend_strip(&root, &entries)?
        };
        for (i, area) in root.split_evenly((self.panels.len(), 1)).iter().enumerate() {
            self.panel(area, i)?;
        }
        Ok(())
    }
}

/// Draw x (in mm, or mV for x in volts: `labels`), v (mm/s), a (m/s²) and, if it is
/// measured, F_STF over time (a panel each on one time axis, F_STF's extrema above the noise
/// marked) to `out_dir/name.{svg,png,csv}`. Long records are decimated keeping every series'
/// extremes; the CSV holds the plotted samples and the marks.
pub fn time_history(
    out_dir: &Path,
    name: &str,
    motion: &Motion,
    f_stf: Option<&[f64]>,
    labels: &MotionLabels,
) -> Result<FigureFiles, ReportError> {
    let Motion { t, x, v, a } = *motion;
    same_length("time history: t and x", t, x)?;
    same_length("time history: t and v", t, v)?;
    same_length("time history: t and a", t, a)?;
    let mut series = vec![x, v, a];
    if let Some(f) = f_stf {
        same_length("time history: t and F_STF", t, f)?;
        require_finite("time history", &[("F_STF", f)])?;
        series.push(f);
    }
    require_finite("time history", &[("t", t), ("x", x)])?;

    // More extrema than a plot can mark are neither drawn nor written.
    let mut marks_full = f_stf.map_or_else(Vec::new, |f| extrema(f, noise_delta(f)));
    if marks_full.len() > MAX_MARKS {
        marks_full.clear();
    }
    let mut keep = decimate_union(&series, MAX_POINTS_PER_LINE);
    keep.extend(marks_full.iter().map(|e| e.index));
    keep.sort_unstable();
    keep.dedup();

    let mut panels = vec![
        (labels.x, milli(&pick(x, &keep))),
        (labels.v, milli(&pick(v, &keep))),
        (labels.a, pick(a, &keep)),
    ];
    let mut columns = vec![
        Column::new("t, s", pick(t, &keep)),
        Column::new(labels.x_column, panels[0].1.clone()),
        Column::new(labels.v_column, panels[1].1.clone()),
        Column::new(labels.a_column, panels[2].1.clone()),
    ];
    let marks: Vec<(f64, f64, ExtremumKind)> = f_stf.map_or_else(Vec::new, |f| {
        marks_full
            .iter()
            .map(|e| (t[e.index], f[e.index], e.kind))
            .collect()
    });
    if let Some(f) = f_stf {
        panels.push((labels.force, pick(f, &keep)));
        let of = |g: fn(&(f64, f64, ExtremumKind)) -> f64| marks.iter().map(g).collect();
        columns.extend([
            Column::new(labels.force, panels[3].1.clone()),
            Column::new("F_STF extremum t, s", of(|m| m.0)),
            Column::new(
                format!("F_STF extremum, {}", labels.force_unit),
                of(|m| m.1),
            ),
            Column::new(
                "F_STF extremum kind (1 max, -1 min)",
                of(|m| match m.2 {
                    ExtremumKind::Max => 1.0,
                    ExtremumKind::Min => -1.0,
                }),
            ),
        ]);
    }
    let plot = TimeHistoryPlot {
        t: pick(t, &keep),
        force: f_stf.is_some(),
        marks,
        panels,
    };
    render(out_dir, name, SIZE_TALL, &plot, &columns)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::figure::SIZE_TALL;
    use crate::report::test_signals::{assert_rendered, column, damped_sine, Signals};

    /// The motion of the signals `s`.
    fn motion_of(s: &Signals) -> Motion<'_> {
        Motion {
            t: &s.t,
            x: &s.x,
            v: &s.v,
            a: &s.a,
        }
    }

    #[test]
    fn renders_a_long_damped_sine_decimated_with_its_extrema() {
        let s = damped_sine(60_000, 10.0);
        let dir = tempfile::tempdir().unwrap();
        let motion = motion_of(&s);
        let files = time_history(
            dir.path(),
            "history",
            &motion,
            Some(&s.f),
            &MotionLabels::LENGTH,
        )
        .unwrap();
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
        // One legend above the panels, naming the marks (drawn where it covers no data); a
        // panel per quantity, each axis named once, and no second axis on any panel.
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        for label in [
            "F_STF maxima",
            "minima",
            "\nF_STF, N\n",
            "\nvelocity v, mm/s\n",
        ] {
            assert_eq!(svg.matches(label).count(), 1, "{label}");
        }
        assert!(!svg.contains("right axis"));
        assert_eq!(svg.matches("\ntime t, s\n").count(), 1);
    }

    /// A record without a measured force: the three motion panels, no force column, no marks
    /// and no legend naming F_STF's maxima.
    #[test]
    fn without_a_force_the_motion_alone_is_drawn() {
        let s = damped_sine(6_000, 10.0);
        let dir = tempfile::tempdir().unwrap();
        let motion = motion_of(&s);
        let files =
            time_history(dir.path(), "history", &motion, None, &MotionLabels::LENGTH).unwrap();
        let cols = assert_rendered(&files, SIZE_TALL);
        let names: Vec<&str> = cols.iter().map(|c| c.name.as_str()).collect();
        assert!(!names.iter().any(|n| n.contains("F_STF")), "{names:?}");
        assert_eq!(column(&cols, "x, mm").len(), s.t.len());
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        assert!(!svg.contains("F_STF") && !svg.contains("minima"));
        assert!(svg.contains("\nMotion over time\n"));
        assert_eq!(svg.matches("\ntime t, s\n").count(), 1);
    }

    #[test]
    fn mismatched_lengths_are_an_error() {
        let s = damped_sine(100, 1.0);
        let motion = Motion {
            x: &s.x[..50],
            ..motion_of(&s)
        };
        let dir = tempfile::tempdir().unwrap();
        let err =
            time_history(dir.path(), "h", &motion, Some(&s.f), &MotionLabels::LENGTH).unwrap_err();
        assert!(matches!(err, ReportError::LengthMismatch { .. }), "{err}");
    }
}
