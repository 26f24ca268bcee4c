//! The sine of the rotor's angle, in a third of the C library's time.
//!
//! The unbalanced rotor's force `F0·ω²·sin φ` is evaluated at every right-hand-side call and
//! at every output sample: on the paper's sweep the C library's `sin` was a quarter of a
//! simulation's time. The angle is at most a few thousand radians, so a two-term Cody–Waite
//! reduction by π/2 (fdlibm's constants: the first term has 33 significant bits, so `n·π/2₁`
//! is exact for `|n| < 2²⁰`) followed by fdlibm's minimax polynomials on `[−π/4, π/4]` gives
//! the sine to within an ulp or so of the correctly rounded value, without table look-ups or
//! branches that would keep a loop over samples from being vectorised. Beyond
//! [`FAST_LIMIT`] the C library's `sin` is used.

/// Largest |x| reduced here (the reduction's product `n·π/2₁` stays exact well beyond it).
pub const FAST_LIMIT: f64 = 1.0e5;

const INV_PIO2: f64 = 6.366_197_723_675_813_824_33e-1;
/// First 33 bits of π/2.
const PIO2_1: f64 = 1.570_796_326_734_125_614_17e0;
/// π/2 − PIO2_1.
const PIO2_1T: f64 = 6.077_100_506_506_192_249_32e-11;
/// 1.5·2⁵²: adding and subtracting it rounds to the nearest integer (|v| < 2⁵¹).
const ROUND: f64 = 6_755_399_441_055_744.0;

const S1: f64 = -1.666_666_666_666_663_243_48e-1;
const S2: f64 = 8.333_333_333_322_489_461_24e-3;
const S3: f64 = -1.984_126_982_985_794_931_34e-4;
const S4: f64 = 2.755_731_370_707_006_767_89e-6;
const S5: f64 = -2.505_076_025_340_686_341_95e-8;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;

const C1: f64 = 4.166_666_666_666_660_190_37e-2;
const C2: f64 = -1.388_888_888_887_410_957_49e-3;
const C3: f64 = 2.480_158_728_947_672_941_78e-5;
const C4: f64 = -2.755_731_435_139_066_330_35e-7;
const C5: f64 = 2.087_572_321_298_174_827_90e-9;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;

/// sin x: the C library's value to within about an ulp (of the result's scale) for
/// |x| ≤ [`FAST_LIMIT`], the C library's own value beyond (and for NaN and infinities).
#[inline]
pub fn sin(x: f64) -> f64 {
    if !(x.abs() <= FAST_LIMIT) {
        return x.sin();
    }
    kernel(x)
}

/// sin x for |x| ≤ [`FAST_LIMIT`] (undefined beyond): straight-line code, which a loop over
/// a column vectorises.
#[inline(always)]
fn kernel(x: f64) -> f64 {
    // The shifted value's low mantissa bits are n itself (two's complement, |n| < 2⁵¹).
    let shifted = x * INV_PIO2 + ROUND;
    let n = shifted - ROUND;
    let r = x - n * PIO2_1;
    let w = n * PIO2_1T;
    let y0 = r - w;
    let y1 = (r - y0) - w;
    let z = y0 * y0;
    // sin(y0 + y1) and cos(y0 + y1) on [−π/4, π/4] (fdlibm's __kernel_sin and __kernel_cos).
    let v = z * y0;
    let rs = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    let s = y0 - ((z * (0.5 * y1 - v * rs) - y1) - v * S1);
    let rc = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    let hz = 0.5 * z;
    let one_minus = 1.0 - hz;
    let c = one_minus + (((1.0 - one_minus) - hz) + (z * rc - y0 * y1));
    // Quadrant n mod 4: sin, cos, −sin, −cos — picked by bit masks, not branches (the
    // quadrant of successive samples is as good as random to a branch predictor).
    let q = shifted.to_bits();
    let odd = 0u64.wrapping_sub(q & 1);
    let bits = (s.to_bits() & !odd) | (c.to_bits() & odd);
    f64::from_bits(bits ^ ((q & 2) << 62))
}

/// `out[i] = scale(i) · sin(angle[i] − offset)` with `scale(i) = f0·ω[i]²`: the rotor's
/// force at a column of samples, value for value as `f0 * w * w * sin(phi - offset)`
/// (vectorised when every angle is within [`FAST_LIMIT`]).
pub fn rotor_force(f0: f64, offset: f64, phi: &[f64], omega: &[f64], out: &mut [f64]) {
    let n = out.len().min(phi.len()).min(omega.len());
    let (phi, omega, out) = (&phi[..n], &omega[..n], &mut out[..n]);
    if phi.iter().all(|p| (p - offset).abs() <= FAST_LIMIT) {
        for i in 0..n {
            out[i] = f0 * omega[i] * omega[i] * kernel(phi[i] - offset);
        }
    } else {
        for i in 0..n {
            out[i] = f0 * omega[i] * omega[i] * sin(phi[i] - offset);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// |ours − libm| in ulps of the larger of |sin x| and 2⁻²⁰ (absolute near a zero, where
    /// the argument's own rounding dominates).
    fn ulps(x: f64) -> f64 {
        let (a, b) = (sin(x), x.sin());
        (a - b).abs() / (f64::EPSILON * b.abs().max(1e-6))
    }

    #[test]
    fn agrees_with_the_c_library_to_about_an_ulp() {
        let mut worst: f64 = 0.0;
        let mut x = -3.0e3;
        // An irrational step: every phase of π/2 is visited.
        while x < 3.0e3 {
            worst = worst.max(ulps(x));
            x += 0.013_713_713_7;
        }
        for &x in &[
            0.0,
            1e-300,
            1e-8,
            0.785,
            1.5707963267948966,
            3.141592653589793,
            99_999.9,
        ] {
            worst = worst.max(ulps(x)).max(ulps(-x));
        }
        assert!(worst <= 2.0, "worst {worst} ulps");
    }

    #[test]
    fn the_column_form_is_the_scalar_form_value_for_value() {
        let phi: Vec<f64> = (0..1000)
            .map(|i| 0.0235 * (i as f64 * 0.2).powi(2))
            .collect();
        let omega: Vec<f64> = (0..1000).map(|i| 0.047 * i as f64 * 0.2).collect();
        for offset in [0.0, 0.3] {
            let mut out = vec![0.0; 1000];
            rotor_force(0.0462, offset, &phi, &omega, &mut out);
            for i in 0..1000 {
                let w = omega[i];
                assert_eq!(out[i], 0.0462 * w * w * sin(phi[i] - offset));
            }
        }
        // An angle beyond the fast range takes the other path, with the same values.
        let (far, w) = ([1.0, 2.0e5], [3.0, 4.0]);
        let mut out = [0.0; 2];
        rotor_force(2.0, 0.0, &far, &w, &mut out);
        assert_eq!(out, [18.0 * 1.0f64.sin(), 32.0 * 2.0e5f64.sin()]);
    }

    #[test]
    fn beyond_the_limit_and_at_non_finite_arguments_it_is_the_c_library() {
        for x in [1.0e5 + 0.5, -4.0e7, 1e300] {
            assert_eq!(sin(x), x.sin());
        }
        assert!(sin(f64::NAN).is_nan());
        assert!(sin(f64::INFINITY).is_nan());
        assert_eq!(sin(0.0), 0.0);
    }
}
