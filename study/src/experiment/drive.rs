//! The drive of a `[simulate]` run, one of five tables: the rotor's angle on a linear
//! `sweep`, at a `constant` speed or along a speed `profile`; `free` vibration; or a shaker's
//! `chirp` force. Each raw table checks itself into a [`Drive`] with its time span and the
//! table as written, for the run's sidecar.

use std::ops::Range;

use anyhow::Result;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use stf_core::physics::excitation::RotorAngle;
use toml::Spanned;

use super::Ctx;

/// How the rotor (or nothing) drives a simulation.
#[derive(Clone, Debug)]
pub enum Drive {
    /// The rotor with a prescribed angle.
    Rotor(RotorAngle),
    /// No drive: free vibration from the initial state.
    Free,
    /// A measured-style force `u(t)` (a shaker), recorded in the `u` column.
    Force(Chirp),
}

/// A linear chirp force `u = A·sin(2π·(f0·s + (f1 − f0)·s²/(2·(t1 − t0))))`, `s = t − t0`:
/// the frequency sweeps linearly from `f0` at `t0` to `f1` at `t1`. Read as written (`chirp =
/// { f0, f1, amplitude, t0, t1, hold }`), then checked (`Chirp::check`).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Chirp {
    /// Frequency at `t0`, Hz.
    pub f0: f64,
    /// Frequency at `t1`, Hz.
    pub f1: f64,
    /// Force amplitude A, N.
    pub amplitude: f64,
    /// Start time, s.
    #[serde(default)]
    pub t0: f64,
    /// End time, s.
    pub t1: f64,
    /// `"linear"` (default) or `"zoh"` ([`Chirp::held`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    hold: Option<Hold>,
}

impl Chirp {
    /// The force at time `t`, N.
    pub fn at(&self, t: f64) -> f64 {
        let s = t - self.t0;
        let rate = (self.f1 - self.f0) / (self.t1 - self.t0);
        self.amplitude * (std::f64::consts::TAU * (self.f0 * s + 0.5 * rate * s * s)).sin()
    }

    /// The force is held from each sample to the next (a DAC's zero-order hold), instead of
    /// varying linearly between them.
    pub fn held(&self) -> bool {
        self.hold == Some(Hold::Zoh)
    }
}

/// A checked drive: the drive, its start and end time (s), and its table as written.
pub(super) struct Checked {
    pub drive: Drive,
    pub t0: f64,
    pub t1: f64,
    pub as_json: Value,
}

/// `sweep = { w0, alpha, t0, t1, phi0 }`: ω = w0 + alpha·(t − t0).
#[derive(Debug, Deserialize, Serialize, Clone)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSweep {
    w0: f64,
    alpha: f64,
    t0: f64,
    t1: f64,
    phi0: Option<f64>,
}

impl RawSweep {
    pub(super) fn check(&self) -> Checked {
        let mut angle = RotorAngle::sweep(self.w0, self.alpha, self.t0);
        if let (Some(p), RotorAngle::Sweep { phi0, .. }) = (self.phi0, &mut angle) {
            *phi0 = p;
        }
        Checked {
            drive: Drive::Rotor(angle),
            t0: self.t0,
            t1: self.t1,
            as_json: json!({ "sweep": self }),
        }
    }
}

/// `constant = { omega, t0, t1, phi0 }`.
#[derive(Debug, Deserialize, Serialize, Clone)]
#[serde(deny_unknown_fields)]
pub(super) struct RawConstant {
    omega: f64,
    #[serde(default)]
    t0: f64,
    t1: f64,
    #[serde(default)]
    phi0: f64,
}

impl RawConstant {
    pub(super) fn check(&self) -> Checked {
        let angle = RotorAngle::Constant {
            omega: self.omega,
            phi0: self.phi0,
        };
        Checked {
            drive: Drive::Rotor(angle),
            t0: self.t0,
            t1: self.t1,
            as_json: json!({ "constant": self }),
        }
    }
}

/// `profile = { t = [..], omega = [..], phi0 }`: ω interpolated between the given times.
#[derive(Debug, Deserialize, Serialize, Clone)]
#[serde(deny_unknown_fields)]
pub(super) struct RawProfile {
    t: Vec<f64>,
    omega: Vec<f64>,
    #[serde(default)]
    phi0: f64,
}

impl RawProfile {
    /// At least two times, increasing, each with a speed; errors point at `span`, the
    /// `[simulate]` section.
    pub(super) fn check(&self, cx: &Ctx, span: Range<usize>) -> Result<Checked> {
        let (t, omega) = (&self.t, &self.omega);
        cx.ensure(
            t.len() == omega.len() && t.len() >= 2,
            span.clone(),
            "simulate.profile",
            "`t` and `omega` need the same length, at least 2",
        )?;
        cx.ensure(
            t.windows(2).all(|w| w[1] > w[0]),
            span,
            "simulate.profile.t",
            "times must increase",
        )?;
        let angle = RotorAngle::profile(t.clone(), omega.clone(), self.phi0);
        Ok(Checked {
            drive: Drive::Rotor(angle),
            t0: t[0],
            t1: t[t.len() - 1],
            as_json: json!({ "profile": self }),
        })
    }
}

/// `free = { t1 }`: free vibration from t = 0.
#[derive(Debug, Deserialize, Serialize, Clone)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFree {
    t1: f64,
}

impl RawFree {
    pub(super) fn check(&self) -> Checked {
        Checked {
            drive: Drive::Free,
            t0: 0.0,
            t1: self.t1,
            as_json: json!({ "free": self }),
        }
    }
}

/// How a shaker's amplifier holds each sample of the force.
#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
enum Hold {
    /// Linear between samples (the default).
    Linear,
    /// Held from each sample to the next (a DAC's zero-order hold).
    Zoh,
}

impl Chirp {
    /// Frequencies not negative, a positive amplitude (every number is finite: `finite.rs`);
    /// errors point at the table's line.
    pub(super) fn check(raw: &Spanned<Chirp>, cx: &Ctx) -> Result<Checked> {
        let (at, c) = (raw.span(), raw.get_ref());
        for (name, v) in [("f0", c.f0), ("f1", c.f1)] {
            let key = format!("simulate.chirp.{name}");
            cx.ensure(
                v >= 0.0,
                at.clone(),
                &key,
                format!("{v} is not a valid value"),
            )?;
        }
        cx.ensure(
            c.amplitude > 0.0,
            at,
            "simulate.chirp.amplitude",
            format!("{} must be a positive force, N", c.amplitude),
        )?;
        Ok(Checked {
            drive: Drive::Force(*c),
            t0: c.t0,
            t1: c.t1,
            as_json: json!({ "chirp": c }),
        })
    }
}
