//! Physics: the oscillator `m·ẍ + k·x + F_R(ẋ) + F_STF = drive` — its parameters, what drives
//! it, the bearing resistance, and the seam through which any STF force model (alone, or as a
//! sum of models) plugs in, with its named parameters.

pub mod channel_law;
pub mod excitation;
pub mod force_model;
pub mod model_sum;
pub mod oscillator;
pub mod oscillator_params;
pub mod param_spec;
pub mod resistance;
pub mod resolved_model;
#[cfg(test)]
pub(crate) mod test_models;
pub mod track;
