//! The STF force recovered from a record's kinematics.
//!
//! ```text
//! F_STF = drive(t) − f_off − m·ẍ − k·x − F_R(ẋ),
//! drive = F0·ω²·sin(φ − phi_off) (rotor) or u − u_off (shaker)
//! ```
//!
//! The velocity and acceleration come from the derivative filter; its noise passes straight
//! into the recovered force (m·σ_a), which is why [`recovery_noise`] reports that floor.

use crate::physics::excitation::Excitation;
use crate::physics::oscillator_params::OscillatorParams;
use crate::physics::resistance::bearing_resistance;

/// Recovered STF force at each sample, N. `drive` is the driving force at each sample
/// (with its offsets applied, as [`rotor_drive`] gives it); all slices have the same length.
pub fn recover_force(
    p: &OscillatorParams,
    drive: &[f64],
    x: &[f64],
    v: &[f64],
    a: &[f64],
) -> Vec<f64> {
    drive
        .iter()
        .zip(x)
        .zip(v)
        .zip(a)
        .map(|(((&u, &x), &v), &a)| u - p.f_off - p.m * a - p.k * x - bearing_resistance(p, v))
        .collect()
}

/// Rotor drive F0·ω²·sin φ at each sample, N.
pub fn rotor_drive(p: &OscillatorParams, phi: &[f64], omega: &[f64]) -> Vec<f64> {
    phi.iter()
        .zip(omega)
        .map(|(&phi, &w)| Excitation::rotor_force(p, phi, w))
        .collect()
}

/// Standard deviation of the recovered force caused by acceleration noise `sigma_a` (m/s²)
/// and velocity noise `sigma_v` (m/s): the floor below which a recovered force means nothing.
pub fn recovery_noise(p: &OscillatorParams, sigma_a: f64, sigma_v: f64) -> f64 {
    (p.m * sigma_a).hypot(p.c * sigma_v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_equation_of_motion_balances() {
        let p = OscillatorParams::FORCED;
        let (x, v, a, f) = (0.01, 0.2, -1.5, 0.7);
        let drive = p.m * a + p.k * x + bearing_resistance(&p, v) + f;
        let got = recover_force(&p, &[drive], &[x], &[v], &[a]);
        assert!((got[0] - f).abs() < 1e-12);
    }
}
