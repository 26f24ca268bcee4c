//! Numerics: the methods the rest of the crate builds on, knowing nothing of the rig — ODE
//! integration, interpolation of sampled signals, the sliding polynomial derivative filter,
//! phase unwrapping, the rebuilding of a measured drive as a smooth signal and a fast sine
//! for the rotor's drive.

pub mod derivative;
pub mod integrate;
pub mod interpolate;
pub mod reconstruct;
pub mod sine;
pub mod unwrap;
