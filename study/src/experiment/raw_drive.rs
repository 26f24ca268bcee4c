//! How a filter of a measured drive is written, in `[data] drive` and `[filter] motion` /
//! `omega`: a name (`"auto"`, `"none"`, …) or a table of polynomial order and window. Both
//! sections read it; `filter.rs` checks it.

use serde::Deserialize;

/// A filter as written: polynomial order and window (samples).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFilterSpec {
    /// The polynomial order.
    pub order: usize,
    /// The window, samples.
    pub window: usize,
}

/// A `[data] drive` value as written.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum RawDrive {
    Named(String),
    Filter(RawFilterSpec),
}
