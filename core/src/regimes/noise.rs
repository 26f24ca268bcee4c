//! The noise floor of a force signal, estimated from the record itself.
//!
//! The estimate is the robust σ of the signal's highest-frequency part: third differences
//! `d = f[i+2] − 3f[i+1] + 3f[i] − f[i−1]` remove any smooth signal (a force that varies on the
//! scale of a rotor cycle contributes ≈ F·(ωΔt)³, negligible at the rates of the rig), while for
//! white noise of σ they have variance 20·σ². The median absolute deviation of `d`, scaled by
//! 1.4826 (MAD → σ of a Gaussian) and divided by √20, is σ; being a median, it ignores the few
//! samples where an on–off force switches abruptly.
//!
//! Third differences keep the signal itself where a period spans few samples (a record of an
//! electronic oscillator at 9 samples a period read 4.7 mV of "noise" below 0.1 mV of real
//! noise), so where this estimate reads more than twice the floor of the spectrum's upper half
//! ([`crate::numerics::derivative::spectral_floor_sigma`]) that floor is taken ([`crate::numerics::derivative::noise_sigma`]'s rule).
//!
//! Caveat: noise that is not white — a force recovered from kinematics through a derivative
//! filter is low-pass — has less power at the highest frequencies, so this underestimates its
//! σ. Such records should override the floor ([`RegimeThresholds::noise_sigma`], e.g. from
//! [`crate::data::recover::recovery_noise`]).
//!
//! [`RegimeThresholds::noise_sigma`]: super::RegimeThresholds::noise_sigma

use super::error::{check_finite, RegimeError};

/// Scale from the median absolute deviation to σ for Gaussian samples.
pub const MAD_TO_SIGMA: f64 = 1.482_602_218_505_602;

/// Robust σ of the white noise on `f` (same unit as `f`), from third differences, or the
/// spectrum's floor where the differences hold signal.
pub fn noise_floor(f: &[f64]) -> Result<f64, RegimeError> {
    check_finite("f", f)?;
    if f.len() < 8 {
        return Err(RegimeError::TooShort {
            what: "the noise floor",
            needed: 8,
            got: f.len(),
        });
    }
    let mut d: Vec<f64> = f
        .windows(4)
        .map(|w| w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0])
        .collect();
    let med = median(&mut d);
    let mut dev: Vec<f64> = d.iter().map(|x| (x - med).abs()).collect();
    let third = MAD_TO_SIGMA * median(&mut dev) / 20f64.sqrt();
    Ok(match crate::numerics::derivative::spectral_floor_sigma(f) {
        Some(floor) if third > crate::numerics::derivative::SIGNAL_IN_DIFFERENCES * floor => floor,
        _ => third,
    })
}

/// Median of `x` (reorders it); 0 for an empty slice.
pub(crate) fn median(x: &mut [f64]) -> f64 {
    let n = x.len();
    if n == 0 {
        return 0.0;
    }
    x.sort_unstable_by(f64::total_cmp);
    if n % 2 == 1 {
        x[n / 2]
    } else {
        0.5 * (x[n / 2 - 1] + x[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::StdRng;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    fn white(n: usize, sigma: f64, seed: u64) -> Vec<f64> {
        let mut rng = StdRng::seed_from_u64(seed);
        let g = Normal::new(0.0, sigma).unwrap();
        (0..n).map(|_| g.sample(&mut rng)).collect()
    }

    #[test]
    fn white_noise_sigma_within_ten_percent() {
        for (seed, sigma) in [(1, 0.02), (2, 0.5), (3, 3.0)] {
            let est = noise_floor(&white(20_000, sigma, seed)).unwrap();
            assert!(
                (est / sigma - 1.0).abs() < 0.1,
                "σ {sigma}: estimated {est}"
            );
        }
    }

    #[test]
    fn a_smooth_force_and_on_off_spikes_do_not_raise_the_floor() {
        // 200 Hz, a 5 N force at 1.5 Hz switched on for 30 % of each cycle, plus σ = 0.02 N.
        let n = 20_000;
        let noise = white(n, 0.02, 9);
        let f: Vec<f64> = (0..n)
            .map(|i| {
                let ph = (i as f64 * 1.5 / 200.0).fract();
                let s = if ph < 0.3 {
                    5.0 * (std::f64::consts::PI * ph / 0.3).sin()
                } else {
                    0.0
                };
                s + noise[i]
            })
            .collect();
        let est = noise_floor(&f).unwrap();
        assert!((est / 0.02 - 1.0).abs() < 0.1, "estimated {est}");
        // And with no noise at all the floor is far below it.
        let clean: Vec<f64> = (0..n)
            .map(|i| 5.0 * (std::f64::consts::TAU * 1.5 * i as f64 / 200.0).sin())
            .collect();
        assert!(noise_floor(&clean).unwrap() < 1e-3);
    }

    #[test]
    fn short_or_bad_signals_are_errors() {
        assert!(noise_floor(&[0.0; 5]).is_err());
        assert!(noise_floor(&[0.0, 1.0, f64::INFINITY, 0.0, 0.0, 0.0, 0.0, 0.0]).is_err());
    }
}
