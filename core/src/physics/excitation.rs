//! What drives the oscillator: the unbalanced rotor or a measured force.
//!
//! The rotor's force is `F0·ω²·sin φ` (the source study's form). Its angle φ(t) is either
//! prescribed — constant ω, a linear sweep, a piecewise-linear ω(t) profile — or measured:
//! samples of a record (wrapped or unwrapped), interpolated by cubic Hermite polynomials with ω
//! from the derivative filter. Rigs driven by a shaker use a measured force `u` (N) instead.

use crate::numerics::interpolate::{Hermite, Linear};
use crate::numerics::sine;
use crate::physics::oscillator_params::OscillatorParams;

/// How the rotor angle φ(t) is given.
#[derive(Clone, Debug)]
pub enum RotorAngle {
    /// Constant speed: φ = φ0 + ω·t.
    Constant {
        /// ω, rad/s.
        omega: f64,
        /// φ at t = 0, rad.
        phi0: f64,
    },
    /// Linear sweep: ω = w0 + α·(t − t0), φ = φ0 + w0·(t − t0) + α·(t − t0)²/2.
    Sweep {
        /// ω at t0, rad/s.
        w0: f64,
        /// Sweep rate, rad/s².
        alpha: f64,
        /// Start time, s.
        t0: f64,
        /// φ at t0, rad.
        phi0: f64,
    },
    /// Piecewise-linear ω(t) through knots; ω is held outside them, φ is its exact integral.
    /// Built by [`RotorAngle::profile`], which integrates φ to every knot once, so that each
    /// evaluation is a binary search and not a sum over the knots before it.
    Profile {
        /// Knot times, s (increasing).
        t: Vec<f64>,
        /// ω at the knots, rad/s.
        omega: Vec<f64>,
        /// φ at each knot, rad (the first is the profile's φ0).
        phi: Vec<f64>,
    },
    /// Measured φ samples, unwrapped, with ω from the derivative filter.
    Measured(Hermite),
}

impl RotorAngle {
    /// Constant ω from φ = 0 at t = 0.
    pub fn constant(omega: f64) -> Self {
        RotorAngle::Constant { omega, phi0: 0.0 }
    }

    /// A linear sweep ω = w0 + α·(t − t0) whose phase is that of a sweep begun from rest,
    /// φ(t0) = w0²/(2α) (so ω = 0.047·t gives φ = 0.0235·t²).
    pub fn sweep(w0: f64, alpha: f64, t0: f64) -> Self {
        let phi0 = if alpha != 0.0 {
            w0 * w0 / (2.0 * alpha)
        } else {
            0.0
        };
        RotorAngle::Sweep {
            w0,
            alpha,
            t0,
            phi0,
        }
    }

    /// A piecewise-linear ω(t) through knots at increasing times `t`, with φ = `phi0` at the
    /// first knot (`t` and `omega` of one length; a shorter `omega` is cut to it).
    pub fn profile(t: Vec<f64>, mut omega: Vec<f64>, phi0: f64) -> Self {
        let n = t.len().min(omega.len());
        omega.truncate(n);
        let mut phi = Vec::with_capacity(n);
        let mut at = phi0;
        for i in 0..n {
            if i > 0 {
                at += 0.5 * (omega[i - 1] + omega[i]) * (t[i] - t[i - 1]);
            }
            phi.push(at);
        }
        let mut t = t;
        t.truncate(n);
        RotorAngle::Profile { t, omega, phi }
    }

    /// Measured samples: unwrapped angle `phi` and speed `omega` at times `t`.
    pub fn measured(t: Vec<f64>, phi: Vec<f64>, omega: Vec<f64>) -> Self {
        RotorAngle::Measured(Hermite::new(t, phi, omega))
    }

    /// φ (rad) and ω (rad/s) at time `t`.
    #[inline]
    pub fn at(&self, t: f64) -> (f64, f64) {
        match self {
            RotorAngle::Constant { omega, phi0 } => (phi0 + omega * t, *omega),
            RotorAngle::Sweep {
                w0,
                alpha,
                t0,
                phi0,
            } => {
                let s = t - t0;
                (phi0 + w0 * s + 0.5 * alpha * s * s, w0 + alpha * s)
            }
            _ => self.tabulated_at(t),
        }
    }

    /// The first time after `t` at which the angle's second derivative may jump: the next knot
    /// of a profile or of measured samples; none for the analytic kinds.
    pub fn next_breakpoint(&self, t: f64) -> Option<f64> {
        match self {
            RotorAngle::Constant { .. } | RotorAngle::Sweep { .. } => None,
            RotorAngle::Profile { t: ts, .. } => {
                crate::numerics::interpolate::next_knot(ts, None, t)
            }
            RotorAngle::Measured(h) => h.next_knot(t),
        }
    }

    /// [`RotorAngle::at`] for the tabulated kinds (kept out of line so that the analytic ones
    /// inline into the right-hand side).
    #[inline(never)]
    fn tabulated_at(&self, t: f64) -> (f64, f64) {
        match self {
            RotorAngle::Profile { t: ts, omega, phi } => profile_at(ts, omega, phi, t),
            RotorAngle::Measured(h) => h.at(t),
            RotorAngle::Constant { .. } | RotorAngle::Sweep { .. } => self.at(t),
        }
    }
}

/// φ and ω of a profile at `t`: the knot before `t` found by binary search, φ there
/// precomputed.
fn profile_at(ts: &[f64], omega: &[f64], phi: &[f64], t: f64) -> (f64, f64) {
    let n = ts.len();
    if n == 0 {
        return (0.0, 0.0);
    }
    if t <= ts[0] {
        return (phi[0] + omega[0] * (t - ts[0]), omega[0]);
    }
    if t >= ts[n - 1] {
        return (phi[n - 1] + omega[n - 1] * (t - ts[n - 1]), omega[n - 1]);
    }
    let i = ts.partition_point(|&x| x <= t).saturating_sub(1).min(n - 2);
    let (ta, tb) = (ts[i], ts[i + 1]);
    let slope = (omega[i + 1] - omega[i]) / (tb - ta);
    let s = t - ta;
    (
        phi[i] + omega[i] * s + 0.5 * slope * s * s,
        omega[i] + slope * s,
    )
}

/// The driving force of the oscillator.
#[derive(Clone, Debug)]
pub enum Excitation {
    /// No drive: free vibration.
    None,
    /// The unbalanced rotor, `F0·ω²·sin φ`.
    Rotor(RotorAngle),
    /// A measured force `u(t)`, N, linearly interpolated.
    Force(Linear),
}

impl Excitation {
    /// The driving force at time `t`, N, for the oscillator's unbalance `F0` (kg·m) and drive
    /// offsets: `F0·ω²·sin(φ − phi_off)` for a rotor, `u(t) − u_off` for a measured force.
    #[inline(always)]
    pub fn force(&self, t: f64, p: &OscillatorParams) -> f64 {
        match self {
            Excitation::None => 0.0,
            Excitation::Rotor(_) => self.force_and_angle(t, p).0,
            Excitation::Force(u) => u.at(t) - p.u_off,
        }
    }

    /// The driving force at `t` (N, as [`Excitation::force`]) together with the rotor angle
    /// and speed `(φ, ω)` if a rotor drives the oscillator: one evaluation of the angle for all
    /// three (the same values as [`Excitation::force`], [`Excitation::phi`],
    /// [`Excitation::omega`]).
    #[inline(always)]
    pub fn force_and_angle(&self, t: f64, p: &OscillatorParams) -> (f64, Option<(f64, f64)>) {
        match self {
            Excitation::Rotor(angle) => {
                let (phi, omega) = angle.at(t);
                (Self::rotor_force(p, phi, omega), Some((phi, omega)))
            }
            _ => (self.force(t, p), None),
        }
    }

    /// The rotor's force `F0·ω²·sin(φ − phi_off)`, N, at angle `phi` and speed `omega` (the
    /// one formula of every rotor drive; the sine is [`sine::sin`]).
    #[inline(always)]
    pub fn rotor_force(p: &OscillatorParams, phi: f64, omega: f64) -> f64 {
        p.f0 * omega * omega * sine::sin(phi - p.phi_off)
    }

    /// The first time after `t` at which the driving force stops being smooth (the next knot of
    /// a measured or piecewise-defined drive), if any: an integrator ends a step there rather
    /// than stepping across it.
    pub fn next_breakpoint(&self, t: f64) -> Option<f64> {
        match self {
            Excitation::None => None,
            Excitation::Rotor(angle) => angle.next_breakpoint(t),
            Excitation::Force(u) => u.next_knot(t),
        }
    }

    /// Rotor angle φ (rad) and speed ω (rad/s) at `t`, if a rotor drives the oscillator.
    pub fn angle(&self, t: f64) -> Option<(f64, f64)> {
        match self {
            Excitation::Rotor(angle) => Some(angle.at(t)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn sweep_from_rest_matches_the_reference_phase() {
        let a = RotorAngle::sweep(2.35, 0.047, 50.0);
        for t in [50.0, 120.0, 200.0] {
            let (phi, w) = a.at(t);
            assert_relative_eq!(phi, 0.0235 * t * t, max_relative = 1e-12);
            assert_relative_eq!(w, 0.047 * t, max_relative = 1e-12);
        }
    }

    #[test]
    fn force_and_angle_agrees_with_the_separate_evaluations() {
        let rotor = Excitation::Rotor(RotorAngle::sweep(2.35, 0.047, 50.0));
        for t in [50.0, 77.7, 199.9] {
            let (drive, angle) = rotor.force_and_angle(t, &OscillatorParams::FORCED);
            assert_eq!(drive, rotor.force(t, &OscillatorParams::FORCED));
            assert_eq!(angle, Some(rotor.angle(t).unwrap()));
        }
        let free = Excitation::None;
        assert_eq!(
            free.force_and_angle(3.0, &OscillatorParams::FORCED),
            (0.0, None)
        );
    }

    #[test]
    fn profile_integrates_omega_exactly() {
        let p = RotorAngle::profile(vec![0.0, 10.0, 20.0], vec![1.0, 3.0, 3.0], 0.5);
        let (phi, w) = p.at(5.0);
        assert_relative_eq!(w, 2.0);
        assert_relative_eq!(phi, 0.5 + 5.0 + 0.5 * 0.2 * 25.0);
        let (phi, w) = p.at(25.0);
        assert_relative_eq!(w, 3.0);
        assert_relative_eq!(phi, 0.5 + 20.0 + 30.0 + 15.0);
        assert_eq!(p.at(10.0), (0.5 + 20.0, 3.0));
        assert_eq!(p.at(-1.0), (0.5 - 1.0, 1.0));
    }

    #[test]
    fn a_long_profile_agrees_with_the_sum_over_its_knots() {
        // 100 001 knots: each evaluation is a binary search (it once summed the knots before
        // it, quadratic over a run); the values are the exact integral, checked against a
        // direct sum at a few times.
        let n = 100_001;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.01).collect();
        let omega: Vec<f64> = t.iter().map(|t| 2.0 + (0.3 * t).sin()).collect();
        let p = RotorAngle::profile(t.clone(), omega.clone(), 0.25);
        for probe in [0.005, 1.234, 500.0, 999.995] {
            let k = (probe / 0.01) as usize;
            let mut phi = 0.25;
            for i in 0..k {
                phi += 0.5 * (omega[i] + omega[i + 1]) * (t[i + 1] - t[i]);
            }
            let slope = (omega[k + 1] - omega[k]) / (t[k + 1] - t[k]);
            let s = probe - t[k];
            phi += omega[k] * s + 0.5 * slope * s * s;
            let (got, w) = p.at(probe);
            assert_relative_eq!(got, phi, max_relative = 1e-12);
            assert_relative_eq!(w, omega[k] + slope * s, max_relative = 1e-12);
        }
    }
}
