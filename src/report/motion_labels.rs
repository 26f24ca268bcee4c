//! The labels of a record's motion on figures' axes and in their CSV columns, in the record's
//! own units: mm, mm/s and m/s² for the trolley's displacement, mV, mV/s and V/s² for an x
//! that is a voltage (an electronic oscillator's output). The plotted numbers are the same
//! either way (x and v in thousandths of the record's unit, a in its unit per s²). The STF
//! force is labelled in the record's unit of force: N, or V where the force is a voltage
//! read with a gain of 1 ([`ShownUnits::force_si`]).

use stf_study::shown_units::ShownUnits;

/// Axis labels and CSV column names of x, v and a.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionLabels {
    /// Axis label of x.
    pub x: &'static str,
    /// Axis label of v.
    pub v: &'static str,
    /// Axis label of a.
    pub a: &'static str,
    /// CSV column of x.
    pub x_column: &'static str,
    /// CSV column of v.
    pub v_column: &'static str,
    /// CSV column of a.
    pub a_column: &'static str,
    /// Unit of x as shown: `mm` or `mV`.
    pub x_unit: &'static str,
    /// Unit of v as shown: `mm/s` or `mV/s`.
    pub v_unit: &'static str,
    /// Unit of a as shown: `m/s²` or `V/s²`.
    pub a_unit: &'static str,
    /// Axis label and CSV column of the STF force: `F_STF, N` or `F_STF, V`.
    pub force: &'static str,
    /// Unit of the STF force: `N` or `V`.
    pub force_unit: &'static str,
}

impl MotionLabels {
    /// The trolley's: x in mm.
    pub const LENGTH: MotionLabels = MotionLabels {
        x: "displacement x, mm",
        v: "velocity v, mm/s",
        a: "acceleration a, m/s²",
        x_column: "x, mm",
        v_column: "v, mm/s",
        a_column: "a, m/s²",
        x_unit: "mm",
        v_unit: "mm/s",
        a_unit: "m/s²",
        force: "F_STF, N",
        force_unit: "N",
    };

    /// A record whose x is a voltage.
    pub const VOLTAGE: MotionLabels = MotionLabels {
        x: "x, mV",
        v: "dx/dt, mV/s",
        a: "d²x/dt², V/s²",
        x_column: "x, mV",
        v_column: "v, mV/s",
        a_column: "a, V/s²",
        x_unit: "mV",
        v_unit: "mV/s",
        a_unit: "V/s²",
        force: "F_STF, N",
        force_unit: "N",
    };

    /// The labels of a record shown in `units`.
    pub fn of(units: &ShownUnits) -> MotionLabels {
        let motion = if units.is_voltage() {
            MotionLabels::VOLTAGE
        } else {
            MotionLabels::LENGTH
        };
        if units.force_si == "V" {
            MotionLabels {
                force: "F_STF, V",
                force_unit: "V",
                ..motion
            }
        } else {
            motion
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_force_is_labelled_in_the_records_unit_of_force() {
        assert_eq!(MotionLabels::of(&ShownUnits::LENGTH).force, "F_STF, N");
        assert_eq!(MotionLabels::of(&ShownUnits::VOLTAGE).force, "F_STF, N");
        let volts = ShownUnits {
            force_si: "V",
            ..ShownUnits::VOLTAGE
        };
        let labels = MotionLabels::of(&volts);
        assert_eq!((labels.force, labels.force_unit), ("F_STF, V", "V"));
        assert_eq!(labels.x, "x, mV");
    }
}
