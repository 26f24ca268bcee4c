//! How well a model's force matches a measured one, regime by regime.
//!
//! The model's force is evaluated on the measured kinematics (same samples, same cycles). The
//! cycles are grouped by their MEASURED smoothed labels; for each regime and for the whole
//! record:
//!
//! - `force_rms_error`: RMS of F_model − F_measured over the samples of those cycles, N, and
//!   `relative_rms_error`: that divided by the measured force RMS there, floored at the
//!   measurement's on-threshold (so a regime where the measured force is only noise does not
//!   divide by ≈ 0);
//! - `energy_error`: mean over cycles of |∮F_model dx − ∮F_measured dx|, J;
//! - `duty_error`: mean over cycles of |duty_model − duty_measured| (with the means of both, so a
//!   model that misses the on–off behaviour shows as duty ≈ 1 against a measured 0.5);
//! - `peak_force_error`: mean over cycles of |peak_model − peak_measured|, N;
//! - the loop metrics the field reads ([`super::loops`]), as the measured and the model's mean
//!   per cycle and the mean |difference| per cycle: `measured_energy`/`model_energy`/
//!   `energy_error` (∮F dx, J), `measured_c_eq`/`model_c_eq`/`c_eq_error` (equivalent viscous
//!   damping, N·s/m), `measured_phase_x`/`model_phase_x`/`phase_x_error` and the same against v
//!   (phase of the force's fundamental, degrees; circular means; differences wrapped to ±180°,
//!   over the cycles where both have a fundamental), `measured_peak_force`/`model_peak_force`;
//! - `label_agreement`: fraction of the cycles whose label from the model's own force (the same
//!   classifier, the same thresholds and the measurement's noise σ, so both are judged alike)
//!   equals the measured label.
//!
//! And the boundary errors: |ω_model − ω_measured| of each boundary both have, rad/s.

use serde::Serialize;

use super::boundaries::{Boundaries, Boundary};
use super::classify::{classify, Classification, Regime};
use super::error::{check_len, RegimeError};
use super::features::CycleFeatures;
use super::loops::wrap_deg;
use super::thresholds::RegimeThresholds;
use crate::data::force_data::ForceData;

/// One value per regime (`None`: the measurement has no cycle in that regime).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PerRegime<T> {
    /// Pre-resonance.
    pub pre_resonance: Option<T>,
    /// Resonance.
    pub resonance: Option<T>,
    /// Post-resonance.
    pub post_resonance: Option<T>,
}

impl<T> PerRegime<T> {
    /// The value for `regime`.
    pub fn get(&self, regime: Regime) -> Option<&T> {
        match regime {
            Regime::PreResonance => self.pre_resonance.as_ref(),
            Regime::Resonance => self.resonance.as_ref(),
            Regime::PostResonance => self.post_resonance.as_ref(),
        }
    }

    /// Set the value for `regime`.
    pub fn set(&mut self, regime: Regime, value: Option<T>) {
        match regime {
            Regime::PreResonance => self.pre_resonance = value,
            Regime::Resonance => self.resonance = value,
            Regime::PostResonance => self.post_resonance = value,
        }
    }
}

/// Errors of a model over a set of cycles; see the [module doc](self).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RegimeMetrics {
    /// Number of cycles.
    pub cycles: usize,
    /// RMS of the measured force, N.
    pub measured_rms: f64,
    /// RMS of the model's force, N.
    pub model_rms: f64,
    /// RMS of the force error, N.
    pub force_rms_error: f64,
    /// `force_rms_error` / max(`measured_rms`, on-threshold).
    pub relative_rms_error: f64,
    /// Mean measured ∮F dx per cycle, J.
    pub measured_energy: f64,
    /// Mean |Δ∮F dx| per cycle, J.
    pub energy_error: f64,
    /// Mean measured duty.
    pub measured_duty: f64,
    /// Mean duty of the model's force.
    pub model_duty: f64,
    /// Mean |Δduty| per cycle.
    pub duty_error: f64,
    /// Mean |Δ peak |F|| per cycle, N.
    pub peak_force_error: f64,
    /// Mean ∮F dx per cycle of the model's force, J.
    pub model_energy: f64,
    /// Mean measured equivalent viscous damping, N·s/m.
    pub measured_c_eq: f64,
    /// Mean equivalent viscous damping of the model's force, N·s/m.
    pub model_c_eq: f64,
    /// Mean |Δc_eq| per cycle, N·s/m.
    pub c_eq_error: f64,
    /// Circular mean of the measured force's phase against x, degrees.
    pub measured_phase_x: f64,
    /// Circular mean of the model force's phase against x, degrees.
    pub model_phase_x: f64,
    /// Mean |Δphase against x| per cycle, degrees.
    pub phase_x_error: f64,
    /// Circular mean of the measured force's phase against v, degrees.
    pub measured_phase_v: f64,
    /// Circular mean of the model force's phase against v, degrees.
    pub model_phase_v: f64,
    /// Mean |Δphase against v| per cycle, degrees.
    pub phase_v_error: f64,
    /// Mean measured peak |F| per cycle, N.
    pub measured_peak_force: f64,
    /// Mean peak |F| of the model's force per cycle, N.
    pub model_peak_force: f64,
    /// Fraction of cycles whose model label equals the measured label.
    pub label_agreement: f64,
}

/// Boundary errors, |ω_model − ω_measured|, rad/s (`None` if either lacks the boundary).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct BoundaryErrors {
    /// Pre-resonance → resonance.
    pub pre_resonance: Option<f64>,
    /// Resonance → post-resonance.
    pub resonance_post: Option<f64>,
}

/// A model compared with a measurement.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Comparison {
    /// Per measured regime.
    pub per_regime: PerRegime<RegimeMetrics>,
    /// Over every cycle.
    pub overall: RegimeMetrics,
    /// Boundary errors.
    pub boundary_errors: BoundaryErrors,
    /// The model's own smoothed labels, cycle by cycle.
    pub model_labels: Vec<Regime>,
    /// The model's own boundaries.
    pub model_boundaries: Boundaries,
    /// The features of the model's force, cycle by cycle (the measured cycles).
    pub model_features: Vec<CycleFeatures>,
    /// RMS of the force error in each cycle, N.
    pub cycle_force_rms_error: Vec<f64>,
}

/// Mean of `x` (`empty` if it has no values).
pub(super) fn mean_or(x: impl Iterator<Item = f64>, empty: f64) -> f64 {
    let (s, n) = x.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n > 0 {
        s / n as f64
    } else {
        empty
    }
}

/// Circular mean of angles in degrees (NaN ones skipped; NaN if none).
fn circular_mean(x: impl Iterator<Item = f64>) -> f64 {
    let (s, c, n) = x
        .filter(|a| a.is_finite())
        .fold((0.0, 0.0, 0usize), |(s, c, n), a| {
            (s + a.to_radians().sin(), c + a.to_radians().cos(), n + 1)
        });
    if n > 0 {
        s.atan2(c).to_degrees()
    } else {
        f64::NAN
    }
}

/// Mean of the finite values (NaN if none).
pub(super) fn finite_mean(x: impl Iterator<Item = f64>) -> f64 {
    mean_or(x.filter(|v| v.is_finite()), f64::NAN)
}

/// |model − measured| of a phase, wrapped to [0°, 180°] (NaN when either is NaN).
pub fn phase_error(measured: f64, model: f64) -> f64 {
    wrap_deg(model - measured).abs()
}

/// The metrics of the cycles `idx`; see the [module doc](self).
fn metrics_over(
    idx: &[usize],
    measured: &Classification,
    model: &Classification,
    f_meas: &[f64],
    f_model: &[f64],
) -> RegimeMetrics {
    let (mut e2, mut m2, mut p2, mut n) = (0.0, 0.0, 0.0, 0usize);
    for &i in idx {
        let c = &measured.cycles[i];
        for k in c.start..c.end {
            let (fm, fp) = (f_meas[k], f_model[k]);
            e2 += (fp - fm) * (fp - fm);
            m2 += fm * fm;
            p2 += fp * fp;
            n += 1;
        }
    }
    let rms = |s: f64| if n > 0 { (s / n as f64).sqrt() } else { 0.0 };
    let (err, meas) = (rms(e2), rms(m2));
    let (mf, pf) = (&measured.features, &model.features);
    let pairs = || idx.iter().map(|&i| (&mf[i], &pf[i]));
    let over = |g: &dyn Fn(&CycleFeatures, &CycleFeatures) -> f64| {
        mean_or(pairs().map(|(a, b)| g(a, b)), 0.0)
    };
    let finite = |g: &dyn Fn(&CycleFeatures, &CycleFeatures) -> f64| {
        finite_mean(pairs().map(|(a, b)| g(a, b)))
    };
    let circ = |g: &dyn Fn(&CycleFeatures) -> f64, set: &[CycleFeatures]| {
        circular_mean(idx.iter().map(|&i| g(&set[i])))
    };
    RegimeMetrics {
        cycles: idx.len(),
        measured_rms: meas,
        model_rms: rms(p2),
        force_rms_error: err,
        relative_rms_error: err / meas.max(measured.on_threshold).max(f64::MIN_POSITIVE),
        measured_energy: over(&|a, _| a.energy),
        energy_error: over(&|a, b| (b.energy - a.energy).abs()),
        measured_duty: over(&|a, _| a.duty),
        model_duty: over(&|_, b| b.duty),
        duty_error: over(&|a, b| (b.duty - a.duty).abs()),
        peak_force_error: over(&|a, b| (b.f_peak - a.f_peak).abs()),
        label_agreement: mean_or(
            idx.iter()
                .map(|&i| f64::from(u8::from(measured.labels[i] == model.labels[i]))),
            0.0,
        ),
        model_energy: finite(&|_, b| b.energy),
        measured_c_eq: finite(&|a, _| a.c_eq),
        model_c_eq: finite(&|_, b| b.c_eq),
        c_eq_error: finite(&|a, b| (b.c_eq - a.c_eq).abs()),
        measured_phase_x: circ(&|f| f.phase_x, mf),
        model_phase_x: circ(&|f| f.phase_x, pf),
        phase_x_error: finite(&|a, b| phase_error(a.phase_x, b.phase_x)),
        measured_phase_v: circ(&|f| f.phase_v, mf),
        model_phase_v: circ(&|f| f.phase_v, pf),
        phase_v_error: finite(&|a, b| phase_error(a.phase_v, b.phase_v)),
        measured_peak_force: finite(&|a, _| a.f_peak),
        model_peak_force: finite(&|_, b| b.f_peak),
    }
}

/// RMS of the force error in each measured cycle, N.
fn cycle_rms(measured: &Classification, f_meas: &[f64], f_model: &[f64]) -> Vec<f64> {
    measured
        .cycles
        .iter()
        .map(|c| {
            let n = c.len().max(1) as f64;
            let s: f64 = (c.start..c.end)
                .map(|k| (f_model[k] - f_meas[k]).powi(2))
                .sum();
            (s / n).sqrt()
        })
        .collect()
}

fn boundary_error(a: Option<Boundary>, b: Option<Boundary>) -> Option<f64> {
    Some((a?.omega - b?.omega).abs())
}

/// Compare the force `model_force` of a model on the measured kinematics with the measured
/// record `sig`, whose classification (with thresholds `th`) is `measured`.
pub fn compare(
    measured: &Classification,
    sig: &ForceData,
    model_force: &[f64],
    th: &RegimeThresholds,
) -> Result<Comparison, RegimeError> {
    check_len("model force", model_force, sig.t.len())?;
    let th_model = RegimeThresholds {
        noise_sigma: Some(measured.noise_sigma),
        ..th.clone()
    };
    let model = classify(
        &sig.with_force(model_force),
        measured.cycles.clone(),
        &th_model,
    )?;
    let mut per_regime = PerRegime::default();
    for r in Regime::ALL {
        let idx = measured.cycles_in(r);
        let m = (!idx.is_empty()).then(|| metrics_over(&idx, measured, &model, sig.f, model_force));
        per_regime.set(r, m);
    }
    let all: Vec<usize> = (0..measured.labels.len()).collect();
    let overall = metrics_over(&all, measured, &model, sig.f, model_force);
    let (mb, pb) = (&measured.boundaries, &model.boundaries);
    Ok(Comparison {
        per_regime,
        overall,
        boundary_errors: BoundaryErrors {
            pre_resonance: boundary_error(mb.pre_resonance, pb.pre_resonance),
            resonance_post: boundary_error(mb.resonance_post, pb.resonance_post),
        },
        model_labels: model.labels,
        model_boundaries: model.boundaries,
        model_features: model.features,
        cycle_force_rms_error: cycle_rms(measured, sig.f, model_force),
    })
}

#[cfg(test)]
mod tests {
    use super::super::cycles::cycles_from_phase;
    use super::*;
    use std::f64::consts::TAU;

    /// A constant-ω record (ω = 6 rad/s, 200 Hz, 30 s) with x = 10 mm sin φ and force `f`.
    fn record(f: impl Fn(f64, f64) -> f64) -> (Vec<f64>, Vec<f64>, [Vec<f64>; 4]) {
        let t: Vec<f64> = (0..6000).map(|i| i as f64 / 200.0).collect();
        let phi: Vec<f64> = t.iter().map(|t| 6.0 * t).collect();
        let x = phi.iter().map(|p| 0.01 * p.sin()).collect();
        let v: Vec<f64> = phi.iter().map(|p| 0.06 * p.cos()).collect();
        let a = phi.iter().map(|p| -0.36 * p.sin()).collect();
        let force = phi.iter().zip(&v).map(|(&p, &v)| f(p, v)).collect();
        (t, phi, [x, v, a, force])
    }

    #[test]
    fn a_model_equal_to_the_measurement_has_no_error() {
        let (t, phi, [x, v, a, f]) = record(|_, v| 40.0 * v);
        let sig = ForceData::new(&t, &x, &v, &a, &f);
        let th = RegimeThresholds::default();
        let m = classify(&sig, cycles_from_phase(&t, &phi).unwrap(), &th).unwrap();
        let c = compare(&m, &sig, &f, &th).unwrap();
        assert_eq!(c.overall.force_rms_error, 0.0);
        assert_eq!(c.overall.label_agreement, 1.0);
        assert_eq!(c.overall.cycles, m.cycles.len());
        assert!(c.per_regime.resonance.is_some());
        assert!(c.per_regime.post_resonance.is_none());
    }

    #[test]
    fn errors_of_a_scaled_and_of_an_on_off_model() {
        // Measured: viscous 40·v (duty 1, resonance-like). Model A: 0.5× (relative RMS error
        // exactly 0.5, energy error half the energy). Model B: the same force only while
        // |sin φ| < 0.5, i.e. on for 1/3 of the cycle.
        let (t, phi, [x, v, a, f]) = record(|_, v| 40.0 * v);
        let sig = ForceData::new(&t, &x, &v, &a, &f);
        let th = RegimeThresholds::default();
        let m = classify(&sig, cycles_from_phase(&t, &phi).unwrap(), &th).unwrap();
        let half: Vec<f64> = f.iter().map(|f| 0.5 * f).collect();
        let ca = compare(&m, &sig, &half, &th).unwrap();
        let r = ca.per_regime.resonance.unwrap();
        assert!((r.relative_rms_error - 0.5).abs() < 1e-9);
        assert!((r.energy_error / r.measured_energy - 0.5).abs() < 1e-9);
        assert!(r.duty_error < 1e-12);
        assert!((r.peak_force_error - 0.5 * 40.0 * 0.06).abs() < 0.01);
        let on_off: Vec<f64> = phi
            .iter()
            .zip(&f)
            .map(|(p, f)| if p.sin().abs() < 0.5 { *f } else { 0.0 })
            .collect();
        let cb = compare(&m, &sig, &on_off, &th).unwrap();
        let r = cb.per_regime.resonance.unwrap();
        let on = 4.0 * (0.5f64).asin() / TAU; // fraction with |sin φ| < 0.5
        assert!(
            (r.model_duty - on).abs() < 0.02,
            "model duty {}",
            r.model_duty
        );
        assert!((r.duty_error - (1.0 - on)).abs() < 0.02);
        // Its own classifier calls it post-resonance-like (on–off): labels disagree.
        assert_eq!(r.label_agreement, 0.0);
        assert!(cb.model_labels.iter().all(|&l| l != Regime::Resonance));
    }

    #[test]
    fn a_model_force_of_the_wrong_length_is_an_error() {
        let (t, phi, [x, v, a, f]) = record(|_, v| 40.0 * v);
        let sig = ForceData::new(&t, &x, &v, &a, &f);
        let th = RegimeThresholds::default();
        let m = classify(&sig, cycles_from_phase(&t, &phi).unwrap(), &th).unwrap();
        assert!(compare(&m, &sig, &f[1..], &th).is_err());
    }
}
