//! Counts of an experiment file read by serde (`[fit] max_iters`, `[discover] holdout_every`):
//! written as integers or as numbers (`max_iters = 1e3`), whole and at least their least
//! value, else an error that names the key and line like every other (toml places it) instead
//! of a settings struct's dump when the run starts.

use serde::{Deserialize, Deserializer};

/// A whole number of at least `least`.
fn count<'de, D: Deserializer<'de>>(d: D, least: u64, what: &str) -> Result<u64, D::Error> {
    let v = f64::deserialize(d)?;
    if v.fract() == 0.0 && v >= least as f64 && v <= u64::MAX as f64 {
        Ok(v as u64)
    } else {
        Err(serde::de::Error::custom(format!(
            "{v} is not a count of {what} (a whole number, at least {least})"
        )))
    }
}

/// `[fit] max_iters`: at least 1.
pub(super) fn iterations<'de, D: Deserializer<'de>>(d: D) -> Result<Option<u64>, D::Error> {
    count(d, 1, "iterations").map(Some)
}

/// `[discover] holdout_every`: every k-th cycle held out, k at least 2 (k = 1 holds out all).
pub(super) fn holdout<'de, D: Deserializer<'de>>(d: D) -> Result<Option<usize>, D::Error> {
    count(d, 2, "cycles").map(|n| Some(usize::try_from(n).unwrap_or(usize::MAX)))
}
