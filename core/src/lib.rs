//! stf-core: the physics and numerics of stf-lab.
//!
//! A trolley of mass `m` on springs `k`, shaken by an unbalanced rotor, drags a blade through a
//! shear-thickening fluid (STF):
//!
//! ```text
//! m·ẍ + k·x + F_R(ẋ) + F_STF = F0·ω²·sin φ
//! ```
//!
//! The crate is layered; each layer uses only those below it (docs/ARCHITECTURE.md §2):
//!
//! - [`numerics`]: integration, interpolation, the derivative filter, phase unwrapping and
//!   the rebuilding of a measured drive as a smooth signal;
//! - [`physics`]: the oscillator and its parameters, excitations, bearing resistance and the
//!   seam through which any STF model plugs in ([`physics::force_model`]);
//! - [`data`]: records and their I/O, kinematics, the recovered force, capped reading of
//!   outside input and what is estimated from a record;
//! - the workflows: [`simulate`] (runs and synthetic records), [`fit`], [`regimes`] and
//!   [`discovery`].
//!
//! It knows no scripting language, no command line and no experiment-file layout.
//!
//! ```
//! use stf_core::physics::{excitation::{Excitation, RotorAngle}, oscillator::Oscillator,
//!                         oscillator_params::OscillatorParams};
//! use stf_core::simulate::Simulation;
//! let osc = Oscillator::new(OscillatorParams::FORCED,
//!                           Excitation::Rotor(RotorAngle::constant(4.0)));
//! let run = Simulation::new(&osc).rate(100.0).run(0.0, 2.0).unwrap();
//! assert_eq!(run.t.len(), 201);
//! ```

#![deny(clippy::unwrap_used)]
// `!(a > b)` is how this crate says "not greater, or NaN": the NaN case is meant.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod data;
pub mod digits;
pub mod discovery;
pub mod fit;
mod model_error;
pub mod names;
pub mod numerics;
pub mod physics;
pub mod regimes;
pub mod simulate;
