//! `compare.md` of `stf-lab compare`, also printed on the terminal: the record's cycles and
//! boundaries (with how far they move with the zero-force level), each model's relative force RMS error (duty error) per regime with its
//! simulated resonance peak, the best model per regime, the loop metrics, the on–off
//! behaviour a model misses and the warnings against its fit. Its `- ` bullets open the
//! report's regimes section. A record without a rotor has no regimes: its table is over the
//! whole record, with no loop metrics by regime.

use std::fmt::Write as _;

use stf_core::regimes::{Boundary, Regime, ZeroLevelSpread};

use crate::experiment::Experiment;
use crate::fitting::FitData;
use stf_study::compare::Compared;
use stf_study::rig_words::RigWords;
use stf_study::shown_units::ShownUnits;

/// What the duty and its error are, with the record's on-threshold (in the record's force
/// unit `unit`: N, or V for a force read in volts), in the words of its rig (a rotor's cycles
/// and regimes, or the periods of the whole record).
pub fn duty_meaning(on_threshold: f64, words: RigWords, unit: &str) -> String {
    let (piece, over) = if words.regimes {
        ("cycle", "a regime's cycles")
    } else {
        ("period", "the record's periods")
    };
    format!(
        "The duty of a {piece} is the fraction of it in which the STF force is on (|F_STF| above \
         {on_threshold:.3} {unit}, the record's on-threshold): 1 for a force that only passes \
         through zero, below 1 for on–off spikes with rest between them; the duty error is the \
         mean over {over} of |model duty − measured duty|."
    )
}

/// How the boundaries move with the zero-force level: the level used, each boundary at half
/// and twice it, and the range each spans; forces in the record's unit `unit`.
pub fn zero_level_line(z: &ZeroLevelSpread, unit: &str) -> String {
    let omega = |b: Option<Boundary>| b.map_or("none".to_string(), |b| format!("{:.2}", b.omega));
    let levels: Vec<String> = z
        .at_levels
        .iter()
        .map(|l| {
            format!(
                "at {:.3} {unit} ({}×) onset {}, resonance → post-resonance {}",
                l.zero_level,
                l.factor,
                omega(l.boundaries.pre_resonance),
                omega(l.boundaries.resonance_post)
            )
        })
        .collect();
    let range = |name: &str, r: Option<[f64; 2]>| {
        r.map(|[lo, hi]| format!("the {name} boundary lies within ω {lo:.2}–{hi:.2} rad/s"))
    };
    let ranges: Vec<String> = [
        range("onset", z.pre_resonance_range),
        range("resonance → post-resonance", z.resonance_post_range),
    ]
    .into_iter()
    .flatten()
    .collect();
    format!(
        "zero force level {:.3} {unit} ({}); recomputed {}: over these levels, with each one's \
         ±, {}",
        z.zero_level,
        z.zero_level_rule,
        levels.join("; "),
        if ranges.is_empty() {
            "no boundary is found".to_string()
        } else {
            ranges.join(", ")
        }
    )
}

/// The whole of compare.md.
pub fn compare_markdown(exp: &Experiment, data: &FitData, c: &Compared) -> String {
    let mut md = String::new();
    let measured = &c.measured;
    let _ = writeln!(md, "# Model comparison: {}\n", exp.path.display());
    let _ = writeln!(
        md,
        "Record `{}`: {} {}; noise floor σ = {:.4} {}{}.\n",
        data.record.source,
        measured.labels.len(),
        data.words().cycles,
        measured.noise_sigma,
        data.units.force_si,
        if measured.no_stf && data.words().regimes {
            "; the STF force is negligible everywhere (no regimes)"
        } else {
            ""
        }
    );
    if !data.words().regimes {
        whole_record_table(&mut md, c, &data.units);
        misses_and_warnings(&mut md, c, false);
        return md;
    }
    for line in crate::documents::compare_loops::boundary_lines(measured) {
        let _ = writeln!(md, "- {line}");
    }
    if let Some(z) = &c.zero_level {
        let _ = writeln!(md, "- {}", zero_level_line(z, data.units.force_si));
    }
    errors_table(&mut md, c, &data.units);
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
    let energy =
        crate::documents::compare_loops::energy_table(&c.labels(), &c.comparisons, &data.units);
    crate::documents::compare_loops::write_markdown(&mut md, &c.loop_rankings, &energy);
    misses_and_warnings(&mut md, c, true);
    md
}

/// A record without a rotor: each model's relative force RMS error (duty error) over the
/// whole record and the largest |x| simulated with it, in the record's units.
fn whole_record_table(md: &mut String, c: &Compared, units: &ShownUnits) {
    let x_unit = units.x;
    let _ = writeln!(
        md,
        "\nRelative force RMS error (duty error) over the whole record; lower is better. {}\n",
        duty_meaning(c.measured.on_threshold, RigWords::ROTORLESS, units.force_si)
    );
    let _ = writeln!(md, "| model | whole record | peak x ({x_unit}) |");
    let _ = writeln!(md, "|---|---|---|");
    for ((f, cmp), p) in c.fits.iter().zip(&c.comparisons).zip(c.peaks()) {
        let o = &cmp.overall;
        let peak = p.map_or("simulation failed".to_string(), |(x, _)| {
            format!("{:.2}", x * 1e3)
        });
        let _ = writeln!(
            md,
            "| {} | {:.3} ({:.2}) | {peak} |",
            f.label, o.relative_rms_error, o.duty_error
        );
    }
    let _ = writeln!(
        md,
        "| *measured* | | {:.2} |\n",
        c.measured_peak.amplitude * 1e3
    );
}

/// The table of relative force RMS error (duty error) per regime and the simulated peak.
fn errors_table(md: &mut String, c: &Compared, units: &ShownUnits) {
    let x_unit = units.x;
    let _ = writeln!(
        md,
        "\nRelative force RMS error (duty error) per regime and its mean over the regimes, the \
         score the models are ranked by; lower is better. {}\n",
        duty_meaning(c.measured.on_threshold, RigWords::ROTOR, units.force_si)
    );
    let _ = writeln!(
        md,
        "| model | pre-resonance | resonance | post-resonance | mean over regimes | peak x ({x_unit}) at ω |"
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
fn misses_and_warnings(md: &mut String, c: &Compared, regimes: bool) {
    for (f, cmp) in c.fits.iter().zip(&c.comparisons) {
        let groups: Vec<(String, Option<&stf_core::regimes::RegimeMetrics>)> = if regimes {
            let name = |r: Regime| r.name().replace('_', "-");
            Regime::ALL
                .iter()
                .map(|&r| (name(r), cmp.per_regime.get(r)))
                .collect()
        } else {
            vec![("the whole record".to_string(), Some(&cmp.overall))]
        };
        for (group, m) in groups {
            if let Some(m) = m.filter(|m| m.duty_error > 0.2) {
                let _ = writeln!(
                    md,
                    "- {} misses the on–off behaviour in {group}: duty {:.2} against the measured {:.2}",
                    f.label,
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
