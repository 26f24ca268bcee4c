//! The sine of a rotor angle, without the platform's `sin` call.
//!
//! Why: the driving force `F0·ω²·sin φ` is evaluated at every right-hand side of a simulation
//! (≈ 65 000 times for the paper's 150 s sweep) and at every output sample, and glibc's `sin`
//! was a fifth of the sweep's integration time (perf). The angles are moderate (a sweep to
//! 9.4 rad/s over 200 s reaches 940 rad), so a short reduction suffices; inlined into the
//! right-hand side it made `integrate` on the sweep 2–3 % faster (the sine and the rest of the
//! right-hand side 43 % of the profile instead of 45 %). The alternatives, measured in one run
//! of `bench_sweep` each, alternated twice (load 5): the `libm` crate's `sin` (fdlibm in Rust,
//! with its branches and general reduction) 3.55 / 3.56 ms best, glibc's `sin` 3.16 /
//! 3.18 ms, this one 3.06 / 3.08 ms.
//!
//! How: `x = k·π/2 + r` with `k` the nearest integer to `x·2/π` (`|r| ≤ π/4`), `π/2` in three
//! parts of which the first two hold 33 bits, so that `k·part` is exact for `|k| < 2²⁰` and the
//! reduction loses nothing but the last subtraction's rounding; then fdlibm's minimax
//! polynomials for `sin r` and `cos r` (both, without a branch on the quadrant, whose pick
//! would be mispredicted half the time), one of them chosen and its sign set from `k mod 4` by
//! bit operations. Absolute error against the correctly rounded sine below 2.3e-16 (tested
//! against `f64::sin`); arguments of magnitude 1e5 and more, or not finite, go to `f64::sin`.

/// `π/2` in parts: the first 33 bits, the next 33 bits, the rest (fdlibm's `pio2_1`, `pio2_2`,
/// `pio2_2t`).
const PIO2_1: f64 = 1.5707963267341256;
const PIO2_2: f64 = 6.077100506303966e-11;
const PIO2_2T: f64 = 2.0222662487959506e-21;
/// Below this magnitude `k < 2²⁰` and the reduction is exact but for one rounding.
const REDUCTION_LIMIT: f64 = 1e5;

/// `sin x` (see the module's notes for its accuracy).
#[inline]
pub fn sin(x: f64) -> f64 {
    if !(x.abs() < REDUCTION_LIMIT) {
        return x.sin();
    }
    // Round to the nearest integer by adding and removing 1.5·2⁵² (no rounding instruction
    // needed on the baseline x86-64 target).
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let kf = (x * std::f64::consts::FRAC_2_PI + SHIFT) - SHIFT;
    let k = kf as i64;
    let r = ((x - kf * PIO2_1) - kf * PIO2_2) - kf * PIO2_2T;
    let (s, c) = (kernel_sin(r), kernel_cos(r));
    // Quadrant k mod 4: sin r, cos r, −sin r, −cos r.
    let odd = ((k & 1) as u64).wrapping_neg();
    let bits = (s.to_bits() & !odd) | (c.to_bits() & odd);
    let sign = ((k & 2) as u64) << 62;
    f64::from_bits(bits ^ sign)
}

/// `sin r` for `|r| ≤ π/4` (fdlibm's `__kernel_sin` without the tail of `r`).
#[inline(always)]
fn kernel_sin(r: f64) -> f64 {
    const S1: f64 = -0.16666666666666632;
    const S2: f64 = 0.00833333333332249;
    const S3: f64 = -0.0001984126982985795;
    const S4: f64 = 2.7557313707070068e-06;
    const S5: f64 = -2.5050760253406863e-08;
    const S6: f64 = 1.58969099521155e-10;
    let z = r * r;
    let v = z * r;
    let p = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    r + v * (S1 + z * p)
}

/// `cos r` for `|r| ≤ π/4` (fdlibm's `__kernel_cos` without the tail of `r`).
#[inline(always)]
fn kernel_cos(r: f64) -> f64 {
    const C1: f64 = 0.0416666666666666;
    const C2: f64 = -0.001388888888887411;
    const C3: f64 = 2.480158728947673e-05;
    const C4: f64 = -2.7557314351390663e-07;
    const C5: f64 = 2.087572321298175e-09;
    const C6: f64 = -1.1359647557788195e-11;
    let z = r * r;
    let p = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + z * p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn agrees_with_the_platform_sine_to_the_last_bits() {
        // A dense walk over the range of rotor angles, points near multiples of π/2 (where the
        // reduction cancels most), and far and special arguments.
        let mut worst: f64 = 0.0;
        let mut x = -1200.0;
        while x < 1200.0 {
            worst = worst.max((sin(x) - x.sin()).abs());
            x += 0.000_731_3;
        }
        for k in -70_000i64..70_000 {
            for d in [0.0, 1e-12, -3e-9] {
                let x = k as f64 * std::f64::consts::FRAC_PI_2 + d;
                if x.abs() < REDUCTION_LIMIT {
                    worst = worst.max((sin(x) - x.sin()).abs());
                }
            }
        }
        assert!(worst <= 2.3e-16, "largest |Δ| {worst:e}");
        assert_eq!(sin(0.0), 0.0);
        assert_eq!(sin(1e-300), 1e-300);
        assert_eq!(sin(3e7), 3e7f64.sin());
        assert!(sin(f64::NAN).is_nan() && sin(f64::INFINITY).is_nan());
    }
}
