//! Per-cycle features of a record: what the force does in each rotor cycle.
//!
//! For a cycle (samples `start..end`, see [`super::cycles`]):
//!
//! - `omega`: the cycle's mean rotor speed, rad/s;
//! - `amplitude`: half the peak-to-peak displacement, m;
//! - `f_peak`, `f_rms`: max |F| and RMS of F, N;
//! - `duty`: fraction of the cycle in which the force is on ([`duty`]);
//! - `energy`: dissipated energy ∮F dx, J, by the trapezoid rule on F dx from sample `start` to
//!   sample `end` (positive for a force that opposes the motion: F enters the equation of motion
//!   on the left-hand side);
//! - `energy_ratio`: ∮F dx / (π·f_peak·amplitude), a dimensionless shape of the loop: 1 for a
//!   viscous force, 4/π for a Coulomb (yield) force, 0 for an elastic force or one in phase with
//!   x or a; 0 when the cycle has no force or no motion;
//! - `corr_x`, `corr_v`, `corr_a`: alignment of the force's extrema with those of x, v and a,
//!   measured as the Pearson correlation, over the cycle, of |F| with |x|, |v| and |a|. A force
//!   that peaks where the blade is fastest (a damper) has `corr_v` near 1; impact spikes at the
//!   turning points (in phase with the acceleration, as the paper observed post-resonance) have
//!   `corr_a` and `corr_x` near 1. The correlation is 0 when either signal is constant over the
//!   cycle (nothing to align). A correlation is used rather than the lag between single peaks
//!   because it uses every sample and does not jump when two peaks of a cycle are nearly equal;
//! - `f_peak_smooth`, `c_eq`, `phase_x`, `phase_v`: what the field reads from the loop — the
//!   peak of the lightly smoothed force (the negligible-force test reads it), the equivalent
//!   viscous damping and the phase of the force's fundamental against x and v
//!   ([`super::loops`]; NaN where the smoothed force never passes the on-threshold: noise has
//!   no phase to read).

use serde::Serialize;

use super::cycles::Cycle;
use super::error::RegimeError;
use super::loops::{equivalent_damping, peak_window, phase_deg, smoothed_peak};
use super::thresholds::RegimeThresholds;
use crate::data::force_data::ForceData;

/// What the force does in one cycle; see the [module doc](self) for each field.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CycleFeatures {
    /// Time at the middle of the cycle, s.
    pub t_mid: f64,
    /// Mean rotor speed, rad/s.
    pub omega: f64,
    /// Half the peak-to-peak displacement, m.
    pub amplitude: f64,
    /// Largest |F|, N.
    pub f_peak: f64,
    /// RMS of F, N.
    pub f_rms: f64,
    /// Fraction of the cycle in which the force is on.
    pub duty: f64,
    /// Dissipated energy ∮F dx, J.
    pub energy: f64,
    /// ∮F dx / (π·f_peak·amplitude).
    pub energy_ratio: f64,
    /// Correlation of |F| with |x|.
    pub corr_x: f64,
    /// Correlation of |F| with |v|.
    pub corr_v: f64,
    /// Correlation of |F| with |a|.
    pub corr_a: f64,
    /// Largest |F| of the force smoothed over about 1/25 of the cycle, N.
    pub f_peak_smooth: f64,
    /// Equivalent viscous damping ∮F dx / (π·ω·X²), N·s/m.
    pub c_eq: f64,
    /// Phase of the force's fundamental against x's, degrees (NaN: no fundamental).
    pub phase_x: f64,
    /// Phase of the force's fundamental against v's, degrees (NaN: no fundamental).
    pub phase_v: f64,
}

/// Fraction of a cycle in which the force `f` (the cycle's samples) is on.
///
/// A sample is on where |F| > `threshold`. The cycle is treated as periodic (its last and first
/// samples are neighbours). Then: a lone on-sample between off-samples is a noise blip and
/// counts as off; an off stretch shorter than `min_off_fraction` of the cycle counts as on, so a
/// force that merely passes through zero (a sine: duty 1) differs from one that rests at zero
/// between spikes (on–off: duty < 1). Empty input: 0.
pub fn duty(f: &[f64], threshold: f64, min_off_fraction: f64) -> f64 {
    let n = f.len();
    if n == 0 {
        return 0.0;
    }
    // One run a sample, merged into the runs of equal values (flipping none).
    let samples = f.iter().map(|x| (x.abs() > threshold, 1)).collect();
    let mut runs = flip_short(samples, true, 0);
    runs = flip_short(runs, true, 2);
    let min_off = (min_off_fraction * n as f64).ceil() as usize;
    runs = flip_short(runs, false, min_off);
    let on: usize = runs.iter().filter(|r| r.0).map(|r| r.1).sum();
    on as f64 / n as f64
}

/// The runs with the first and last merged when equal (the cycle is periodic).
fn merge_ends(mut runs: Vec<(bool, usize)>) -> Vec<(bool, usize)> {
    if runs.len() > 1 && runs[0].0 == runs[runs.len() - 1].0 {
        if let Some(last) = runs.pop() {
            runs[0].1 += last.1;
        }
    }
    runs
}

/// Turn runs of `value` shorter than `min_len` into the other value and merge neighbours
/// (only when the cycle has both values; a cycle that is all on or all off stays so).
fn flip_short(runs: Vec<(bool, usize)>, value: bool, min_len: usize) -> Vec<(bool, usize)> {
    if runs.len() < 2 {
        return runs;
    }
    let mut out: Vec<(bool, usize)> = Vec::with_capacity(runs.len());
    for (v, len) in runs {
        let v = if v == value && len < min_len { !v } else { v };
        match out.last_mut() {
            Some(r) if r.0 == v => r.1 += len,
            _ => out.push((v, len)),
        }
    }
    merge_ends(out)
}

/// Pearson correlation of |a| with |b|; 0 when either is constant.
fn abs_correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    if n < 2 {
        return 0.0;
    }
    let mean = |s: &[f64]| s[..n].iter().map(|x| x.abs()).sum::<f64>() / n as f64;
    let (ma, mb) = (mean(a), mean(b));
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for i in 0..n {
        let (da, db) = (a[i].abs() - ma, b[i].abs() - mb);
        sab += da * db;
        saa += da * da;
        sbb += db * db;
    }
    let den = (saa * sbb).sqrt();
    if den > 0.0 {
        (sab / den).clamp(-1.0, 1.0)
    } else {
        0.0
    }
}

/// Features of one cycle with force on-threshold `on_threshold` (N); see [`duty`] for
/// `min_off_fraction`. The cycle must fit the signals (`end` < number of samples).
pub fn cycle_features(
    sig: &ForceData,
    cycle: &Cycle,
    on_threshold: f64,
    min_off_fraction: f64,
) -> Result<CycleFeatures, RegimeError> {
    let n = sig.check()?;
    features_of_checked(sig, n, cycle, on_threshold, min_off_fraction)
}

/// [`cycle_features`] of signals already checked to be `n` samples long and finite (the
/// check reads every sample: once a record, not once a cycle).
fn features_of_checked(
    sig: &ForceData,
    n: usize,
    cycle: &Cycle,
    on_threshold: f64,
    min_off_fraction: f64,
) -> Result<CycleFeatures, RegimeError> {
    let (s, e) = (cycle.start, cycle.end);
    if !(s < e && e < n) {
        return Err(RegimeError::BadCycle {
            start: s,
            end: e,
            len: n,
        });
    }
    let f = &sig.f[s..e];
    let x = &sig.x[s..e];
    let (xmin, xmax) = x
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    let amplitude = 0.5 * (xmax - xmin);
    let f_peak = f.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let f_rms = (f.iter().map(|v| v * v).sum::<f64>() / f.len() as f64).sqrt();
    let energy: f64 = (s..e)
        .map(|i| 0.5 * (sig.f[i] + sig.f[i + 1]) * (sig.x[i + 1] - sig.x[i]))
        .sum();
    let f_peak_smooth = smoothed_peak(f, peak_window(f.len()));
    // A force that is never on (only noise, or none) has no phase to read.
    let phase = |r: &[f64]| {
        if f_peak_smooth > on_threshold {
            phase_deg(&sig.t[s..e], f, r)
        } else {
            f64::NAN
        }
    };
    let scale = std::f64::consts::PI * f_peak * amplitude;
    let energy_ratio = if scale > 0.0 { energy / scale } else { 0.0 };
    Ok(CycleFeatures {
        t_mid: cycle.t_mid,
        omega: cycle.omega,
        amplitude,
        f_peak,
        f_rms,
        duty: duty(f, on_threshold, min_off_fraction),
        energy,
        energy_ratio,
        corr_x: abs_correlation(f, x),
        corr_v: abs_correlation(f, &sig.v[s..e]),
        corr_a: abs_correlation(f, &sig.a[s..e]),
        f_peak_smooth,
        c_eq: equivalent_damping(energy, cycle.omega, amplitude),
        phase_x: phase(x),
        phase_v: phase(&sig.v[s..e]),
    })
}

/// Features of every cycle, with the on-threshold of `th` for noise σ `sigma` (N).
pub fn features(
    sig: &ForceData,
    cycles: &[Cycle],
    th: &RegimeThresholds,
    sigma: f64,
) -> Result<Vec<CycleFeatures>, RegimeError> {
    let on = th.on_threshold(sigma);
    let n = sig.check()?;
    cycles
        .iter()
        .map(|c| features_of_checked(sig, n, c, on, th.min_off_fraction))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    /// `n` samples per cycle of x = X sin ωt over `cycles` cycles, with a force from (x, v, a).
    struct Case {
        t: Vec<f64>,
        x: Vec<f64>,
        v: Vec<f64>,
        a: Vec<f64>,
        f: Vec<f64>,
    }

    fn case(
        omega: f64,
        amp: f64,
        n: usize,
        cycles: usize,
        force: impl Fn(f64, f64, f64, f64) -> f64,
    ) -> Case {
        let dt = TAU / omega / n as f64;
        let t: Vec<f64> = (0..=n * cycles).map(|i| i as f64 * dt).collect();
        let x: Vec<f64> = t.iter().map(|t| amp * (omega * t).sin()).collect();
        let v: Vec<f64> = t.iter().map(|t| amp * omega * (omega * t).cos()).collect();
        let a: Vec<f64> = t
            .iter()
            .map(|t| -amp * omega * omega * (omega * t).sin())
            .collect();
        let f = (0..t.len())
            .map(|i| force(t[i], x[i], v[i], a[i]))
            .collect();
        Case { t, x, v, a, f }
    }

    impl Case {
        fn sig(&self) -> ForceData<'_> {
            ForceData::new(&self.t, &self.x, &self.v, &self.a, &self.f)
        }
        fn cycle(&self, n: usize, k: usize, omega: f64) -> Cycle {
            Cycle {
                start: k * n,
                end: (k + 1) * n,
                t_mid: self.t[k * n + n / 2],
                omega,
            }
        }
    }

    #[test]
    fn a_pure_sine_force_has_duty_one() {
        // With the default thresholds and σ from a quiet sensor (0.02 N): 3σ = 0.06 N.
        let th = RegimeThresholds::default();
        for amp in [0.5, 2.0, 10.0] {
            let c = case(6.0, 0.01, 333, 3, |t, _, _, _| amp * (6.0 * t + 0.3).sin());
            let f = cycle_features(
                &c.sig(),
                &c.cycle(333, 1, 6.0),
                th.on_threshold(0.02),
                th.min_off_fraction,
            )
            .unwrap();
            assert_eq!(f.duty, 1.0, "amplitude {amp}");
            assert!((f.f_peak - amp).abs() < 1e-3 * amp);
            assert!((f.f_rms - amp / 2f64.sqrt()).abs() < 1e-3 * amp);
        }
    }

    #[test]
    fn a_half_wave_rectified_spike_train_has_the_duty_it_was_built_with() {
        // Half-sine spikes of 50 N lasting a fraction d of each cycle, zero in between.
        for d in [0.1, 0.25, 0.4, 0.6] {
            let spike = move |t: f64| {
                let ph = (t * 6.0 / TAU).fract();
                if ph < d {
                    50.0 * (PI * ph / d).sin()
                } else {
                    0.0
                }
            };
            let c = case(6.0, 0.01, 1000, 3, |t, _, _, _| spike(t));
            let f = cycle_features(&c.sig(), &c.cycle(1000, 1, 6.0), 0.06, 0.05).unwrap();
            // Below 0.06 N the spike's ends are off: asin(0.06/50)/π of d at each end (≈ 0.1 %).
            assert!(
                (f.duty - d).abs() < 0.002 + 1.0 / 1000.0,
                "built {d}, got {}",
                f.duty
            );
        }
    }

    #[test]
    fn duty_ignores_lone_noise_blips_and_keeps_real_gaps() {
        let mut f = vec![0.0; 100];
        f[10] = 1.0; // lone blip: off
        for v in &mut f[40..60] {
            *v = 1.0;
        }
        assert!((duty(&f, 0.5, 0.05) - 0.2).abs() < 1e-12);
        // A 3-sample gap inside the on stretch is bridged (3 % < 5 %), a 10-sample gap is not.
        let mut g = f.clone();
        for v in &mut g[48..51] {
            *v = 0.0;
        }
        assert!((duty(&g, 0.5, 0.05) - 0.2).abs() < 1e-12);
        for v in &mut g[45..55] {
            *v = 0.0;
        }
        assert!((duty(&g, 0.5, 0.05) - 0.1).abs() < 1e-12);
        assert_eq!(duty(&[0.0; 10], 0.5, 0.05), 0.0);
        assert_eq!(duty(&[], 0.5, 0.05), 0.0);
    }

    #[test]
    fn viscous_energy_per_cycle_is_pi_c_omega_x_squared() {
        let (c_visc, omega, amp) = (12.0, 7.3, 0.013);
        let c = case(omega, amp, 500, 4, |_, _, v, _| c_visc * v);
        let exact = PI * c_visc * omega * amp * amp;
        for k in 0..4 {
            let f = cycle_features(&c.sig(), &c.cycle(500, k, omega), 0.06, 0.05).unwrap();
            assert!(
                (f.energy / exact - 1.0).abs() < 1e-3,
                "∮F dx {} vs {exact}",
                f.energy
            );
            assert!((f.energy_ratio - 1.0).abs() < 1e-3);
            assert!((f.amplitude - amp).abs() < 1e-3 * amp);
            assert!(f.corr_v > 0.999, "a damper peaks with |v|: {}", f.corr_v);
            // |x| and |v| are out of phase: corr(|sin|, |cos|) = (1/π − 4/π²)/(½ − 4/π²) ≈ −0.92.
            assert!(f.corr_x < -0.9, "{}", f.corr_x);
        }
    }

    #[test]
    fn an_elastic_force_dissipates_nothing_and_aligns_with_x_and_a() {
        let c = case(5.0, 0.01, 400, 2, |_, x, _, _| 300.0 * x);
        let f = cycle_features(&c.sig(), &c.cycle(400, 0, 5.0), 0.06, 0.05).unwrap();
        assert!(f.energy.abs() < 1e-6 * f.f_peak * f.amplitude);
        assert!(f.corr_x > 0.999 && f.corr_a > 0.999 && f.corr_v < -0.9);
    }

    #[test]
    fn a_force_that_is_never_on_has_no_phase() {
        // 0.04 N of damper force stays below the on-threshold 0.06 N: no phase to read; ten
        // times more has the damper's 90° against x.
        for (c_visc, on) in [(4.0, false), (40.0, true)] {
            let c = case(6.0, 0.01 / 6.0, 400, 2, |_, _, v, _| c_visc * v);
            let f = cycle_features(&c.sig(), &c.cycle(400, 0, 6.0), 0.06, 0.05).unwrap();
            assert_eq!(f.phase_x.is_finite(), on, "{f:?}");
            if on {
                assert!(
                    (f.phase_x - 90.0).abs() < 0.5 && f.phase_v.abs() < 0.5,
                    "{f:?}"
                );
                assert!((f.c_eq / c_visc - 1.0).abs() < 1e-3, "{f:?}");
            }
        }
    }

    #[test]
    fn cycles_outside_the_record_are_errors() {
        let c = case(5.0, 0.01, 100, 1, |_, _, _, _| 0.0);
        let bad = Cycle {
            start: 50,
            end: 101,
            t_mid: 0.0,
            omega: 5.0,
        };
        assert!(matches!(
            cycle_features(&c.sig(), &bad, 0.06, 0.05),
            Err(RegimeError::BadCycle { .. })
        ));
        let short = ForceData {
            f: &c.f[..10],
            ..c.sig()
        };
        assert!(matches!(
            short.check().map_err(RegimeError::from),
            Err(RegimeError::LengthMismatch { name: "f", .. })
        ));
    }
}
