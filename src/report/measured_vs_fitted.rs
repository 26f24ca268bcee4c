//! Measured against modelled signal over time, on one axis, so the reader sees where a model
//! misses: the STF force of a record and each model's fitted force, or (trajectory level) the
//! measured displacement and the oscillator simulated with each model.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::colour::series_colour;
use super::decimate::{decimate_union, pick, MAX_POINTS_PER_LINE};
use super::envelope::{band, buckets_for, dense, envelope};
use super::figure::{
    axis_desc_style, draw_line, draw_mesh, draw_runs, legend_strip, model_entries_flagged, msg,
    one_panel, render, require_finite, same_as_earlier, same_length, titled, Chart2d, Draw,
    FigureFiles, Swatch, MEASURED_GREY, MEASURED_LINE, MEASURED_WIDTH, SIZE_WIDE, T_LABEL,
};
use super::plot_range::{exact_range, padded_range};
use super::series_csv::Column;
use super::ReportError;
use stf_study::shown_units::ShownUnits;

/// What a measured-vs-modelled figure shows: its title, the quantity with its unit (axis and
/// CSV columns) and what the model curves are.
#[derive(Clone, Copy, Debug)]
pub struct Quantity {
    /// Figure title.
    pub title: &'static str,
    /// The quantity and its unit, e.g. `F_STF, N`.
    pub label: &'static str,
    /// What a model curve is: `fitted` or `simulated`.
    pub model_word: &'static str,
    /// Legend and CSV name of the grey band: `measured`, or what stands in its place.
    pub band: &'static str,
}

impl Quantity {
    /// The quantity labelled in the record's own units: a displacement of a record whose x is
    /// a voltage in mV, the STF force in V where the record's force is a voltage
    /// ([`ShownUnits::force_si`]), every other label as it is.
    pub fn in_units(self, units: &ShownUnits) -> Quantity {
        let volts = units.force_si == "V";
        let label = match (units.is_voltage(), self.label) {
            (true, "x, mm") => "x, mV",
            (true, "x residual, mm") => "x residual, mV",
            (_, "F_STF, N") if volts => "F_STF, V",
            (_, "F_STF residual, N") if volts => "F_STF residual, V",
            (_, label) => label,
        };
        Quantity { label, ..self }
    }
}

/// The STF force against each model's fitted force.
pub const STF_FORCE: Quantity = Quantity {
    title: "STF force: measured and fitted",
    label: "F_STF, N",
    model_word: "fitted",
    band: "measured",
};

/// The STF force residual (measured − modelled, N) of a base model, drawn as the band,
/// against the final model's.
pub const STF_FORCE_RESIDUAL: Quantity = Quantity {
    title: "STF force residual: measured − modelled",
    label: "F_STF residual, N",
    model_word: "fitted",
    band: "base",
};

/// The displacement against the oscillator simulated with each model (values in mm).
pub const DISPLACEMENT_MM: Quantity = Quantity {
    title: "Displacement: measured and simulated",
    label: "x, mm",
    model_word: "simulated",
    band: "measured",
};

/// The STF force of a validation record against each model's prediction from its
/// kinematics, with the parameters fitted on another record.
pub const STF_FORCE_VALIDATION: Quantity = Quantity {
    title: "Validation record: STF force measured and predicted",
    label: "F_STF, N",
    model_word: "predicted",
    band: "measured",
};

/// The displacement of a validation record against the oscillator simulated with each model
/// as fitted on another record (values in mm).
pub const DISPLACEMENT_VALIDATION_MM: Quantity = Quantity {
    title: "Validation record: displacement measured and predicted",
    label: "x, mm",
    model_word: "predicted",
    band: "measured",
};

/// The displacement residual (measured − simulated, mm) of a base model, drawn as the band,
/// against the final model's.
pub const DISPLACEMENT_RESIDUAL_MM: Quantity = Quantity {
    title: "Displacement residual: measured − simulated",
    label: "x residual, mm",
    model_word: "simulated",
    band: "base",
};

struct MeasuredVsFittedPlot {
    quantity: Quantity,
    t: Vec<f64>,
    measured: Vec<f64>,
    fitted: Vec<(String, Vec<f64>)>,
}

impl MeasuredVsFittedPlot {
    /// A record of hundreds of cycles: the measured envelope as a grey band, each model's as
    /// its upper and lower edge (the cycles themselves are in the regime windows).
    fn draw_envelopes<DB: DrawingBackend>(
        &self,
        chart: &mut Chart2d<'_, DB>,
    ) -> Result<(), String> {
        let buckets = buckets_for(&self.measured);
        let measured = envelope(&self.t, &self.measured, buckets);
        chart
            .draw_series([Polygon::new(band(&measured), MEASURED_GREY.filled())])
            .map_err(msg)?;
        for (i, (_, f)) in self.fitted.iter().enumerate() {
            let colour = series_colour(i);
            let edges = envelope(&self.t, f, buckets);
            let upper = edges.iter().map(|&(t, _, hi)| (t, hi));
            draw_line(chart, upper, colour.stroke_width(2))?;
            let lower = edges.iter().map(|&(t, lo, _)| (t, lo));
            draw_line(chart, lower, colour.stroke_width(2))?;
        }
        Ok(())
    }

    /// The legend, above the plot: every line spans the whole time axis, so no corner of the
    /// plot is free of data.
    fn legend_entries(&self) -> Vec<(String, Swatch)> {
        let suffix = if dense(&self.measured) {
            " (envelope)"
        } else {
            ""
        };
        let band = format!("{}{suffix}", self.quantity.band);
        let labels: Vec<&str> = self.fitted.iter().map(|(l, _)| l.as_str()).collect();
        let curves: Vec<&[f64]> = self.fitted.iter().map(|(_, f)| f.as_slice()).collect();
        let models = model_entries_flagged(&labels, &same_as_earlier(&curves), suffix);
        std::iter::once((band, Swatch::Line(MEASURED_LINE, 2)))
            .chain(models)
            .collect()
    }
}

impl Draw for MeasuredVsFittedPlot {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let no_data = || "measured vs fitted: no finite value".to_string();
        let t_range = exact_range(&self.t).ok_or_else(no_data)?;
        let f_range = padded_range(
            self.measured
                .iter()
                .chain(self.fitted.iter().flat_map(|(_, f)| f)),
        )
        .ok_or_else(no_data)?;
        let root = legend_strip(&titled(root, self.quantity.title)?, &self.legend_entries())?;
        let mut chart = one_panel(&root)
            .build_cartesian_2d(t_range.clone(), f_range.clone())
            .map_err(msg)?;
        let desc = (T_LABEL, self.quantity.label);
        draw_mesh(&mut chart, desc, None, axis_desc_style())?;
        if dense(&self.measured) {
            return self.draw_envelopes(&mut chart);
        }
        let measured = (self.t.as_slice(), self.measured.as_slice());
        draw_runs(
            &mut chart,
            measured,
            MEASURED_LINE.stroke_width(MEASURED_WIDTH),
        )?;
        for (i, (_, f)) in self.fitted.iter().enumerate() {
            let style = series_colour(i).stroke_width(2);
            draw_runs(&mut chart, (&self.t, f), style)?;
        }
        Ok(())
    }
}

/// Draw the measured `quantity` and each model's (`(model label, values)`) over time `t` (s)
/// to `out_dir/name.{svg,png,csv}`. The CSV holds t, the measured values and one column per
/// model, as plotted.
pub fn measured_vs_model(
    out_dir: &Path,
    name: &str,
    quantity: Quantity,
    t: &[f64],
    measured: &[f64],
    fitted: &[(&str, impl AsRef<[f64]>)],
) -> Result<FigureFiles, ReportError> {
    same_length("measured vs fitted: t and measured", t, measured)?;
    for (label, f) in fitted {
        same_length(&format!("measured vs fitted: t and {label}"), t, f.as_ref())?;
    }
    let what = format!("measured {}", quantity.label);
    require_finite("measured vs fitted", &[(&what, measured)])?;
    let mut all: Vec<&[f64]> = vec![measured];
    all.extend(fitted.iter().map(|(_, f)| f.as_ref()));
    let keep = decimate_union(&all, MAX_POINTS_PER_LINE);
    let plot = MeasuredVsFittedPlot {
        quantity,
        t: pick(t, &keep),
        measured: pick(measured, &keep),
        fitted: fitted
            .iter()
            .map(|(label, f)| (label.to_string(), pick(f.as_ref(), &keep)))
            .collect(),
    };
    let mut columns = vec![
        Column::new("t, s", plot.t.clone()),
        Column::new(
            format!("{} {}", quantity.band, quantity.label),
            plot.measured.clone(),
        ),
    ];
    columns.extend(plot.fitted.iter().map(|(label, f)| {
        Column::new(
            format!("{label}: {} {}", quantity.model_word, quantity.label),
            f.clone(),
        )
    }));
    render(out_dir, name, SIZE_WIDE, &plot, &columns)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::test_signals::{assert_rendered, column, damped_sine};

    #[test]
    fn renders_measured_and_two_models() {
        let s = damped_sine(3_000, 3.0);
        let linear: Vec<f64> = s.v.iter().map(|v| 25.0 * v).collect();
        let quadratic: Vec<f64> = s.v.iter().map(|v| 20.0 * v + 400.0 * v * v.abs()).collect();
        let dir = tempfile::tempdir().unwrap();
        let files = measured_vs_model(
            dir.path(),
            "fit",
            STF_FORCE,
            &s.t,
            &s.f,
            &[("linear", &linear), ("power law", &quadratic)],
        )
        .unwrap();
        let cols = assert_rendered(&files, SIZE_WIDE);
        assert_eq!(column(&cols, "measured F_STF, N"), &s.f[..]);
        assert_eq!(column(&cols, "power law: fitted F_STF, N"), &quadratic[..]);
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        assert!(
            svg.contains("power law") && svg.contains("measured"),
            "legend"
        );
    }

    #[test]
    fn a_displacement_figure_says_displacement_not_force() {
        let s = damped_sine(1_000, 2.0);
        let x_mm: Vec<f64> = s.x.iter().map(|x| x * 1e3).collect();
        let dir = tempfile::tempdir().unwrap();
        let files = measured_vs_model(
            dir.path(),
            "x",
            DISPLACEMENT_MM,
            &s.t,
            &x_mm,
            &[("base", &x_mm)],
        )
        .unwrap();
        let cols = assert_rendered(&files, SIZE_WIDE);
        assert_eq!(column(&cols, "measured x, mm"), &x_mm[..]);
        assert_eq!(column(&cols, "base: simulated x, mm"), &x_mm[..]);
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        assert!(svg.contains("Displacement") && !svg.contains("STF force"));
    }
}
