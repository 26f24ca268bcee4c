//! The measured channels a record carries beside its signals (a control voltage, a
//! temperature): the columns that models' laws name (`F_y = { law = "affine", channel =
//! "u_ctrl" }`) or `[data] channels` lists, read with the record's time, window and layout,
//! in their own units (a law's gain carries the channel's unit). [`Channels`] is what a
//! model's configuration takes to wrap a parameter in its law
//! ([`stf_core::physics::channel_law::ChannelLaw`]).

use std::sync::Arc;

use stf_core::data::record::{Column, Offset, ReadOptions, Signal, Unit};
use stf_core::physics::channel_law::MeasuredChannel;

use crate::experiment::ModelEntry;

/// The channels of one record, by name.
#[derive(Clone, Debug, Default)]
pub struct Channels(Vec<Arc<MeasuredChannel>>);

impl Channels {
    /// No channels (a model with a law is then an error naming the channel).
    pub fn none() -> Self {
        Channels(Vec::new())
    }

    /// These channels.
    pub fn of(channels: Vec<Arc<MeasuredChannel>>) -> Self {
        Channels(channels)
    }

    /// Stand-ins for the channels the laws of `entries` name (each 1 at t = 0), where a
    /// model's parameters are wanted by name without a record (a campaign's columns): the
    /// laws' coefficients are named as on any record; their bounds are not the record's.
    pub fn stand_ins_for(entries: &[ModelEntry]) -> Self {
        Channels(
            named_by(entries)
                .iter()
                .filter_map(|n| MeasuredChannel::new(n, vec![0.0], vec![1.0]).ok())
                .map(Arc::new)
                .collect(),
        )
    }

    /// The channel `name`, if the record has it.
    pub fn get(&self, name: &str) -> Option<&Arc<MeasuredChannel>> {
        self.0.iter().find(|c| c.name() == name)
    }

    /// Their names, in order.
    pub fn names(&self) -> Vec<&str> {
        self.0.iter().map(|c| c.name()).collect()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// The channels the laws of `entries` name, each once, in order of appearance.
pub fn named_by<'a>(entries: impl IntoIterator<Item = &'a ModelEntry>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for entry in entries {
        for law in entry.params.iter().filter_map(|p| p.law.as_ref()) {
            if !out.contains(&law.channel) {
                out.push(law.channel.clone());
            }
        }
    }
    out
}

/// Read the columns `names` of the record `file` (laid out as `layout` says) on its time
/// grid, cut to `window`: an error naming the file and the column when one is missing or not
/// a number.
pub fn read(
    layout: &ReadOptions,
    file: &std::path::Path,
    window: Option<(f64, f64)>,
    names: &[String],
) -> Result<Channels, String> {
    let mut out = Vec::new();
    for name in names {
        let opts = layout
            .clone()
            .column(Signal::X, Column::Name(name.clone()))
            .unit(Signal::X, Unit::si(Signal::X))
            .offset(Signal::X, Offset::Value(0.0));
        let record = opts.read(file).map_err(|e| {
            format!(
                "channel `{name}` (a column a law or `[data] channels` names): cannot read it \
                 from {}: {e}",
                file.display()
            )
        })?;
        let record = match window {
            Some((t0, t1)) => record.slice_time(t0, t1),
            None => record,
        };
        let channel = MeasuredChannel::new(name, record.t, record.x)
            .map_err(|e| format!("{}: {e}", file.display()))?;
        out.push(Arc::new(channel));
    }
    Ok(Channels(out))
}
