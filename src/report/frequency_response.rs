//! The frequency response of a sweep: the local maxima of the displacement against rotor
//! speed, for each record (typically with and without STF), with the smoothed trend of
//! [`smooth_trend`](super::smooth_trend) drawn through them.

use std::ops::Range;
use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::series_colour;
use super::decimate::{decimate_union, pick, MAX_POINTS_PER_LINE};
use super::figure::{
    axis_desc_style, draw_legend, finite_points, msg, one_panel, render, same_length, tick_label,
    tick_style, titled, Draw, FigureFiles, SIZE_WIDE,
};
use super::plot_range::padded_range;
use super::series_csv::Column;
use super::smoothing::{smooth_trend, Smoothing};
use super::ReportError;

/// What a frequency response is, which sets how it is drawn; in drawing order (models first,
/// then the record, then the reference on top).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum FrfRole {
    /// The oscillator with a fitted model: a coloured trend over faint maxima.
    #[default]
    Model,
    /// The record: grey maxima under a dark trend.
    Measured,
    /// The oscillator without STF: a black dashed trend drawn over the others, so a model
    /// whose response equals it cannot hide it.
    Reference,
}

/// One frequency response: the local maxima of x of one record, in time order.
#[derive(Clone, Debug, PartialEq)]
pub struct FrfCurve {
    /// What the record is, e.g. `"without STF"`.
    pub label: String,
    /// Rotor speed at each local maximum, rad/s.
    pub omega: Vec<f64>,
    /// The local maxima of the displacement, m.
    pub x_peak: Vec<f64>,
    /// How it is drawn.
    pub role: FrfRole,
}

/// A change of regime along ω: where (rad/s) and the half-width of its uncertainty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegimeChange {
    /// ω at the change, rad/s.
    pub omega: f64,
    /// Half-width of its uncertainty, rad/s.
    pub uncertainty: f64,
}

struct PlottedCurve {
    label: String,
    role: FrfRole,
    omega: Vec<f64>,
    x_peak: Vec<f64>,
    trend: Vec<f64>,
}

struct FrequencyResponsePlot {
    /// The axis label of the maxima: `local maximum of x, mm` (or mV).
    y_desc: String,
    curves: Vec<PlottedCurve>,
    /// Pre-resonance → resonance and resonance → post-resonance, where the record has them.
    changes: [Option<RegimeChange>; 2],
}

const MEASURED_GREY: RGBColor = RGBColor(150, 150, 150);
const RESONANCE_SHADE: RGBColor = RGBColor(255, 244, 214);
const UNCERTAINTY_SHADE: RGBColor = RGBColor(200, 200, 200);

impl FrequencyResponsePlot {
    /// The resonance regime shaded between the two changes, each change's uncertainty
    /// darker, and the regimes named along the top.
    fn shade_regimes<DB: DrawingBackend>(
        &self,
        chart: &mut ChartContext<DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
        w: &Range<f64>,
        x: &Range<f64>,
    ) -> Result<(), String> {
        let [pre, post] = self.changes;
        let lo = pre.map_or(w.start, |c| c.omega);
        let hi = post.map_or(w.end, |c| c.omega);
        let pad = 0.01 * (w.end - w.start);
        let mut names = Vec::new();
        if pre.is_some() || post.is_some() {
            chart
                .draw_series([Rectangle::new(
                    [(lo, x.start), (hi, x.end)],
                    RESONANCE_SHADE.filled(),
                )])
                .map_err(msg)?;
            let first = if pre.is_some() {
                "pre-resonance"
            } else {
                "resonance"
            };
            names.push((w.start + pad, first));
        }
        let after = |c: RegimeChange, name| (c.omega + c.uncertainty + pad, name);
        names.extend(pre.map(|c| after(c, "resonance")));
        names.extend(post.map(|c| after(c, "post-resonance")));
        for c in self.changes.iter().flatten() {
            let band = [
                (c.omega - c.uncertainty, x.start),
                (c.omega + c.uncertainty, x.end),
            ];
            chart
                .draw_series([Rectangle::new(band, UNCERTAINTY_SHADE.filled())])
                .map_err(msg)?;
        }
        let top = x.end - 0.04 * (x.end - x.start);
        let style = tick_style().color(&RGBColor(90, 90, 90));
        chart
            .draw_series(
                names
                    .into_iter()
                    .map(|(at, name)| Text::new(name, (at, top), style.clone())),
            )
            .map_err(msg)?;
        Ok(())
    }

    /// One curve: its maxima as dots and its trend as a line, with one legend entry.
    fn draw_curve<'a, DB: DrawingBackend + 'a>(
        chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
        c: &PlottedCurve,
        colour: RGBColor,
    ) -> Result<(), String> {
        let (dots, line): (ShapeStyle, ShapeStyle) = match c.role {
            FrfRole::Measured => (
                MEASURED_GREY.mix(0.6).filled(),
                BLACK.mix(0.7).stroke_width(3),
            ),
            FrfRole::Reference => (BLACK.mix(0.0).filled(), BLACK.stroke_width(2)),
            FrfRole::Model => (colour.mix(0.3).filled(), colour.stroke_width(3)),
        };
        chart
            .draw_series(
                finite_points(&c.omega, &c.x_peak)
                    .into_iter()
                    .map(|p| Circle::new(p, 2, dots)),
            )
            .map_err(msg)?;
        let points = finite_points(&c.omega, &c.trend);
        let legend = match c.role {
            FrfRole::Reference => chart
                .draw_series(DashedLineSeries::new(points, 10, 6, line))
                .map_err(msg)?,
            _ => chart
                .draw_series(LineSeries::new(points, line))
                .map_err(msg)?,
        };
        let dashed = c.role == FrfRole::Reference;
        legend.label(c.label.as_str()).legend(move |(x, y)| {
            let gap = if dashed { 6 } else { 0 };
            EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (9, 0)], line)
                + PathElement::new(vec![(9 + gap, 0), (24, 0)], line)
        });
        Ok(())
    }
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
        let root = titled(root, "Frequency response: local maxima of x")?;
        let mut chart = one_panel(&root)
            .build_cartesian_2d(w_range.clone(), x_range.clone())
            .map_err(msg)?;
        let (ws, xs) = (w_range.end - w_range.start, x_range.end - x_range.start);
        self.shade_regimes(&mut chart, &w_range, &x_range)?;
        chart
            .configure_mesh()
            .x_desc("rotor speed ω, rad/s")
            .y_desc(self.y_desc.as_str())
            .x_label_formatter(&|v| tick_label(*v, ws))
            .y_label_formatter(&|v| tick_label(*v, xs))
            .axis_desc_style(axis_desc_style())
            .label_style(tick_style())
            .light_line_style(WHITE.mix(0.0))
            .bold_line_style(BLACK.mix(0.08))
            .draw()
            .map_err(msg)?;
        let mut drawn: Vec<&PlottedCurve> = self.curves.iter().collect();
        drawn.sort_by_key(|c| c.role);
        let mut model = 0;
        for c in drawn {
            let colour = series_colour(model);
            if c.role == FrfRole::Model {
                model += 1;
            }
            Self::draw_curve(&mut chart, c, colour)?;
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

/// Draw the local maxima of x against ω for each curve, with each curve's smoothed trend
/// (outliers replaced by the mean of their neighbours, then a moving average, per
/// `smoothing`), to `out_dir/name.{svg,png,csv}`. The CSV has three columns per curve: ω, the
/// maxima and the trend, as plotted, in `x_unit` (`mm`, or `mV` for a record in volts: the
/// maxima are drawn in thousandths of the record's unit either way).
pub fn frequency_response(
    out_dir: &Path,
    name: &str,
    curves: &[FrfCurve],
    changes: [Option<RegimeChange>; 2],
    smoothing: &Smoothing,
    x_unit: &str,
) -> Result<FigureFiles, ReportError> {
    let mut plotted = Vec::with_capacity(curves.len());
    for c in curves {
        same_length(
            &format!("frequency response {:?}: ω and x_peak", c.label),
            &c.omega,
            &c.x_peak,
        )?;
        let x_mm: Vec<f64> = c.x_peak.iter().map(|x| x * 1e3).collect();
        // A simulation has no noise to smooth away, and smoothing would flatten its peak.
        let trend = match c.role {
            FrfRole::Measured => smooth_trend(&x_mm, smoothing),
            _ => x_mm.clone(),
        };
        let keep = decimate_union(&[&x_mm, &trend], MAX_POINTS_PER_LINE);
        plotted.push(PlottedCurve {
            label: c.label.clone(),
            role: c.role,
            omega: pick(&c.omega, &keep),
            x_peak: pick(&x_mm, &keep),
            trend: pick(&trend, &keep),
        });
    }
    let has_data = plotted
        .iter()
        .any(|c| !finite_points(&c.omega, &c.x_peak).is_empty());
    if !has_data {
        return Err(ReportError::no_data("frequency response"));
    }
    let columns: Vec<Column> = plotted
        .iter()
        .flat_map(|c| {
            [
                Column::new(format!("{}: ω, rad/s", c.label), c.omega.clone()),
                Column::new(
                    format!("{}: local maximum of x, {x_unit}", c.label),
                    c.x_peak.clone(),
                ),
                Column::new(format!("{}: trend, {x_unit}", c.label), c.trend.clone()),
            ]
        })
        .collect();
    let plot = FrequencyResponsePlot {
        y_desc: format!("local maximum of x, {x_unit}"),
        curves: plotted,
        changes,
    };
    render(out_dir, name, SIZE_WIDE, &plot, &columns)
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
            role: FrfRole::Model,
        }
    }

    #[test]
    fn renders_the_record_the_reference_and_a_model_with_one_legend_entry_each() {
        let mut without = resonance("without STF", 40.0, 0.05, 300);
        without.role = FrfRole::Reference;
        let mut measured = resonance("measured", 41.0, 0.1, 300);
        measured.role = FrfRole::Measured;
        measured.x_peak[100] *= 3.0; // an outlier the trend must ignore
        let with = resonance("with STF", 42.0, 0.2, 250);
        let changes = [
            Some(RegimeChange {
                omega: 30.0,
                uncertainty: 1.0,
            }),
            Some(RegimeChange {
                omega: 50.0,
                uncertainty: 0.5,
            }),
        ];
        let dir = tempfile::tempdir().unwrap();
        let smoothing = Smoothing::default();
        let curves = [measured.clone(), without.clone(), with];
        let files =
            frequency_response(dir.path(), "frf", &curves, changes, &smoothing, "mm").unwrap();
        let cols = assert_rendered(&files, SIZE_WIDE);
        assert_eq!(cols.len(), 9);
        // One legend entry per curve (its trend and its maxima share it), regimes named.
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        for label in ["measured", "without STF", "with STF"] {
            assert_eq!(svg.matches(&format!(">\n{label}\n<")).count(), 1, "{label}");
        }
        for regime in ["pre-resonance", "resonance", "post-resonance"] {
            assert_eq!(
                svg.matches(&format!(">\n{regime}\n<")).count(),
                1,
                "{regime}"
            );
        }
        // x in mm; the record's trend smoothed, a simulation's through its maxima (its peak
        // kept whole).
        let mm = |c: &FrfCurve| c.x_peak.iter().map(|x| x * 1e3).collect::<Vec<f64>>();
        assert_eq!(column(&cols, "measured: ω, rad/s"), &measured.omega[..]);
        assert_eq!(
            column(&cols, "measured: local maximum of x, mm"),
            &mm(&measured)[..]
        );
        let trend = column(&cols, "measured: trend, mm");
        assert_eq!(trend, &smooth_trend(&mm(&measured), &smoothing)[..]);
        assert!(
            trend[100] < 1.5 * mm(&measured)[99],
            "outlier leaked into the trend"
        );
        assert_eq!(column(&cols, "without STF: trend, mm"), &mm(&without)[..]);
        assert_eq!(column(&cols, "with STF: ω, rad/s").len(), 250);
    }

    #[test]
    fn no_curve_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let err = frequency_response(
            dir.path(),
            "f",
            &[],
            [None, None],
            &Smoothing::default(),
            "mm",
        )
        .unwrap_err();
        assert!(matches!(err, ReportError::NoData { .. }), "{err}");
    }
}
