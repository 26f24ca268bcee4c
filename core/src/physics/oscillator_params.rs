//! The oscillator's own parameters and the reference sets of the source study.

use serde::{Deserialize, Serialize};

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
        m: 7.650,
        k: 267.9245,
        c: 4.3736,
        t_friction: 0.4190,
        delta_t: 0.0,
        f0: 0.0,
        eta: 1e3,
        f_off: 0.0,
        phi_off: 0.0,
        u_off: 0.0,
    };

    /// Names of the parameters, in the order of [`OscillatorParams::to_vec`].
    pub const NAMES: [&'static str; 10] = [
        "m", "k", "c", "T", "delta_T", "F0", "eta", "f_off", "phi_off", "u_off",
    ];

    /// The offsets among [`OscillatorParams::NAMES`]: additive terms that start at 0 and may
    /// take either sign.
    pub const OFFSETS: [&'static str; 3] = ["f_off", "phi_off", "u_off"];

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
        [
            self.m,
            self.k,
            self.c,
            self.t_friction,
            self.delta_t,
            self.f0,
            self.eta,
            self.f_off,
            self.phi_off,
            self.u_off,
        ]
    }

    /// Set a parameter by name; false if there is none of that name.
    pub fn set(&mut self, name: &str, value: f64) -> bool {
        match name {
            "m" => self.m = value,
            "k" => self.k = value,
            "c" => self.c = value,
            "T" => self.t_friction = value,
            "delta_T" => self.delta_t = value,
            "F0" => self.f0 = value,
            "eta" => self.eta = value,
            "f_off" => self.f_off = value,
            "phi_off" => self.phi_off = value,
            "u_off" => self.u_off = value,
            _ => return false,
        }
        true
    }

    /// Get a parameter by name.
    pub fn get(&self, name: &str) -> Option<f64> {
        Self::NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| self.to_vec()[i])
    }

    /// Natural frequency √(k/m), rad/s.
    pub fn natural_frequency(&self) -> f64 {
        (self.k / self.m).sqrt()
    }
}

impl Default for OscillatorParams {
    fn default() -> Self {
        Self::FORCED
    }
}
