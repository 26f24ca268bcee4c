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
use super::decimate::{decimate_union, pick};
use super::figure::{
    draw_line, draw_mesh, finite_points, legend_strip, model_entries_flagged, msg, render,
    same_as_earlier, same_length, small_panel, tick_style, titled, Draw, FigureFiles, Swatch,
    ONE_COLUMN, TWO_COLUMNS,
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
    /// What a group of samples is, for the title: `regime`, or `third of the record` for a
    /// record without regimes.
    pub group: &'static str,
}

const BINS: usize = 40;
const GREY: RGBColor = RGBColor(120, 120, 120);
/// The most points a group's scatter draws over all models: its samples are decimated
/// together, keeping each one's extremes of the measured value and of every residual.
pub const MAX_SCATTER_POINTS: usize = 6_000;

/// One group as drawn: the scatter's samples (decimated) and the residuals' histograms (of
/// every sample).
struct PlottedGroup {
    name: String,
    /// The measured values of the samples drawn.
    measured: Vec<f64>,
    /// Per model, its values at the samples drawn.
    fitted: Vec<Vec<f64>>,
    /// The histograms' range, if any residual is finite.
    range: Option<Range<f64>>,
    /// Per model, the density of its residual in each of [`BINS`] bins over `range`.
    histograms: Vec<Vec<f64>>,
}

struct ParityPlot<'a> {
    quantity: &'a ParityQuantity,
    groups: Vec<PlottedGroup>,
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

impl ParityPlot<'_> {
    fn parity<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        g: &PlottedGroup,
    ) -> Result<(), String> {
        let (name, measured, fitted) = (&g.name, &g.measured, &g.fitted);
        let range = padded_range(measured.iter().chain(fitted.iter().flatten()))
            .ok_or_else(|| format!("{name}: no finite value"))?;
        let mut chart = small_panel(area, Some(name))
            .build_cartesian_2d(range.clone(), range.clone())
            .map_err(msg)?;
        let label = &self.quantity.label;
        let desc = (format!("measured {label}"), format!("fitted {label}"));
        draw_mesh(&mut chart, desc, Some((5, 5)), tick_style())?;
        for (i, f) in fitted.iter().enumerate() {
            let colour = series_colour(i).mix(0.35).filled();
            chart
                .draw_series(
                    finite_points(measured, f)
                        .into_iter()
                        .map(|p| Circle::new(p, 2, colour)),
                )
                .map_err(msg)?;
        }
        let diagonal = [(range.start, range.start), (range.end, range.end)];
        draw_line(&mut chart, diagonal, BLACK.stroke_width(1))
    }

    fn residuals<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        g: &PlottedGroup,
    ) -> Result<(), String> {
        let (name, histograms) = (&g.name, &g.histograms);
        let range = g
            .range
            .clone()
            .ok_or_else(|| format!("{name}: no finite residual"))?;
        let width = (range.end - range.start) / BINS as f64;
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
        // Short enough for a third of two columns; the axis's ends say where residuals are
        // left off.
        let x_desc = format!("residual {}", self.quantity.label);
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
        let labels: Vec<&str> = self.models.iter().map(|(l, _)| *l).collect();
        let drawn: Vec<Vec<f64>> = (0..labels.len())
            .map(|i| {
                self.groups
                    .iter()
                    .flat_map(|g| g.fitted[i].clone())
                    .collect()
            })
            .collect();
        let curves: Vec<&[f64]> = drawn.iter().map(Vec::as_slice).collect();
        let mut entries = model_entries_flagged(&labels, &same_as_earlier(&curves), "");
        if self.quantity.noise_sigma.is_some_and(|s| s > 0.0) {
            entries.push(("noise floor".into(), Swatch::Line(GREY, 3)));
        }
        entries
    }
}

impl Draw for ParityPlot<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let title = format!(
            "Measured against fitted, and the residual's distribution, by {}",
            self.quantity.group
        );
        let root = legend_strip(&titled(root, &title)?, &self.legend_entries())?;
        let cells = root.split_evenly((2, self.groups.len()));
        let n = self.groups.len();
        for (k, group) in self.groups.iter().enumerate() {
            self.parity(&cells[k], group)?;
            self.residuals(&cells[n + k], group)?;
        }
        Ok(())
    }
}

/// A group as drawn: its samples decimated for the scatter (each model's share of
/// [`MAX_SCATTER_POINTS`], keeping the extremes of the measured value and of every residual;
/// the indices returned) and the histograms of every sample's residual.
fn plotted_group(
    g: &SampleGroup,
    measured: &[f64],
    models: &[(&str, &[f64])],
    sigma: Option<f64>,
) -> (PlottedGroup, Vec<usize>) {
    let m = pick(measured, &g.samples);
    let fitted: Vec<Vec<f64>> = models.iter().map(|(_, f)| pick(f, &g.samples)).collect();
    let residuals = residuals_of(&m, &fitted);
    let range = histogram_range(&residuals, sigma);
    let histograms = match &range {
        Some(r) => residuals.iter().map(|res| density(res, r)).collect(),
        None => Vec::new(),
    };
    // Residuals with NaN where a value is missing, aligned with the samples.
    let aligned: Vec<Vec<f64>> = fitted
        .iter()
        .map(|f| m.iter().zip(f).map(|(a, b)| a - b).collect())
        .collect();
    let mut series: Vec<&[f64]> = vec![&m];
    series.extend(aligned.iter().map(Vec::as_slice));
    let keep = decimate_union(&series, MAX_SCATTER_POINTS / models.len().max(1));
    let rows = pick_indices(&g.samples, &keep);
    let group = PlottedGroup {
        name: g.name.clone(),
        measured: pick(&m, &keep),
        fitted: fitted.iter().map(|f| pick(f, &keep)).collect(),
        range,
        histograms,
    };
    (group, rows)
}

/// `indices[keep[k]]` for each k.
fn pick_indices(indices: &[usize], keep: &[usize]) -> Vec<usize> {
    keep.iter()
        .filter_map(|&k| indices.get(k).copied())
        .collect()
}

/// The CSV of the figure: the scatter's rows (group number, measured, each model) and each
/// group's histograms (group number, bin centre, each model's density).
fn parity_columns(
    quantity: &ParityQuantity,
    measured: &[f64],
    models: &[(&str, &[f64])],
    plotted: &[(PlottedGroup, Vec<usize>)],
) -> Vec<Column> {
    let label = &quantity.label;
    let rows: Vec<usize> = plotted
        .iter()
        .flat_map(|(_, r)| r.iter().copied())
        .collect();
    let mut columns = vec![
        Column::numbered("group", plotted.iter().map(|(_, r)| r.len())),
        Column::new(format!("measured {label}"), pick(measured, &rows)),
    ];
    columns.extend(
        models
            .iter()
            .map(|(name, f)| Column::new(format!("{name} {label}"), pick(f, &rows))),
    );
    let binned: Vec<&PlottedGroup> = plotted
        .iter()
        .map(|(g, _)| g)
        .filter(|g| g.range.is_some())
        .collect();
    let centres = binned.iter().flat_map(|g| {
        let r = g.range.clone().unwrap_or(0.0..0.0);
        let width = (r.end - r.start) / BINS as f64;
        (0..BINS).map(move |b| r.start + width * (b as f64 + 0.5))
    });
    columns.push(Column::numbered(
        "histogram group",
        binned.iter().map(|_| BINS),
    ));
    columns.push(Column::new(
        format!("residual bin centre, {label}"),
        centres.collect(),
    ));
    columns.extend(models.iter().enumerate().map(|(i, (name, _))| {
        let density = binned.iter().flat_map(|g| g.histograms[i].iter().copied());
        Column::new(format!("{name} residual density"), density.collect())
    }));
    columns
}

/// Draw, for each group of samples, the parity plot of every model (`(label, fitted)`)
/// against `measured` and the histogram of its residual with the noise floor's normal
/// curve, to `out_dir/name.{svg,png,csv}`. A group's scatter is decimated (at most
/// [`MAX_SCATTER_POINTS`] over its models, every extreme of the measured value and of each
/// residual kept); its histograms count every sample. The CSV holds the scatter as drawn (the
/// group's number, the measured value and each model's) and the histograms (the group's
/// number, each bin's centre and each model's density).
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
    let plotted: Vec<(PlottedGroup, Vec<usize>)> = groups
        .iter()
        .map(|g| plotted_group(g, measured, models, quantity.noise_sigma))
        .collect();
    let columns = parity_columns(quantity, measured, models, &plotted);
    let width = if plotted.len() > 1 {
        TWO_COLUMNS
    } else {
        ONE_COLUMN
    };
    let size = (width, 800);
    let plot = ParityPlot {
        quantity,
        groups: plotted.into_iter().map(|(g, _)| g).collect(),
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
            group: "regime",
            noise_sigma: Some(0.0015),
        };
        let dir = tempfile::tempdir().unwrap();
        let models = [
            ("power law", good.as_slice()),
            ("linear", linear.as_slice()),
        ];
        let files = parity(dir.path(), "parity", &quantity, &s.f, &models, &groups).unwrap();
        let cols = assert_rendered(&files, (TWO_COLUMNS, 800));
        assert_eq!(column(&cols, "measured F_STF, N"), &s.f[..]);
        assert_eq!(column(&cols, "linear F_STF, N"), &linear[..]);
        assert_eq!(column(&cols, "group")[1_500], 2.0);
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        assert!(svg.contains("\nsecond half\n") && svg.contains("\nnoise floor\n"));
    }

    #[test]
    fn a_million_samples_are_drawn_and_written_decimated_with_their_extremes() {
        let s = damped_sine(1_000_000, 100.0);
        let mut model: Vec<f64> = s.v.iter().map(|v| 20.0 * v + 400.0 * v * v.abs()).collect();
        let mut f = s.f.clone();
        // A spike in the measured force and one in the model's, where nothing else is extreme.
        f[123_457] = 3.0;
        model[654_321] = -2.5;
        let groups = [
            SampleGroup {
                name: "early".into(),
                samples: (0..500_000).collect(),
            },
            SampleGroup {
                name: "late".into(),
                samples: (500_000..1_000_000).collect(),
            },
        ];
        let quantity = ParityQuantity {
            label: "F_STF, N".into(),
            group: "regime",
            noise_sigma: Some(0.0015),
        };
        let dir = tempfile::tempdir().unwrap();
        let models = [("power law", model.as_slice())];
        let files = parity(dir.path(), "parity", &quantity, &f, &models, &groups).unwrap();
        let cols = assert_rendered(&files, (TWO_COLUMNS, 800));
        let measured = column(&cols, "measured F_STF, N");
        assert!(
            measured.len() <= 2 * MAX_SCATTER_POINTS,
            "{} rows",
            measured.len()
        );
        let fitted = column(&cols, "power law F_STF, N");
        assert!(measured.contains(&3.0) && fitted.contains(&-2.5));
        let extreme = |v: &[f64], pick: fn(f64, f64) -> f64| v.iter().copied().reduce(pick);
        assert_eq!(extreme(measured, f64::min), extreme(&f, f64::min));
        // Every sample counts in the histograms: each density integrates to at most 1 and
        // the best model's to nearly 1.
        let density = column(&cols, "power law residual density");
        let centres = column(&cols, "residual bin centre, F_STF, N");
        assert_eq!((density.len(), centres.len()), (2 * BINS, 2 * BINS));
        let width = centres[1] - centres[0];
        let mass: f64 = density[..BINS].iter().sum::<f64>() * width;
        assert!(mass > 0.9 && mass <= 1.0 + 1e-9, "{mass}");
        let bytes = std::fs::metadata(&files.csv).unwrap().len();
        assert!(bytes < 2_000_000, "parity.csv is {bytes} bytes");
    }
}
