//! The oscillator's own parameters and the reference sets of the source study, and
//! [`OscParam`], the name of one of them: a parameter is read and set by that type
//! (`system[OscParam::K]`); its text (`k`, `delta_T`) is parsed once, where a user's setting
//! is checked.

use std::fmt;
use std::ops::{Index, IndexMut};
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Mass, stiffness and bearing resistance of the trolley, and the rotor's unbalance.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct OscillatorParams {
    /// Moving mass, kg.
    pub m: f64,
    /// Spring stiffness, N/m.
    pub k: f64,
    /// Viscous bearing resistance, N·s/m.
    pub c: f64,
    /// Dynamic dry friction, N.
    #[serde(rename = "T")]
    pub t_friction: f64,
    /// Extra static friction at rest, N (decays as 1/(1 + η|v|)).
    #[serde(rename = "delta_T")]
    pub delta_t: f64,
    /// Unbalance m0·e of the rotor, kg·m.
    #[serde(rename = "F0")]
    pub f0: f64,
    /// Decay rate of static friction with speed, s/m; also sets the smoothing ε = 1e-3/η.
    pub eta: f64,
    /// A constant force on the trolley, N, on the side of the STF force:
    /// `m·ẍ + k·x + F_R + F_STF + f_off = drive`. A force sensor's or a rig's static offset;
    /// with a nonlinear force it is not the same as a displacement offset.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub f_off: f64,
    /// The rotor angle's zero offset, rad: the drive is `F0·ω²·sin(φ − phi_off)`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub phi_off: f64,
    /// The measured drive force's offset, N: the drive is `u(t) − u_off`. On a shaker rig it is
    /// the same term as `f_off` (a fit refuses to free both).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub u_off: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

impl OscillatorParams {
    /// The source study's identification from the forced frequency sweeps.
    pub const FORCED: OscillatorParams = OscillatorParams {
        m: 7.650,
        k: 269.9346,
        c: 3.6839,
        t_friction: 0.5424,
        delta_t: 0.0947,
        f0: 0.0462,
        eta: 1e3,
        f_off: 0.0,
        phi_off: 0.0,
        u_off: 0.0,
    };

    /// The source study's identification from free vibration (no rotor, no static excess).
    pub const FREE: OscillatorParams = OscillatorParams {
        k: 267.9245,
        c: 4.3736,
        t_friction: 0.4190,
        delta_t: 0.0,
        f0: 0.0,
        ..Self::FORCED
    };

    /// Names of the parameters, in the order of [`OscillatorParams::to_vec`].
    pub const NAMES: [&'static str; 10] = [
        "m", "k", "c", "T", "delta_T", "F0", "eta", "f_off", "phi_off", "u_off",
    ];

    /// A preset by name: `forced` or `free`.
    pub fn preset(name: &str) -> Option<OscillatorParams> {
        match name {
            "forced" => Some(Self::FORCED),
            "free" => Some(Self::FREE),
            _ => None,
        }
    }

    /// The values in the order of [`OscillatorParams::NAMES`].
    pub fn to_vec(&self) -> [f64; 10] {
        OscParam::ALL.map(|p| self[p])
    }

    /// The parameter named `name` (text not yet parsed into an [`OscParam`]); `None` if there
    /// is none of that name.
    pub fn get(&self, name: &str) -> Option<f64> {
        name.parse::<OscParam>().ok().map(|p| self[p])
    }
}

/// One of the oscillator's parameters, in the order of [`OscillatorParams::NAMES`]; its text
/// is that name (`FromStr`, `Display`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum OscParam {
    /// `m`, moving mass, kg.
    M,
    /// `k`, spring stiffness, N/m.
    K,
    /// `c`, viscous bearing resistance, N·s/m.
    C,
    /// `T`, dynamic dry friction, N.
    T,
    /// `delta_T`, extra static friction at rest, N.
    DeltaT,
    /// `F0`, the rotor's unbalance, kg·m.
    F0,
    /// `eta`, decay rate of static friction with speed, s/m.
    Eta,
    /// `f_off`, a constant force on the trolley, N.
    FOff,
    /// `phi_off`, the rotor angle's zero offset, rad.
    PhiOff,
    /// `u_off`, the measured drive force's offset, N.
    UOff,
}

impl OscParam {
    /// Every parameter, in the order of [`OscillatorParams::NAMES`].
    pub const ALL: [OscParam; 10] = [
        OscParam::M,
        OscParam::K,
        OscParam::C,
        OscParam::T,
        OscParam::DeltaT,
        OscParam::F0,
        OscParam::Eta,
        OscParam::FOff,
        OscParam::PhiOff,
        OscParam::UOff,
    ];

    /// The parameter's name (`delta_T`).
    pub fn name(self) -> &'static str {
        OscillatorParams::NAMES[self as usize]
    }

    /// The parameter's SI unit.
    pub fn unit(self) -> &'static str {
        const UNITS: [&str; 10] = [
            "kg", "N/m", "N·s/m", "N", "N", "kg·m", "s/m", "N", "rad", "N",
        ];
        UNITS[self as usize]
    }

    /// An offset: an additive term that starts at 0 and may take either sign.
    pub fn is_offset(self) -> bool {
        matches!(self, OscParam::FOff | OscParam::PhiOff | OscParam::UOff)
    }
}

/// A name that is no oscillator parameter; the message lists the known ones.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
#[error("`{0}` is not an oscillator parameter; known: {known}", known = OscillatorParams::NAMES.join(", "))]
pub struct UnknownOscParam(pub String);

impl FromStr for OscParam {
    type Err = UnknownOscParam;

    fn from_str(name: &str) -> Result<Self, Self::Err> {
        OscParam::ALL
            .into_iter()
            .find(|p| p.name() == name)
            .ok_or_else(|| UnknownOscParam(name.to_string()))
    }
}

impl fmt::Display for OscParam {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Index<OscParam> for OscillatorParams {
    type Output = f64;

    fn index(&self, p: OscParam) -> &f64 {
        match p {
            OscParam::M => &self.m,
            OscParam::K => &self.k,
            OscParam::C => &self.c,
            OscParam::T => &self.t_friction,
            OscParam::DeltaT => &self.delta_t,
            OscParam::F0 => &self.f0,
            OscParam::Eta => &self.eta,
            OscParam::FOff => &self.f_off,
            OscParam::PhiOff => &self.phi_off,
            OscParam::UOff => &self.u_off,
        }
    }
}

impl IndexMut<OscParam> for OscillatorParams {
    fn index_mut(&mut self, p: OscParam) -> &mut f64 {
        match p {
            OscParam::M => &mut self.m,
            OscParam::K => &mut self.k,
            OscParam::C => &mut self.c,
            OscParam::T => &mut self.t_friction,
            OscParam::DeltaT => &mut self.delta_t,
            OscParam::F0 => &mut self.f0,
            OscParam::Eta => &mut self.eta,
            OscParam::FOff => &mut self.f_off,
            OscParam::PhiOff => &mut self.phi_off,
            OscParam::UOff => &mut self.u_off,
        }
    }
}

impl Default for OscillatorParams {
    fn default() -> Self {
        Self::FORCED
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_parameter_reads_back_by_its_name_and_its_place() {
        let values = OscillatorParams::FORCED.to_vec();
        let mut p = OscillatorParams::FORCED;
        for (i, param) in OscParam::ALL.into_iter().enumerate() {
            assert_eq!(param.name(), OscillatorParams::NAMES[i]);
            assert_eq!(param.to_string().parse::<OscParam>(), Ok(param));
            assert_eq!(p[param], values[i]);
            p[param] = i as f64 + 0.5;
            assert_eq!(p.to_vec()[i], i as f64 + 0.5);
            assert_eq!(p.get(param.name()), Some(i as f64 + 0.5));
        }
        // Each name reaches its own field, in the order of NAMES.
        let by_field = OscillatorParams {
            m: 0.5,
            k: 1.5,
            c: 2.5,
            t_friction: 3.5,
            delta_t: 4.5,
            f0: 5.5,
            eta: 6.5,
            f_off: 7.5,
            phi_off: 8.5,
            u_off: 9.5,
        };
        assert_eq!(p, by_field);
        assert_eq!(values[3], OscillatorParams::FORCED.t_friction);
        let offsets: Vec<&str> = OscParam::ALL
            .into_iter()
            .filter(|p| p.is_offset())
            .map(OscParam::name)
            .collect();
        assert_eq!(offsets, ["f_off", "phi_off", "u_off"]);
        assert_eq!(OscParam::DeltaT.unit(), "N");
    }

    #[test]
    fn an_unknown_name_lists_the_known_ones() {
        let e = "stiffness".parse::<OscParam>().unwrap_err();
        assert_eq!(
            e.to_string(),
            "`stiffness` is not an oscillator parameter; known: m, k, c, T, delta_T, F0, eta, \
             f_off, phi_off, u_off"
        );
        assert_eq!(OscillatorParams::FORCED.get("stiffness"), None);
    }
}
