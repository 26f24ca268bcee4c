//! `compare.md` of `stf-lab compare`, also printed on the terminal: the record's cycles and
//! boundaries, each model's relative force RMS error (duty error) per regime with its
//! simulated resonance peak, the best model per regime, the loop metrics, the on–off
//! behaviour a model misses and the warnings against its fit. Its `- ` bullets open the
//! report's regimes section.

use std::fmt::Write as _;

use stf_core::regimes::Regime;

use crate::experiment::Experiment;
use crate::fitting::FitData;
use stf_study::compare::Compared;

/// What the duty and its error are, with the record's on-threshold.
pub fn duty_meaning(on_threshold: f64) -> String {
    format!(
        "The duty of a cycle is the fraction of it in which the STF force is on (|F_STF| above \
         {on_threshold:.3} N, the record's on-threshold): 1 for a force that only passes through \
         zero, below 1 for on–off spikes with rest between them; the duty error is the mean over \
         a regime's cycles of |model duty − measured duty|."
    )
}

/// The whole of compare.md.
pub fn compare_markdown(exp: &Experiment, data: &FitData, c: &Compared) -> String {
    let mut md = String::new();
    let measured = &c.measured;
    let _ = writeln!(md, "# Model comparison: {}\n", exp.path.display());
    let _ = writeln!(
        md,
        "Record `{}`: {} cycles; noise floor σ = {:.4} N{}.\n",
        data.record.source,
        measured.labels.len(),
        measured.noise_sigma,
        if measured.no_stf {
            "; the STF force is negligible everywhere (no regimes)"
        } else {
            ""
        }
    );
    for line in crate::documents::compare_loops::boundary_lines(measured) {
        let _ = writeln!(md, "- {line}");
    }
    errors_table(&mut md, c);
    for r in Regime::ALL {
        if let Some(b) = c.ranking.best_in(r) {
            let _ = writeln!(md, "- best in {}: **{b}**", r.name().replace('_', "-"));
        }
    }
    if let Some(b) = c.ranking.best_overall() {
        let _ = writeln!(
            md,
            "- best over the regimes (mean of the per-regime errors): **{b}**"
        );
    }
    let energy = crate::documents::compare_loops::energy_table(&c.labels(), &c.comparisons);
    crate::documents::compare_loops::write_markdown(&mut md, &c.loop_rankings, &energy);
    misses_and_warnings(&mut md, c);
    md
}

/// The table of relative force RMS error (duty error) per regime and the simulated peak.
fn errors_table(md: &mut String, c: &Compared) {
    let _ = writeln!(
        md,
        "\nRelative force RMS error (duty error) per regime and its mean over the regimes, the \
         score the models are ranked by; lower is better. {}\n",
        duty_meaning(c.measured.on_threshold)
    );
    let _ = writeln!(
        md,
        "| model | pre-resonance | resonance | post-resonance | mean over regimes | peak x (mm) at ω |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|");
    for ((f, cmp), p) in c.fits.iter().zip(&c.comparisons).zip(c.peaks()) {
        let mut row = format!("| {} ", f.label);
        for r in Regime::ALL {
            match cmp.per_regime.get(r) {
                Some(m) => {
                    let _ = write!(row, "| {:.3} ({:.2}) ", m.relative_rms_error, m.duty_error);
                }
                None => row.push_str("| — "),
            }
        }
        match c.mean_error(&f.label) {
            Some(score) => {
                let _ = write!(row, "| {score:.3} ");
            }
            None => row.push_str("| — "),
        }
        match p {
            Some((x, w)) => {
                let _ = write!(row, "| {:.2} at {:.2} |", x * 1e3, w);
            }
            None => row.push_str("| simulation failed |"),
        }
        let _ = writeln!(md, "{row}");
    }
    let _ = writeln!(
        md,
        "| *measured* | | | | | {:.2} at {:.2} |\n",
        c.measured_peak.amplitude * 1e3,
        c.measured_peak.omega
    );
}

/// The on–off behaviour each model misses (a duty error above 0.2 in a regime), then the
/// fits not to be trusted as they stand (`*` bullets: the report shows them in its own box).
fn misses_and_warnings(md: &mut String, c: &Compared) {
    for (f, cmp) in c.fits.iter().zip(&c.comparisons) {
        for r in Regime::ALL {
            if let Some(m) = cmp.per_regime.get(r).filter(|m| m.duty_error > 0.2) {
                let _ = writeln!(
                    md,
                    "- {} misses the on–off behaviour in {}: duty {:.2} against the measured {:.2}",
                    f.label,
                    r.name().replace('_', "-"),
                    m.model_duty,
                    m.measured_duty
                );
            }
        }
    }
    let warned: Vec<String> = c
        .fits
        .iter()
        .flat_map(|f| {
            f.warnings
                .iter()
                .map(move |w| format!("* {}: {w}", f.label))
        })
        .collect();
    if !warned.is_empty() {
        let _ = writeln!(md, "\n**Warnings**\n\n{}", warned.join("\n"));
    }
}
