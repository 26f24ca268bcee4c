//! Records that cannot be what the experiment file says they are, caught before anything is
//! fitted: a time column in the wrong unit, a displacement in mm read as m, a `[data] rate`
//! that disagrees with the record's own `t` column. The estimation record and the `[validate]`
//! record are checked alike.
//!
//! Clearly impossible records are refused with what looks wrong and the `[data] units` key
//! that likely fixes it; merely suspicious ones — among them the scales of
//! [`crate::plausible_scale`]: a motion too fast or too small for the units declared — give
//! warnings (printed, and in
//! `discovery.json`'s notes). The sample-rate check needs the frequency the record must
//! resolve: the rotor's (its ω), else the natural frequency of a configured `[system]`, which
//! is unit-consistent in any unit system. The displacement checks use the trolley's sizes, so
//! they apply to records of the rotor rig (φ or ω present, docs/ARCHITECTURE.md §1) only:
//! shaker records driven by `u` may come from other rigs in volts (x of 0.1–1 V read as m,
//! m ≈ 1, k ≈ 1e5 in volt units), which these sizes do not fit. Every check is switched off
//! by `[data] plausibility = false`.

use anyhow::{bail, Result};
use stf_core::data::record::{ReadOptions, Record, TimeBase};

use crate::experiment::Experiment;

/// Longest plausible record, s: three days.
pub const MAX_DURATION: f64 = 3.0 * 86_400.0;
/// A record longer than this (one day) is suspicious.
pub const LONG_DURATION: f64 = 86_400.0;
/// Largest plausible displacement of the trolley, m.
pub const MAX_X: f64 = 1.0;
/// A displacement beyond this is suspicious on the trolley, m.
pub const LARGE_X: f64 = 0.25;
/// A sample rate above this is suspicious, Hz.
pub const HIGH_RATE: f64 = 1e6;
/// Relative disagreement between `[data] rate` and the `t` column that is flagged.
pub const RATE_TOLERANCE: f64 = 0.01;

/// Check `record` (read from `file` with `exp`'s layout): an error for an impossible record,
/// else the warnings for a suspicious one.
pub fn check(exp: &Experiment, file: &std::path::Path, record: &Record) -> Result<Vec<String>> {
    if !exp.data_plausibility {
        return Ok(Vec::new());
    }
    let mut warnings = Vec::new();
    let name = file.display();
    let off = "(`[data] plausibility = false` turns this check off)";
    let (n, t) = (record.t.len(), &record.t);
    if n >= 2 {
        let span = t[n - 1] - t[0];
        let rate = (n - 1) as f64 / span;
        let t_key = "`[data] units = { t = \"ms\" }` (or \"us\")";
        if span > MAX_DURATION {
            bail!(
                "{name}: the record spans {span:.4e} s ({:.3e} days), beyond what a rig records \
                 ({} days): its time is likely in ms or µs read as s; set {t_key} {off}",
                span / 86_400.0,
                MAX_DURATION / 86_400.0
            );
        }
        if let Some(f) = drive_frequency(exp, record).filter(|f| rate < 2.0 * f) {
            bail!(
                "{name}: {rate:.4} samples per second is below twice the {what} frequency \
                 ({f:.4} Hz): no record of this rig can be that coarse; is its time in ms or µs \
                 read as s? set {t_key} {off}",
                what = if record.omega.is_some() {
                    "rotor's"
                } else {
                    "oscillator's natural"
                },
            );
        }
        if span > LONG_DURATION {
            warnings.push(format!(
                "{name}: the record spans {:.2} days: is its time in ms read as s (`[data] units`)?",
                span / 86_400.0
            ));
        }
        if rate > HIGH_RATE {
            warnings.push(format!(
                "{name}: {rate:.4e} samples per second: is its time in s read as ms or µs \
                 (`[data] units.t`)?"
            ));
        }
    }
    check_x(record, &name.to_string(), off, &mut warnings)?;
    warnings.extend(crate::plausible_scale::too_fast(
        exp,
        record,
        &name.to_string(),
    ));
    warnings.extend(crate::plausible_scale::too_small(
        exp,
        record,
        &name.to_string(),
    ));
    if let Some(w) = rate_against_column(exp, file, record) {
        warnings.push(w);
    }
    Ok(warnings)
}

/// The frequency a record must resolve, Hz: the rotor's fastest (from its ω column), else the
/// configured oscillator's natural frequency — when the oscillator is configured, not taken
/// from the record.
fn drive_frequency(exp: &Experiment, record: &Record) -> Option<f64> {
    let tau = std::f64::consts::TAU;
    if let Some(w) = &record.omega {
        let peak = w.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        return (peak > 0.0 && peak.is_finite()).then_some(peak / tau);
    }
    let configured = exp.system_given || rotor(record);
    configured.then(|| (exp.system.k / exp.system.m).sqrt() / tau)
}

/// Whether the record is of the rotor rig, the trolley of docs/ARCHITECTURE.md §1.
fn rotor(record: &Record) -> bool {
    record.phi.is_some() || record.omega.is_some()
}

/// x (read in metres) on the rotor rig: beyond [`MAX_X`] refused, beyond [`LARGE_X`] a
/// warning.
fn check_x(record: &Record, name: &str, off: &str, warnings: &mut Vec<String>) -> Result<()> {
    if !rotor(record) {
        return Ok(());
    }
    let mut sorted: Vec<f64> = record.x.iter().copied().filter(|v| v.is_finite()).collect();
    if sorted.is_empty() {
        return Ok(());
    }
    sorted.sort_by(f64::total_cmp);
    let centre = sorted[sorted.len() / 2];
    let peak = sorted
        .iter()
        .fold(0.0_f64, |m, v| m.max((v - centre).abs()));
    if peak > MAX_X {
        bail!(
            "{name}: x moves {peak:.4} m from its median, beyond what this rig can ({MAX_X} m): \
             x is likely in mm or µm read as m; set `[data] units = {{ x = \"mm\" }}` (or \"um\") \
             {off}"
        );
    }
    if peak > LARGE_X {
        warnings.push(format!(
            "{name}: x moves {peak:.4} m from its median: is it in mm read as m (`[data] units.x`)?"
        ));
    }
    Ok(())
}

/// With `[data] rate`, the record's own `t` column (if it has one) read as seconds: a warning
/// when its step disagrees with the rate by more than [`RATE_TOLERANCE`].
fn rate_against_column(
    exp: &Experiment,
    file: &std::path::Path,
    record: &Record,
) -> Option<String> {
    let TimeBase::Rate { rate, .. } = exp.data_layout.time else {
        return None;
    };
    let mut opts: ReadOptions = exp.data_layout.clone();
    opts.time = TimeBase::Column;
    let with_t = opts.read(file).ok()?;
    let n = with_t.t.len().min(record.t.len());
    let step = with_t.sample_step()?;
    let column_rate = 1.0 / step;
    let off = ((column_rate - rate) / rate).abs();
    (n >= 2 && column_rate.is_finite() && off > RATE_TOLERANCE).then(|| {
        format!(
            "{}: `[data] rate` is {rate} Hz, but the record's `t` column steps {step:.6e} s \
             ({column_rate:.6} Hz, {:.3}× the rate): is the rate, or the column's unit, wrong?",
            file.display(),
            column_rate / rate
        )
    })
}
