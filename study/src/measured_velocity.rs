//! A measured velocity beside x: a column `v` of the record, in x's unit per second (m/s for
//! x in m, mm/s for x in mm, …), read with the record's time, window and layout.
//!
//! It is cross-checked against the derivative of x: the least-squares gain `g` of the
//! measured v on the filtered one, and their correlation. When they agree (`g` within
//! [`GAIN_TOLERANCE`] of 1, correlation above [`MIN_CORRELATION`]) the measured v replaces
//! the filtered one in the kinematics (its noise, estimated from it, enters the floors);
//! otherwise the derivative of x is kept and a warning names the likely mistake: a gain near
//! 1 000 or 10 (v in mm/s or cm/s read as x's unit per second), near −1 (the opposite sign),
//! or no relation at all.

use stf_core::data::kinematics::Kinematics;
use stf_core::data::record::{Column, Offset, ReadOptions, Signal};
use stf_core::numerics::derivative::noise_sigma;

/// How far the gain of the measured v on the derivative of x may be from 1.
pub const GAIN_TOLERANCE: f64 = 0.1;
/// The least correlation of the measured v with the derivative of x.
pub const MIN_CORRELATION: f64 = 0.9;

/// The record's `v` column, in SI, cut to `window` (none when the file has no `v`).
pub fn read(
    layout: &ReadOptions,
    file: &std::path::Path,
    window: Option<(f64, f64)>,
) -> Option<Vec<f64>> {
    let opts = layout
        .clone()
        .column(Signal::X, Column::Name("v".into()))
        .offset(Signal::X, Offset::Value(0.0));
    let record = opts.read(file).ok()?;
    let record = match window {
        Some((t0, t1)) => record.slice_time(t0, t1),
        None => record,
    };
    Some(record.x)
}

/// Cross-check `v` (m/s) against the derivative of x in `k`: use it when they agree (the
/// kinematics' v and σ_v become the measured ones), else a warning about `name`.
pub fn use_or_warn(k: &mut Kinematics, v: Vec<f64>, name: &str) -> Option<String> {
    if v.len() != k.v.len() {
        return Some(format!(
            "{name}: its `v` column has {} samples where x has {}: not used",
            v.len(),
            k.v.len()
        ));
    }
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let (vv, dd, vd) = (dot(&v, &v), dot(&k.v, &k.v), dot(&v, &k.v));
    let gain = vd / dd;
    let correlation = vd / (vv * dd).sqrt();
    if (gain - 1.0).abs() <= GAIN_TOLERANCE && correlation >= MIN_CORRELATION {
        k.sigma_v = noise_sigma(&v);
        k.v = v;
        return None;
    }
    let likely = if correlation < MIN_CORRELATION.min(0.5) && correlation > -0.5 {
        "they are unrelated: is `v` another signal?".to_string()
    } else if (gain + 1.0).abs() <= GAIN_TOLERANCE {
        "is its sign the opposite of x's?".to_string()
    } else if (gain / 1000.0 - 1.0).abs() <= GAIN_TOLERANCE {
        "is it in mm/s read in x's unit per second?".to_string()
    } else if (gain / 100.0 - 1.0).abs() <= GAIN_TOLERANCE {
        "is it in cm/s read in x's unit per second?".to_string()
    } else {
        "is its unit x's unit per second?".to_string()
    };
    Some(format!(
        "{name}: the measured `v` is {gain:.4}× the derivative of x (correlation \
         {correlation:.3}): {likely} The derivative of x is used"
    ))
}
