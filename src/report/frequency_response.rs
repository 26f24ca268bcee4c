//! The frequency response of a sweep: the local maxima of the displacement against rotor
//! speed, for each record (typically with and without STF), with the smoothed trend of
//! [`smooth_trend`](super::smooth_trend) drawn through them.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::series_colour;
use super::decimate::{decimate_union, pick, MAX_POINTS_PER_LINE};
use super::figure::{
    axis_desc_style, finite_points, legend_line, legend_style, msg, render, same_length,
    tick_style, title_style, Draw, FigureFiles, SIZE,
};
use super::plot_range::padded_range;
use super::series_csv::Column;
use super::smoothing::{smooth_trend, Smoothing};
use super::ReportError;

/// One frequency response: the local maxima of x of one record, in time order.
#[derive(Clone, Debug, PartialEq)]
pub struct FrfCurve {
    /// What the record is, e.g. `"without STF"`.
    pub label: String,
    /// Rotor speed at each local maximum, rad/s.
    pub omega: Vec<f64>,
    /// The local maxima of the displacement, m.
    pub x_peak: Vec<f64>,
}

struct PlottedCurve {
    label: String,
    omega: Vec<f64>,
    x_peak: Vec<f64>,
    trend: Vec<f64>,
}

struct FrequencyResponsePlot {
    curves: Vec<PlottedCurve>,
}

impl Draw for FrequencyResponsePlot {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let no_data = || "frequency response: no finite value".to_string();
        let w_range =
            padded_range(self.curves.iter().flat_map(|c| &c.omega)).ok_or_else(no_data)?;
        let x_range = padded_range(
            self.curves
                .iter()
                .flat_map(|c| c.x_peak.iter().chain(&c.trend)),
        )
        .ok_or_else(no_data)?;
        let root = root
            .titled("Frequency response: local maxima of x", title_style())
            .map_err(msg)?;
        let mut chart = ChartBuilder::on(&root)
            .margin(10)
            .margin_right(30)
            .x_label_area_size(50)
            .y_label_area_size(90)
            .build_cartesian_2d(w_range, x_range)
            .map_err(msg)?;
        chart
            .configure_mesh()
            .x_desc("rotor speed ω, rad/s")
            .y_desc("local maximum of x, m")
            .axis_desc_style(axis_desc_style())
            .label_style(tick_style())
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(msg)?;
        for (i, c) in self.curves.iter().enumerate() {
            let colour = series_colour(i);
            chart
                .draw_series(
                    finite_points(&c.omega, &c.x_peak)
                        .into_iter()
                        .map(|p| Circle::new(p, 2, colour.mix(0.45).filled())),
                )
                .map_err(msg)?
                .label(format!("{}: local maxima", c.label))
                .legend(move |(x, y)| Circle::new((x + 12, y), 3, colour.mix(0.6).filled()));
            chart
                .draw_series(LineSeries::new(
                    finite_points(&c.omega, &c.trend),
                    colour.stroke_width(3),
                ))
                .map_err(msg)?
                .label(format!("{}: smoothed trend", c.label))
                .legend(legend_line(colour));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font(legend_style())
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(msg)
    }
}

/// Draw the local maxima of x against ω for each curve, with each curve's smoothed trend
/// (outliers replaced by the mean of their neighbours, then a moving average, per
/// `smoothing`), to `out_dir/name.{svg,png,csv}`. The CSV has three columns per curve: ω, the
/// maxima and the trend, as plotted.
pub fn frequency_response(
    out_dir: &Path,
    name: &str,
    curves: &[FrfCurve],
    smoothing: &Smoothing,
) -> Result<FigureFiles, ReportError> {
    let mut plotted = Vec::with_capacity(curves.len());
    for c in curves {
        same_length(
            &format!("frequency response {:?}: ω and x_peak", c.label),
            &c.omega,
            &c.x_peak,
        )?;
        let trend = smooth_trend(&c.x_peak, smoothing);
        let keep = decimate_union(&[&c.x_peak, &trend], MAX_POINTS_PER_LINE);
        plotted.push(PlottedCurve {
            label: c.label.clone(),
            omega: pick(&c.omega, &keep),
            x_peak: pick(&c.x_peak, &keep),
            trend: pick(&trend, &keep),
        });
    }
    let has_data = plotted
        .iter()
        .any(|c| !finite_points(&c.omega, &c.x_peak).is_empty());
    if !has_data {
        return Err(ReportError::NoData {
            what: "frequency response".into(),
        });
    }
    let columns: Vec<Column> = plotted
        .iter()
        .flat_map(|c| {
            [
                Column::new(format!("{}: ω, rad/s", c.label), c.omega.clone()),
                Column::new(
                    format!("{}: local maximum of x, m", c.label),
                    c.x_peak.clone(),
                ),
                Column::new(format!("{}: smoothed trend, m", c.label), c.trend.clone()),
            ]
        })
        .collect();
    render(
        out_dir,
        name,
        SIZE,
        &FrequencyResponsePlot { curves: plotted },
        &columns,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::test_signals::{assert_rendered, column};

    /// A resonance curve x(ω) = 1 mm / |1 − (ω/ωn)²|, capped, sampled at `n` maxima.
    fn resonance(label: &str, wn: f64, damping: f64, n: usize) -> FrfCurve {
        let omega: Vec<f64> = (0..n).map(|i| 10.0 + 60.0 * i as f64 / n as f64).collect();
        let x_peak = omega
            .iter()
            .map(|w| {
                let r = w / wn;
                1e-3 / ((1.0 - r * r).powi(2) + (2.0 * damping * r).powi(2)).sqrt()
            })
            .collect();
        FrfCurve {
            label: label.into(),
            omega,
            x_peak,
        }
    }

    #[test]
    fn renders_two_curves_with_trends_and_writes_them() {
        let mut without = resonance("without STF", 40.0, 0.05, 300);
        without.x_peak[100] *= 3.0; // an outlier the trend must ignore
        let with = resonance("with STF", 42.0, 0.2, 250);
        let dir = tempfile::tempdir().unwrap();
        let smoothing = Smoothing::default();
        let files =
            frequency_response(dir.path(), "frf", &[without.clone(), with], &smoothing).unwrap();
        let cols = assert_rendered(&files, SIZE);
        assert_eq!(cols.len(), 6);
        assert_eq!(column(&cols, "without STF: ω, rad/s"), &without.omega[..]);
        assert_eq!(
            column(&cols, "without STF: local maximum of x, m"),
            &without.x_peak[..]
        );
        let trend = column(&cols, "without STF: smoothed trend, m");
        assert_eq!(trend, &smooth_trend(&without.x_peak, &smoothing)[..]);
        assert!(
            trend[100] < 1.5 * without.x_peak[99],
            "outlier leaked into the trend"
        );
        assert_eq!(column(&cols, "with STF: ω, rad/s").len(), 250);
    }

    #[test]
    fn no_curve_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let err = frequency_response(dir.path(), "f", &[], &Smoothing::default()).unwrap_err();
        assert!(matches!(err, ReportError::NoData { .. }), "{err}");
    }
}
