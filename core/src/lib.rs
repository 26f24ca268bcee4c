//! stf-core: the physics and numerics of stf-lab.
//!
//! A trolley of mass `m` on springs `k`, shaken by an unbalanced rotor, drags a blade through a
//! shear-thickening fluid (STF):
//!
//! ```text
//! m·ẍ + k·x + F_R(ẋ) + F_STF = F0·ω²·sin φ
//! ```
//!
//! This crate holds the oscillator ([`oscillator`]), its excitations ([`excitation`]), the
//! bearing resistance ([`resistance`]), the seam through which any STF model plugs in
//! ([`force_model`]), simulation ([`simulate`]), records and their I/O ([`record`]), signal
//! processing ([`derivative`], [`unwrap`], [`recover`]) and synthetic records ([`synthetic`]).
//! It knows no scripting language, no command line and no experiment-file layout.
//!
//! ```
//! use stf_core::{excitation::{Excitation, RotorAngle}, oscillator::Oscillator,
//!                simulate::Simulation, system::OscillatorParams};
//! let osc = Oscillator::new(OscillatorParams::FORCED,
//!                           Excitation::Rotor(RotorAngle::constant(4.0)));
//! let run = Simulation::new(&osc).rate(100.0).run(0.0, 2.0).unwrap();
//! assert_eq!(run.t.len(), 201);
//! ```

#![deny(clippy::unwrap_used)]
// `!(a > b)` is how this crate says "not greater, or NaN": the NaN case is meant.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod analysis;
pub mod bounded;
pub mod data_bounds;
pub mod derivative;
pub mod discovery;
pub mod estimate;
pub mod excitation;
pub mod fit;
pub mod force_model;
pub mod integrate;
pub mod interpolate;
pub mod kinematics;
pub mod model_sum;
pub mod oscillator;
pub mod params;
pub mod reconstruct;
pub mod record;
pub mod recover;
pub mod regimes;
pub mod resistance;
pub mod simulate;
pub mod synthetic;
pub mod system;
pub mod unwrap;
