//! Force-level calibration on synthetic data made here: recovery, offsets, internal states,
//! honesty about unidentifiable parameters, failures and non-convergence.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use stf_core::data::force_data::ForceData;
use stf_core::fit::{Convergence, FitError, FitParam, FitProgress, FitSettings, ForceFit, Solver};
use stf_core::physics::force_model::{ForceModel, ModelError, ModelState};
use stf_core::physics::model_sum::ModelSum;
use stf_core::physics::param_spec::ParamSpec;

/// `K·|v|ⁿ·sign v`; errs for n above `fail_above`; may carry an ignored parameter.
struct PowerLaw {
    specs: Vec<ParamSpec>,
    fail_above: f64,
}

impl PowerLaw {
    fn new() -> Self {
        PowerLaw {
            specs: vec![
                ParamSpec::new("K", "N (s/m)^n", 1.0, 0.0, 100.0, "consistency"),
                ParamSpec::new("n", "", 1.2, 1.0, 4.0, "exponent"),
            ],
            fail_above: f64::INFINITY,
        }
    }
    fn with_ghost(mut self) -> Self {
        self.specs
            .push(ParamSpec::new("ghost", "", 1.0, 0.0, 10.0, "ignored"));
        self
    }
}

impl ForceModel for PowerLaw {
    fn name(&self) -> &str {
        "power_law"
    }
    fn params(&self) -> &[ParamSpec] {
        &self.specs
    }
    fn force(&self, p: &[f64], s: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
        if p[1] > self.fail_above {
            return Err(ModelError::new("power_law", "exponent too large"));
        }
        Ok(p[0] * s.v.abs().powf(p[1]) * s.v.signum())
    }
}

/// Added mass only.
struct AddedMass(Vec<ParamSpec>);

impl ForceModel for AddedMass {
    fn name(&self) -> &str {
        "added_mass"
    }
    fn params(&self) -> &[ParamSpec] {
        &self.0
    }
    fn added_mass(&self, p: &[f64], _: &ModelState) -> Result<f64, ModelError> {
        Ok(p[0])
    }
    fn force(&self, _: &[f64], _: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
        Ok(0.0)
    }
}

/// Maxwell element: F = z, ż = G·v − z/τ.
struct Maxwell(Vec<ParamSpec>);

impl ForceModel for Maxwell {
    fn name(&self) -> &str {
        "maxwell"
    }
    fn params(&self) -> &[ParamSpec] {
        &self.0
    }
    fn n_internal(&self) -> usize {
        1
    }
    fn force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, ModelError> {
        dz[0] = p[0] * s.v - s.z[0] / p[1];
        Ok(s.z[0])
    }
}

/// Kinematics of a sine sweep: x = A·sin φ, φ = 2π(f0·t + β·t²/2), 1 kHz, 8 s.
struct Sweep {
    t: Vec<f64>,
    x: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
}

fn sweep() -> Sweep {
    let (amp, f0, beta) = (0.03, 0.3, 0.25);
    let mut s = Sweep {
        t: vec![],
        x: vec![],
        v: vec![],
        a: vec![],
    };
    for i in 0..8000 {
        let t = i as f64 * 1e-3;
        let phi = 2.0 * std::f64::consts::PI * (f0 * t + 0.5 * beta * t * t);
        let w = 2.0 * std::f64::consts::PI * (f0 + beta * t);
        let dw = 2.0 * std::f64::consts::PI * beta;
        s.t.push(t);
        s.x.push(amp * phi.sin());
        s.v.push(amp * w * phi.cos());
        s.a.push(amp * (dw * phi.cos() - w * w * phi.sin()));
    }
    s
}

fn noisy(f: impl Iterator<Item = f64>, sigma: f64, seed: u64) -> Vec<f64> {
    let mut rng = StdRng::seed_from_u64(seed);
    let normal = Normal::new(0.0, sigma).unwrap();
    f.map(|v| v + normal.sample(&mut rng)).collect()
}

fn data<'a>(s: &'a Sweep, f: &'a [f64]) -> ForceData<'a> {
    ForceData {
        t: &s.t,
        x: &s.x,
        v: &s.v,
        a: &s.a,
        f,
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

#[test]
fn power_law_recovers_k_and_n_within_two_percent() {
    let s = sweep();
    let f = noisy(
        s.v.iter().map(|v| 4.0 * v.abs().powf(1.5) * v.signum()),
        0.02,
        1,
    );
    let calls = AtomicU64::new(0);
    let observer = |_: FitProgress| {
        calls.fetch_add(1, Ordering::Relaxed);
    };
    let r = ForceFit::new(Arc::new(PowerLaw::new()))
        .fit(&data(&s, &f), Some(&observer))
        .unwrap();
    assert!(r.convergence.converged(), "{:?}", r.log);
    assert!(rel(r.value("K").unwrap(), 4.0) < 0.02, "{:?}", r.params);
    assert!(rel(r.value("n").unwrap(), 1.5) < 0.02, "{:?}", r.params);
    // The noise is the only residual left; the errors are small and honest.
    assert!(rel(r.rms, 0.02) < 0.05, "rms {}", r.rms);
    let se_k = r.std_error("K").unwrap();
    assert!(se_k > 0.0 && se_k < 0.05 * 4.0);
    assert!((r.value("K").unwrap() - 4.0).abs() < 5.0 * se_k);
    // argmin's observer shows the one Levenberg–Marquardt stage's start and each of its
    // iterations, then the standard errors' stage: all of it before the fit returns.
    assert_eq!(calls.load(Ordering::Relaxed), r.iterations + 2);
    let expected_aic = r.n_points as f64 * (r.rss / r.n_points as f64).ln() + 4.0;
    assert!((r.aic - expected_aic).abs() < 1e-9 * expected_aic.abs());
    assert!(r.bic > r.aic);
}

#[test]
fn power_law_plus_added_mass_recovers_all_three_within_five_percent() {
    let s = sweep();
    let truth =
        s.v.iter()
            .zip(&s.a)
            .map(|(v, a)| 4.0 * v.abs().powf(1.5) * v.signum() + 0.3 * a);
    let f = noisy(truth, 0.02, 2);
    let added = Arc::new(AddedMass(vec![ParamSpec::new(
        "m_a",
        "kg",
        0.1,
        0.0,
        5.0,
        "added mass",
    )]));
    let sum = ModelSum::new(vec![Arc::new(PowerLaw::new()), added]).unwrap();
    let r = ForceFit::new(Arc::new(sum))
        .fit(&data(&s, &f), None)
        .unwrap();
    assert!(r.convergence.converged(), "{:?}", r.log);
    assert!(rel(r.value("K").unwrap(), 4.0) < 0.05, "{:?}", r.params);
    assert!(rel(r.value("n").unwrap(), 1.5) < 0.05, "{:?}", r.params);
    assert!(rel(r.value("m_a").unwrap(), 0.3) < 0.05, "{:?}", r.params);
    assert_eq!(r.correlation.len(), 3);
}

#[test]
fn a_model_with_internal_state_is_integrated_along_the_kinematics() {
    let s = sweep();
    // Truth: ż = G·v − z/τ integrated finely (10 substeps per sample, exact v).
    let (g, tau) = (50.0, 0.05);
    let mut z = 0.0;
    let mut truth = Vec::with_capacity(s.t.len());
    for i in 0..s.t.len() {
        truth.push(z);
        if i + 1 < s.t.len() {
            for k in 0..10 {
                let frac = (k as f64 + 0.5) / 10.0;
                let v = s.v[i] + frac * (s.v[i + 1] - s.v[i]);
                z += 1e-4 * (g * v - z / tau);
            }
        }
    }
    let f = noisy(truth.into_iter(), 0.02, 3);
    let model = Arc::new(Maxwell(vec![
        ParamSpec::new("G", "N/m", 20.0, 0.0, 1e3, "stiffness"),
        ParamSpec::new("tau", "s", 0.1, 1e-4, 10.0, "relaxation time"),
    ]));
    let r = ForceFit::new(model).fit(&data(&s, &f), None).unwrap();
    assert!(rel(r.value("G").unwrap(), g) < 0.02, "{:?}", r.params);
    assert!(rel(r.value("tau").unwrap(), tau) < 0.02, "{:?}", r.params);
}

#[test]
fn a_force_offset_is_fitted_like_any_parameter() {
    let s = sweep();
    let f = noisy(
        s.v.iter()
            .map(|v| 4.0 * v.abs().powf(1.5) * v.signum() + 0.25),
        0.02,
        4,
    );
    let r = ForceFit::new(Arc::new(PowerLaw::new()))
        .offset(FitParam::new("f_off", 0.0))
        .fit(&data(&s, &f), None)
        .unwrap();
    assert!(
        (r.value("f_off").unwrap() - 0.25).abs() < 0.01,
        "{:?}",
        r.params
    );
    assert!(
        rel(r.value("K").unwrap(), 4.0) < 0.02,
        "{:?} {:?}",
        r.params,
        r.log
    );
}

#[test]
fn a_parameter_the_model_ignores_has_no_finite_error() {
    let s = sweep();
    let f = noisy(
        s.v.iter().map(|v| 4.0 * v.abs().powf(1.5) * v.signum()),
        0.02,
        5,
    );
    let r = ForceFit::new(Arc::new(PowerLaw::new().with_ghost()))
        .fit(&data(&s, &f), None)
        .unwrap();
    let se = r.std_error("ghost").unwrap();
    assert!(!se.is_finite() || se > 1e6, "ghost std error {se}");
    assert!(r.std_error("K").unwrap().is_finite());
}

#[test]
fn model_failures_become_penalties_and_are_counted() {
    let s = sweep();
    let f = noisy(
        s.v.iter().map(|v| 4.0 * v.abs().powf(1.5) * v.signum()),
        0.02,
        6,
    );
    let mut model = PowerLaw::new();
    model.fail_above = 2.0;
    let settings = FitSettings::default()
        .solver(Solver::ParticleSwarm)
        .max_iters(30)
        .particles(12);
    let r = ForceFit::new(Arc::new(model))
        .settings(settings)
        .fit(&data(&s, &f), None)
        .unwrap();
    assert!(r.failures > 0);
    assert!(r
        .last_failure
        .as_deref()
        .unwrap()
        .contains("exponent too large"));
    assert!(rel(r.value("n").unwrap(), 1.5) < 0.02, "{:?}", r.params);
}

#[test]
fn running_out_of_iterations_is_reported() {
    let s = sweep();
    let f = noisy(
        s.v.iter().map(|v| 4.0 * v.abs().powf(1.5) * v.signum()),
        0.02,
        7,
    );
    let r = ForceFit::new(Arc::new(PowerLaw::new()))
        .settings(
            FitSettings::default()
                .solver(Solver::NelderMead)
                .max_iters(3),
        )
        .fit(&data(&s, &f), None)
        .unwrap();
    assert_eq!(r.convergence, Convergence::MaxIterations);
    assert!(!r.convergence.converged());
}

#[test]
fn the_swarm_is_deterministic() {
    let s = sweep();
    let f = noisy(
        s.v.iter().map(|v| 2.0 * v.abs().powf(2.0) * v.signum()),
        0.02,
        8,
    );
    let run = || {
        ForceFit::new(Arc::new(PowerLaw::new()))
            .settings(
                FitSettings::default()
                    .solver(Solver::ParticleSwarm)
                    .max_iters(10)
                    .particles(8)
                    .seed(42),
            )
            .fit(&data(&s, &f), None)
            .unwrap()
    };
    let (a, b) = (run(), run());
    assert_eq!(a.params, b.params);
    assert_eq!(a.evaluations, b.evaluations);
}

#[test]
fn bad_requests_are_typed_errors() {
    let s = sweep();
    let f = vec![0.0; s.t.len()];
    let fit = || ForceFit::new(Arc::new(PowerLaw::new()));
    assert!(matches!(
        fit()
            .param(FitParam::new("q", 1.0))
            .fit(&data(&s, &f), None),
        Err(FitError::UnknownParam { .. })
    ));
    assert!(matches!(
        fit()
            .param(FitParam::new("n", 9.0).bounds(1.0, 4.0))
            .fit(&data(&s, &f), None),
        Err(FitError::OutOfBounds { .. })
    ));
    let short = &f[..10];
    assert!(matches!(
        fit().fit(&data(&s, short), None),
        Err(FitError::BadData(_))
    ));
}
