//! A few cycles of each regime over time, as the source study's figures show them: one column
//! per window (pre-resonance, resonance, post-resonance), one row per quantity (x(t), v(t),
//! F_STF(t)), the measured signal a thin grey line under each model's curve (fitted or
//! simulated). Zoomed so the cycles' shapes read, where a whole sweep is a solid band.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::series_colour;
use super::decimate::pick;
use super::figure::{
    draw_mesh, draw_runs, legend_strip, msg, render, small_panel, tick_style, titled, Draw,
    FigureFiles, Swatch, MEASURED_LINE, MEASURED_WIDTH, T_LABEL,
};
use super::plot_range::{exact_range, padded_range};
use super::regime_windows::{cut_windows, RegimeWindow};
use super::ReportError;

/// One row of the figure: a quantity measured and as each model has it (a model without it
/// is left out of the row).
#[derive(Clone, Debug)]
pub struct TimeRow<'a> {
    /// The quantity and its unit, e.g. `x, mm`.
    pub label: &'a str,
    /// The measured series.
    pub measured: &'a [f64],
    /// `(model label, series)`; a label keeps its colour across rows.
    pub models: Vec<(&'a str, &'a [f64])>,
}

struct TimePlot<'a> {
    title: &'a str,
    t: &'a [f64],
    rows: &'a [TimeRow<'a>],
    /// Every model label, in colour order.
    labels: Vec<&'a str>,
    windows: Vec<(RegimeWindow, Vec<usize>)>,
}

impl TimePlot<'_> {
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        row: &TimeRow,
        (w, kept): &(RegimeWindow, Vec<usize>),
        caption: Option<&str>,
    ) -> Result<(), String> {
        let t = pick(self.t, kept);
        let y = pick(row.measured, kept);
        let models: Vec<(usize, Vec<f64>)> = row
            .models
            .iter()
            .map(|(label, m)| {
                let colour = self.labels.iter().position(|l| l == label).unwrap_or(0);
                (colour, pick(m, kept))
            })
            .collect();
        let no_data = || format!("{}: no finite value", w.name);
        let y_range = padded_range(y.iter().chain(models.iter().flat_map(|m| &m.1)));
        let y_range = y_range.ok_or_else(no_data)?;
        let t_range = exact_range(&t).ok_or_else(no_data)?;
        let mut chart = small_panel(area, caption)
            .build_cartesian_2d(t_range, y_range)
            .map_err(msg)?;
        draw_mesh(&mut chart, (T_LABEL, row.label), Some((4, 6)), tick_style())?;
        let measured = MEASURED_LINE.stroke_width(MEASURED_WIDTH);
        draw_runs(&mut chart, (&t, &y), measured)?;
        for (colour, m) in &models {
            draw_runs(&mut chart, (&t, m), series_colour(*colour).stroke_width(2))?;
        }
        Ok(())
    }
}

impl Draw for TimePlot<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let title = self.title;
        let measured = ("measured".to_string(), Swatch::Line(MEASURED_LINE, 2));
        let models = self
            .labels
            .iter()
            .enumerate()
            .map(|(i, l)| (l.to_string(), Swatch::Line(series_colour(i), 3)));
        let entries: Vec<_> = std::iter::once(measured).chain(models).collect();
        let root = legend_strip(&titled(root, title)?, &entries)?;
        let columns = self.windows.len();
        let cells = root.split_evenly((self.rows.len(), columns));
        for (k, cell) in cells.iter().enumerate() {
            let (row, col) = (k / columns, k % columns);
            let w = &self.windows[col];
            let caption = (row == 0).then_some(w.0.name.as_str());
            self.panel(cell, &self.rows[row], w, caption)?;
        }
        Ok(())
    }
}

/// Draw each window of `rows` over time `t` (a column per window, a row per quantity, every
/// model over the measured series) to `out_dir/name.{svg,png,csv}`. The CSV holds the
/// window's number with the samples drawn. `title` says what the windows are in words that
/// fit the rig (a rotor's regimes, or thirds of a record).
pub fn regime_time_windows(
    out_dir: &Path,
    name: &str,
    title: &str,
    t: &[f64],
    rows: &[TimeRow],
    windows: &[RegimeWindow],
) -> Result<FigureFiles, ReportError> {
    const FIGURE: &str = "regime time windows";
    if rows.is_empty() {
        return Err(ReportError::no_data(format!(
            "{FIGURE}: no window of at least two samples"
        )));
    }
    let mut labels: Vec<&str> = Vec::new();
    let mut named: Vec<(String, &[f64])> = Vec::new();
    for row in rows {
        named.push((row.label.to_string(), row.measured));
        for (label, m) in &row.models {
            named.push((label.to_string(), m));
            if !labels.contains(label) {
                labels.push(label);
            }
        }
    }
    let mut cut = cut_windows(FIGURE, t, &named, windows, rows.len())?;
    for row in rows {
        cut.push_column(format!("{} measured", row.label), row.measured);
        for (label, m) in &row.models {
            cut.push_column(format!("{} {label}", row.label), m);
        }
    }
    let plot = TimePlot {
        title,
        t,
        rows,
        labels,
        windows: cut.windows,
    };
    render(out_dir, name, cut.size, &plot, &cut.columns)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::figure::TWO_COLUMNS;
    use crate::report::test_signals::{assert_rendered, column, damped_sine};

    #[test]
    fn draws_x_v_and_force_of_each_window_with_the_models_where_they_have_them() {
        let s = damped_sine(3_000, 6.0);
        let model: Vec<f64> = s.f.iter().map(|f| 0.9 * f).collect();
        let simulated: Vec<f64> = s.x.iter().map(|x| 1.1 * x).collect();
        let rows = [
            TimeRow {
                label: "x, m",
                measured: &s.x,
                models: vec![("trajectory", &simulated)],
            },
            TimeRow {
                label: "v, m/s",
                measured: &s.v,
                models: Vec::new(),
            },
            TimeRow {
                label: "F_STF, N",
                measured: &s.f,
                models: vec![("power law", &model), ("trajectory", &s.f)],
            },
        ];
        let windows = [
            RegimeWindow {
                name: "early".into(),
                start: 0,
                end: 400,
            },
            RegimeWindow {
                name: "late".into(),
                start: 2_000,
                end: 2_300,
            },
            RegimeWindow {
                name: "later".into(),
                start: 2_500,
                end: 2_700,
            },
        ];
        let dir = tempfile::tempdir().unwrap();
        let files =
            regime_time_windows(dir.path(), "w", "A few cycles", &s.t, &rows, &windows).unwrap();
        let cols = assert_rendered(&files, (TWO_COLUMNS, 1000));
        let t = column(&cols, "t, s");
        assert_eq!(t.len(), 900);
        assert_eq!(t[400], s.t[2_000]);
        assert_eq!(column(&cols, "F_STF, N power law")[1], model[1]);
        assert_eq!(column(&cols, "x, m trajectory")[400], simulated[2_000]);
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        assert!(svg.contains("\nearly\n") && svg.contains("\nlate\n"));
        assert_eq!(
            svg.matches("\ntrajectory\n").count(),
            1,
            "one legend entry a model"
        );
    }

    #[test]
    fn no_window_is_an_error() {
        let s = damped_sine(100, 1.0);
        let rows = [TimeRow {
            label: "x, m",
            measured: &s.x,
            models: Vec::new(),
        }];
        let dir = tempfile::tempdir().unwrap();
        assert!(regime_time_windows(dir.path(), "w", "A few cycles", &s.t, &rows, &[]).is_err());
    }
}
