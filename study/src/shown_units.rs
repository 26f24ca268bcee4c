//! The units a record's motion is shown in: the record's own. A record of the trolley (x a
//! length, in any unit the layout reads) is shown in mm, mm/s and mm²; a record whose `x` is a
//! voltage kept as it is (`[data] units = { x = "V" }`, or a gain of exactly 1 V per V: an
//! electronic oscillator such as the Silverbox) is shown in mV, mV/s and mV². The numbers are
//! the same (a thousandth of the record's SI value either way); only the labels follow the
//! record, in the terminal, the JSON's units, the reports and the figures' axes. A record in
//! volts carries its forces in the unit of the force its fits balance: V when that force (the
//! drive `u` at trajectory level, the STF force at force level) too is a voltage read with a
//! gain of 1, else N; parameters' units follow both ([`crate::param_units`]).

use serde::Serialize;
use stf_core::data::record::{ReadOptions, Signal, Unit};

use crate::experiment::FitLevel;

/// The labels of a record's displacement, velocity and squared displacement, and the factor
/// from the record's values to them.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ShownUnits {
    /// Displacement: `mm` or `mV`.
    pub x: &'static str,
    /// Velocity: `mm/s` or `mV/s`.
    pub v: &'static str,
    /// Acceleration: `mm/s²` or `mV/s²`.
    pub a: &'static str,
    /// Squared displacement (the paper's S(μ)): `mm²` or `mV²`.
    pub x_squared: &'static str,
    /// The record's own unit of x, as read: `m` or `V` (the JSON's SI unit of a displacement).
    pub x_si: &'static str,
    /// The record's own unit of force: `N`, or `V` on a record in volts whose fitted force
    /// (the drive at trajectory level, the STF force at force level) is a voltage read with
    /// a gain of 1.
    pub force_si: &'static str,
    /// From the record's values to the shown ones.
    #[serde(skip)]
    pub scale: f64,
}

impl ShownUnits {
    /// A record of the trolley: x a length.
    pub const LENGTH: ShownUnits = ShownUnits {
        x: "mm",
        v: "mm/s",
        a: "mm/s²",
        x_squared: "mm²",
        x_si: "m",
        force_si: "N",
        scale: 1e3,
    };

    /// A record whose x is a voltage kept in volts.
    pub const VOLTAGE: ShownUnits = ShownUnits {
        x: "mV",
        v: "mV/s",
        a: "mV/s²",
        x_squared: "mV²",
        x_si: "V",
        force_si: "N",
        scale: 1e3,
    };

    /// The units the layout's `x` is shown in: volts when x is read in volts with a gain of 1
    /// (no sensor turns it into a length), a length otherwise; on a record in volts, forces
    /// in volts too when the force fits at `level` balance (the drive `u` at trajectory level,
    /// the STF force at force level) is read in volts with a gain of 1.
    pub fn of(layout: &ReadOptions, level: FitLevel) -> ShownUnits {
        let volts = |s: Signal| layout.channel(s).unit == Unit::Volt { gain: 1.0 };
        let force = match level {
            FitLevel::Force => Signal::FStf,
            FitLevel::Trajectory => Signal::U,
        };
        if !volts(Signal::X) {
            ShownUnits::LENGTH
        } else if volts(force) {
            ShownUnits {
                force_si: "V",
                ..ShownUnits::VOLTAGE
            }
        } else {
            ShownUnits::VOLTAGE
        }
    }

    /// The unit errors and gaps are shown in at `level`, and the factor from the record's
    /// values: the force's (N, or V) at force level; at trajectory level the record's own
    /// length (mm, or mV for x in volts).
    pub fn at_level(&self, level: FitLevel) -> (&'static str, f64) {
        match level {
            FitLevel::Force => (self.force_si, 1.0),
            FitLevel::Trajectory => (self.x, self.scale),
        }
    }

    /// Whether x is a voltage.
    pub fn is_voltage(&self) -> bool {
        self.x_si == "V"
    }
}

impl Default for ShownUnits {
    fn default() -> Self {
        ShownUnits::LENGTH
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn x_in_volts_with_unit_gain_is_shown_in_millivolts_and_a_sensor_in_millimetres() {
        let volts = ReadOptions::default().unit(Signal::X, Unit::Volt { gain: 1.0 });
        assert_eq!(
            ShownUnits::of(&volts, FitLevel::Trajectory),
            ShownUnits::VOLTAGE
        );
        let sensor = ReadOptions::default().unit(Signal::X, Unit::Volt { gain: 0.002 });
        assert_eq!(
            ShownUnits::of(&sensor, FitLevel::Trajectory),
            ShownUnits::LENGTH
        );
        let mm = ReadOptions::default().unit(Signal::X, Unit::Millimetre);
        assert_eq!(ShownUnits::of(&mm, FitLevel::Trajectory).x, "mm");
        assert_eq!(ShownUnits::of(&volts, FitLevel::Trajectory).force_si, "N");
    }

    #[test]
    fn a_fitted_force_in_volts_on_a_record_in_volts_carries_the_forces_in_volts() {
        let both = ReadOptions::default()
            .unit(Signal::X, Unit::Volt { gain: 1.0 })
            .unit(Signal::U, Unit::Volt { gain: 1.0 });
        assert_eq!(ShownUnits::of(&both, FitLevel::Trajectory).force_si, "V");
        assert_eq!(ShownUnits::of(&both, FitLevel::Force).force_si, "N");
        let sensor = ReadOptions::default()
            .unit(Signal::X, Unit::Volt { gain: 1.0 })
            .unit(Signal::U, Unit::Volt { gain: 20.0 });
        assert_eq!(ShownUnits::of(&sensor, FitLevel::Trajectory).force_si, "N");
        let metres = ReadOptions::default().unit(Signal::U, Unit::Volt { gain: 1.0 });
        assert_eq!(ShownUnits::of(&metres, FitLevel::Trajectory).force_si, "N");
    }
}
