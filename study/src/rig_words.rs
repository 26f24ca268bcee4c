//! Words that fit the rig a record comes from. A rotor's record is cut into the rotor's
//! cycles and its cycles are grouped by regime (pre-resonance, resonance, post-resonance); a
//! record without a rotor (a shaker driven by `u`, a damper on an actuator, an electronic
//! oscillator, a free vibration) has no rotor cycle and no regime: it is cut into periods of
//! its motion, and what is said of it is said of the whole record.

use stf_core::data::record::Record;

/// The words the terminal and the reports use for a record's pieces and their groups.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RigWords {
    /// The pieces a record is cut into: `cycles` (of the rotor) or `periods` (of x).
    pub cycles: &'static str,
    /// All of them together: `all cycles` or `whole record`.
    pub all: &'static str,
    /// Whether the record's pieces are grouped by the rotor's regimes.
    pub regimes: bool,
}

impl RigWords {
    /// A rotor's record.
    pub const ROTOR: RigWords = RigWords {
        cycles: "cycles",
        all: "all cycles",
        regimes: true,
    };

    /// A record without a rotor.
    pub const ROTORLESS: RigWords = RigWords {
        cycles: "periods",
        all: "whole record",
        regimes: false,
    };

    /// The words of `record`: a rotor's when it has a rotor angle or speed.
    pub fn of(record: &Record) -> RigWords {
        if record.phi.is_some() || record.omega.is_some() {
            RigWords::ROTOR
        } else {
            RigWords::ROTORLESS
        }
    }
}
