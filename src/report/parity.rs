//! Measured against fitted, regime by regime: on top, a parity plot (each sample's fitted
//! value against its measured one, the line y = x where they agree); under it the residual's
//! distribution (measured − fitted) per model as a histogram outline, beside the normal curve
//! of the noise floor. A model that misses an effect shows a tilted cloud and a residual wider
//! than the noise; one at the noise shows a band along y = x and the noise's bell.

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::series_colour;
use super::decimate::pick;
use super::figure::{
    draw_line, draw_mesh, legend_strip, model_entries, msg, render, same_length, small_panel,
    tick_label, tick_style, titled, Draw, FigureFiles, Swatch,
};
use super::plot_range::padded_range;
use super::series_csv::Column;
use super::ReportError;

/// A group of samples scored together (a regime): its name and the samples' indices.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SampleGroup {
    /// Its name, e.g. `resonance`.
    pub name: String,
    /// The samples, increasing.
    pub samples: Vec<usize>,
}

/// What the values are: the quantity with its unit (`F_STF, N`) and the noise floor σ in the
/// same unit, if known.
#[derive(Clone, Debug, PartialEq)]
pub struct ParityQuantity {
    /// Quantity and unit.
    pub label: String,
    /// The noise floor σ, drawn as the normal curve under the histograms.
    pub noise_sigma: Option<f64>,
}

const BINS: usize = 40;
const GREY: RGBColor = RGBColor(120, 120, 120);

struct ParityPlot<'a> {
    quantity: &'a ParityQuantity,
    /// Per group: name, measured, and per model the fitted values.
    groups: Vec<(String, Vec<f64>, Vec<Vec<f64>>)>,
    models: &'a [(&'a str, &'a [f64])],
}

/// The residuals' axis: symmetric about 0, wide enough for the best model's residual (4× its
/// RMS) and the noise (6σ) but no wider than the largest residual, so a bad model's tails do
/// not squeeze the good ones into a bin or two. Residuals beyond it are left off (a density
/// over all of them, so a model with wide tails shows a low bell).
fn histogram_range(residuals: &[Vec<f64>], sigma: Option<f64>) -> Option<Range<f64>> {
    let rms = |r: &Vec<f64>| (r.iter().map(|v| v * v).sum::<f64>() / r.len().max(1) as f64).sqrt();
    let best = residuals
        .iter()
        .filter(|r| !r.is_empty())
        .map(rms)
        .fold(f64::INFINITY, f64::min);
    let largest = residuals
        .iter()
        .flatten()
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    if !best.is_finite() {
        return None;
    }
    let wanted = (4.0 * best).max(6.0 * sigma.unwrap_or(0.0));
    let half = wanted.min(largest).max(f64::MIN_POSITIVE);
    Some(-half..half)
}

/// The density histogram of `r` over `range` in [`BINS`] bins (per residual of `r`, so values
/// beyond the range lower the bars).
fn density(r: &[f64], range: &Range<f64>) -> Vec<f64> {
    let width = (range.end - range.start) / BINS as f64;
    let mut h = vec![0.0; BINS];
    for v in r {
        let b = ((v - range.start) / width).floor();
        if (0.0..BINS as f64).contains(&b) {
            h[b as usize] += 1.0 / (r.len() as f64 * width);
        }
    }
    h
}

/// measured − fitted, the finite values, for each model.
fn residuals_of(measured: &[f64], fitted: &[Vec<f64>]) -> Vec<Vec<f64>> {
    fitted
        .iter()
        .map(|f| {
            measured
                .iter()
                .zip(f)
                .map(|(m, f)| m - f)
                .filter(|r| r.is_finite())
                .collect()
        })
        .collect()
}

/// The normal density with σ `s` at `x`.
fn bell(x: f64, s: f64) -> f64 {
    (-0.5 * (x / s).powi(2)).exp() / (s * (2.0 * std::f64::consts::PI).sqrt())
}

/// Every `step`-th index, so a scatter has at most `max` points.
fn thin(n: usize, max: usize) -> impl Iterator<Item = usize> {
    (0..n).step_by(n.div_ceil(max.max(1)).max(1))
}

impl ParityPlot<'_> {
    fn parity<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        (name, measured, fitted): &(String, Vec<f64>, Vec<Vec<f64>>),
    ) -> Result<(), String> {
        let range = padded_range(measured.iter().chain(fitted.iter().flatten()))
            .ok_or_else(|| format!("{name}: no finite value"))?;
        let mut chart = small_panel(area, Some(name))
            .build_cartesian_2d(range.clone(), range.clone())
            .map_err(msg)?;
        let label = &self.quantity.label;
        let desc = (format!("measured {label}"), format!("fitted {label}"));
        draw_mesh(&mut chart, desc, Some((5, 5)), tick_style())?;
        let per_model = 3_000 / fitted.len().max(1);
        for (i, f) in fitted.iter().enumerate() {
            let colour = series_colour(i).mix(0.35).filled();
            chart
                .draw_series(
                    thin(measured.len(), per_model)
                        .filter(|&k| measured[k].is_finite() && f[k].is_finite())
                        .map(|k| Circle::new((measured[k], f[k]), 2, colour)),
                )
                .map_err(msg)?;
        }
        let diagonal = [(range.start, range.start), (range.end, range.end)];
        draw_line(&mut chart, diagonal, BLACK.stroke_width(1))
    }

    fn residuals<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        (name, measured, fitted): &(String, Vec<f64>, Vec<Vec<f64>>),
    ) -> Result<(), String> {
        let residuals = residuals_of(measured, fitted);
        let range = histogram_range(&residuals, self.quantity.noise_sigma)
            .ok_or_else(|| format!("{name}: no finite residual"))?;
        let width = (range.end - range.start) / BINS as f64;
        let histograms: Vec<Vec<f64>> = residuals.iter().map(|r| density(r, &range)).collect();
        let sigma = self.quantity.noise_sigma.filter(|s| *s > 0.0);
        let top = histograms
            .iter()
            .flatten()
            .copied()
            .chain(sigma.map(|s| bell(0.0, s)))
            .fold(0.0_f64, f64::max)
            .max(f64::MIN_POSITIVE)
            * 1.1;
        let span = range.end - range.start;
        let mut chart = small_panel(area, None)
            .build_cartesian_2d(range.clone(), 0.0..top)
            .map_err(msg)?;
        let x_desc = format!(
            "residual (measured − fitted) {}; beyond ±{}: off the plot",
            self.quantity.label,
            tick_label(range.end, span)
        );
        draw_mesh(&mut chart, (x_desc, "density"), Some((5, 4)), tick_style())?;
        for (i, h) in histograms.iter().enumerate() {
            let steps = h.iter().enumerate().flat_map(|(b, d)| {
                let x0 = range.start + b as f64 * width;
                [(x0, *d), (x0 + width, *d)]
            });
            draw_line(&mut chart, steps, series_colour(i).stroke_width(2))?;
        }
        if let Some(s) = sigma {
            let curve = (0..=200).map(|k| {
                let x = range.start + span * k as f64 / 200.0;
                (x, bell(x, s))
            });
            draw_line(&mut chart, curve, GREY.stroke_width(2))?;
        }
        Ok(())
    }

    /// The legend the panels share, above them: each model's colour (its scatter and its
    /// histogram) and the noise floor's curve.
    fn legend_entries(&self) -> Vec<(String, Swatch)> {
        let mut entries = model_entries(self.models.iter().map(|(l, _)| *l), "");
        if self.quantity.noise_sigma.is_some_and(|s| s > 0.0) {
            entries.push(("noise floor".into(), Swatch::Line(GREY, 3)));
        }
        entries
    }
}

impl Draw for ParityPlot<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let title = "Measured against fitted, and the residual's distribution, by regime";
        let root = legend_strip(&titled(root, title)?, &self.legend_entries())?;
        let cells = root.split_evenly((2, self.groups.len()));
        let n = self.groups.len();
        for (k, group) in self.groups.iter().enumerate() {
            self.parity(&cells[k], group)?;
            self.residuals(&cells[n + k], group)?;
        }
        Ok(())
    }
}

/// Draw, for each group of samples, the parity plot of every model (`(label, fitted)`)
/// against `measured` and the histogram of its residual with the noise floor's normal
/// curve, to `out_dir/name.{svg,png,csv}`. The CSV holds the group's number, the measured
/// value and each model's, for every sample of every group.
pub fn parity(
    out_dir: &Path,
    name: &str,
    quantity: &ParityQuantity,
    measured: &[f64],
    models: &[(&str, &[f64])],
    groups: &[SampleGroup],
) -> Result<FigureFiles, ReportError> {
    for (label, f) in models {
        same_length(&format!("parity: measured and {label}"), measured, f)?;
    }
    let groups: Vec<&SampleGroup> = groups
        .iter()
        .filter(|g| !g.samples.is_empty() && g.samples.iter().all(|&i| i < measured.len()))
        .collect();
    if groups.is_empty() || models.is_empty() {
        return Err(ReportError::no_data(
            "parity: no group of samples, or no model",
        ));
    }
    let plotted: Vec<(String, Vec<f64>, Vec<Vec<f64>>)> = groups
        .iter()
        .map(|g| {
            let of = |v: &[f64]| pick(v, &g.samples);
            (
                g.name.clone(),
                of(measured),
                models.iter().map(|(_, f)| of(f)).collect(),
            )
        })
        .collect();
    let rows: Vec<usize> = groups.iter().flat_map(|g| g.samples.clone()).collect();
    let mut columns = vec![
        Column::numbered("group", groups.iter().map(|g| g.samples.len())),
        Column::new(
            format!("measured {}", quantity.label),
            pick(measured, &rows),
        ),
    ];
    columns.extend(
        models
            .iter()
            .map(|(label, f)| Column::new(format!("{label} {}", quantity.label), pick(f, &rows))),
    );
    let size = (480 * plotted.len() as u32 + 40, 900);
    let plot = ParityPlot {
        quantity,
        groups: plotted,
        models,
    };
    render(out_dir, name, size, &plot, &columns)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::test_signals::{assert_rendered, column, damped_sine};

    #[test]
    fn draws_parity_and_residuals_per_group() {
        let s = damped_sine(2_000, 4.0);
        let good: Vec<f64> = s.v.iter().map(|v| 20.0 * v + 400.0 * v * v.abs()).collect();
        let linear: Vec<f64> = s.v.iter().map(|v| 25.0 * v).collect();
        let groups = [
            SampleGroup {
                name: "first half".into(),
                samples: (0..1_000).collect(),
            },
            SampleGroup {
                name: "second half".into(),
                samples: (1_000..2_000).collect(),
            },
        ];
        let quantity = ParityQuantity {
            label: "F_STF, N".into(),
            noise_sigma: Some(0.0015),
        };
        let dir = tempfile::tempdir().unwrap();
        let models = [
            ("power law", good.as_slice()),
            ("linear", linear.as_slice()),
        ];
        let files = parity(dir.path(), "parity", &quantity, &s.f, &models, &groups).unwrap();
        let cols = assert_rendered(&files, (1000, 900));
        assert_eq!(column(&cols, "measured F_STF, N"), &s.f[..]);
        assert_eq!(column(&cols, "linear F_STF, N"), &linear[..]);
        assert_eq!(column(&cols, "group")[1_500], 2.0);
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        assert!(svg.contains("\nsecond half\n") && svg.contains("\nnoise floor\n"));
    }
}
