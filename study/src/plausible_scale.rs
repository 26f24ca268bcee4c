//! Scales no rig records, warned of with the unit mistake that likely made them: a motion
//! far too fast (time in s read as ms: a rotor at 5 000 rad/s, a resonance at 800 Hz) and a
//! displacement far too small for the unit it is declared in (x in m read as mm: a stroke of
//! 0.08 mm). Part of the record checks of [`crate::plausibility`], switched off with them.
//!
//! The speed is the rotor's (its ω column, else its angle over the record) or, without a
//! rotor, that of x's cycles about its median (upward crossings armed by a dip below a tenth
//! of its range). The rotor rig's rotor runs at about 1 Hz, any rig this lab reads below a
//! few hundred Hz: [`MAX_ROTOR_OMEGA`] and [`MAX_FREQUENCY`] leave a factor of ten or more
//! either side, and a time read 1 000× too short lands well beyond them.

use stf_core::data::record::{Record, Signal, Unit};
use stf_core::numerics::unwrap::unwrap_phase;
use stf_core::regimes::cycles::cycles_from_x;

use crate::experiment::Experiment;

/// A rotor faster than this, rad/s (≈ 16 Hz, 950 rpm), is suspicious: the rig's runs at
/// ≈ 1 Hz, and its unbalance would pull 460 N at 100 rad/s.
pub const MAX_ROTOR_OMEGA: f64 = 100.0;
/// A motion whose cycles run faster than this, Hz, is suspicious.
pub const MAX_FREQUENCY: f64 = 250.0;
/// A displacement whose range about its median stays below this share of the unit it is
/// declared in (0.2 mm for mm) is suspicious, for units smaller than the metre.
pub const SMALL_IN_UNIT: f64 = 0.2;

/// A warning when the record moves faster than a rig can: its time likely in s read as ms.
pub fn too_fast(exp: &Experiment, record: &Record, name: &str) -> Option<String> {
    let t_unit = exp.data_layout.channel(Signal::T).unit;
    let fix = time_fix(t_unit);
    if let Some(w) = rotor_speed(record) {
        return (w > MAX_ROTOR_OMEGA).then(|| {
            format!(
                "{name}: the rotor turns at {w:.4} rad/s ({:.4} Hz), far faster than a rig's \
                 rotor ({MAX_ROTOR_OMEGA} rad/s at most): {fix}",
                w / std::f64::consts::TAU
            )
        });
    }
    let f = cycle_frequency(record)?;
    (f > MAX_FREQUENCY).then(|| {
        format!(
            "{name}: x runs through cycles at {f:.4} Hz (ω = {:.4} rad/s), faster than a rig \
             this lab reads ({MAX_FREQUENCY} Hz at most): {fix}",
            f * std::f64::consts::TAU
        )
    })
}

/// A warning when x, declared in a unit smaller than the metre, moves less than
/// [`SMALL_IN_UNIT`] of it: its values likely in m (or a larger unit) read as that unit.
pub fn too_small(exp: &Experiment, record: &Record, name: &str) -> Option<String> {
    let unit = exp.data_layout.channel(Signal::X).unit;
    let (label, larger) = match unit {
        Unit::Centimetre => ("cm", "m"),
        Unit::Millimetre => ("mm", "m (or cm)"),
        Unit::Micrometre => ("µm", "mm (or m)"),
        Unit::Inch => ("in", "m or ft"),
        _ => return None,
    };
    let range = range_about_median(&record.x)?;
    let in_unit = range / unit.scale();
    (in_unit > 0.0 && in_unit < SMALL_IN_UNIT).then(|| {
        format!(
            "{name}: x moves only {in_unit:.4} {label} from its median, declared in {label}: \
             are its values in {larger} read as {label}? (`[data] units.x`)"
        )
    })
}

/// What to check of a time column declared in `unit`.
fn time_fix(unit: Unit) -> String {
    match unit {
        Unit::Millisecond => "is `t` in s read as ms? (`[data] units = { t = \"s\" }`)".into(),
        Unit::Microsecond => "is `t` in ms or s read as µs? (`[data] units.t`)".into(),
        _ => "is the record's time in the unit `[data] units.t` declares?".into(),
    }
}

/// The rotor's speed, rad/s: the peak of its ω column, else its angle's mean rate.
fn rotor_speed(record: &Record) -> Option<f64> {
    if let Some(w) = &record.omega {
        return Some(w.iter().fold(0.0_f64, |m, v| m.max(v.abs())));
    }
    let phi = unwrap_phase(record.phi.as_ref()?);
    let (n, t) = (phi.len(), &record.t);
    (n >= 2 && t[n - 1] > t[0]).then(|| (phi[n - 1] - phi[0]).abs() / (t[n - 1] - t[0]))
}

/// The median frequency of x's cycles about its median, Hz (none with fewer than 3).
fn cycle_frequency(record: &Record) -> Option<f64> {
    let centre = median(&record.x)?;
    let x: Vec<f64> = record.x.iter().map(|v| v - centre).collect();
    let range = range_about_median(&record.x)?;
    let cycles = cycles_from_x(&record.t, &x, 0.1 * range).ok()?;
    let mut f: Vec<f64> = cycles
        .iter()
        .map(|c| c.omega / std::f64::consts::TAU)
        .collect();
    if f.len() < 3 {
        return None;
    }
    f.sort_by(f64::total_cmp);
    Some(f[f.len() / 2])
}

/// The largest |x − median x| (none for an empty or non-finite record).
fn range_about_median(x: &[f64]) -> Option<f64> {
    let centre = median(x)?;
    let r = x.iter().fold(0.0_f64, |m, v| m.max((v - centre).abs()));
    r.is_finite().then_some(r)
}

/// The median of the finite values (none without).
fn median(x: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}
