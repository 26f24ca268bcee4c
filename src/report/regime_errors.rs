//! The per-regime errors of several models as grouped bars: one group per regime
//! (pre-resonance, resonance, post-resonance, overall), one bar per model.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::series_colour;
use super::figure::{
    axis_desc_style, legend_strip, msg, one_panel, render, tick_label, tick_style, titled, Draw,
    FigureFiles, Swatch, SIZE_WIDE,
};
use super::series_csv::Column;
use super::ReportError;

struct RegimeErrorPlot<'a> {
    groups: &'a [&'a str],
    models: &'a [(&'a str, Vec<f64>)],
    y_label: &'a str,
}

impl Draw for RegimeErrorPlot<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let top = self
            .models
            .iter()
            .flat_map(|(_, v)| v.iter().copied())
            .filter(|v| v.is_finite())
            .fold(0.0_f64, f64::max)
            .max(1e-9)
            * 1.15;
        let n_groups = self.groups.len();
        let root = titled(root, "Errors of each model, regime by regime")?;
        // The legend above the bars: inside, it would cover the tallest.
        let entries: Vec<(String, Swatch)> = self
            .models
            .iter()
            .enumerate()
            .map(|(m, (label, _))| (label.to_string(), Swatch::Line(series_colour(m), 14)))
            .collect();
        let root = legend_strip(&root, &entries)?;
        let mut chart = one_panel(&root)
            .build_cartesian_2d(0.0..n_groups as f64, 0.0..top)
            .map_err(msg)?;
        let groups = self.groups;
        chart
            .configure_mesh()
            .x_labels(n_groups * 2 + 1)
            .x_label_formatter(&|x| {
                let i = x.floor() as usize;
                if (x - i as f64 - 0.5).abs() < 0.26 {
                    groups.get(i).map_or(String::new(), |g| g.to_string())
                } else {
                    String::new()
                }
            })
            .disable_x_mesh()
            .y_labels(6)
            .y_desc(self.y_label)
            .y_label_formatter(&|v| tick_label(*v, top))
            .x_desc("regime")
            .axis_desc_style(axis_desc_style())
            .label_style(tick_style())
            .draw()
            .map_err(msg)?;
        let n_models = self.models.len().max(1) as f64;
        let width = 0.8 / n_models;
        for (m, (_, values)) in self.models.iter().enumerate() {
            let colour = series_colour(m);
            let bars = values
                .iter()
                .enumerate()
                .filter(|(_, v)| v.is_finite())
                .map(|(g, &v)| {
                    let x0 = g as f64 + 0.1 + m as f64 * width;
                    Rectangle::new([(x0, 0.0), (x0 + width * 0.9, v)], colour.filled())
                });
            chart.draw_series(bars).map_err(msg)?;
        }
        Ok(())
    }
}

/// Draw `models` (label, one value per group; NaN: no bar) over `groups` as grouped bars
/// with the y axis `y_label` to `out_dir/name.{svg,png,csv}`.
pub fn regime_errors(
    out_dir: &Path,
    name: &str,
    groups: &[&str],
    models: &[(&str, Vec<f64>)],
    y_label: &str,
) -> Result<FigureFiles, ReportError> {
    if models.is_empty() || groups.is_empty() {
        return Err(ReportError::no_data("regime errors: no model or no regime"));
    }
    let plot = RegimeErrorPlot {
        groups,
        models,
        y_label,
    };
    let columns: Vec<Column> = std::iter::once(Column::new(
        "regime (0 pre-resonance, 1 resonance, 2 post-resonance, 3 overall)",
        (0..groups.len()).map(|g| g as f64).collect(),
    ))
    .chain(
        models
            .iter()
            .map(|(l, v)| Column::new(format!("{l}: {y_label}"), v.clone())),
    )
    .collect();
    render(out_dir, name, SIZE_WIDE, &plot, &columns)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_grouped_bars_and_their_csv() {
        let dir = tempfile::tempdir().unwrap();
        let files = regime_errors(
            dir.path(),
            "errors",
            &["pre", "res", "post", "overall"],
            &[
                ("a", vec![0.5, 0.2, f64::NAN, 0.3]),
                ("b", vec![0.1, 0.1, 0.1, 0.1]),
            ],
            "relative force RMS error",
        )
        .unwrap();
        crate::report::test_signals::assert_prints_well(&files, SIZE_WIDE);
        assert!(std::fs::read_to_string(&files.svg)
            .unwrap()
            .contains("relative force RMS error"));
        let csv = std::fs::read_to_string(&files.csv).unwrap();
        assert!(csv.lines().count() == 5, "{csv}");
    }
}
