//! The stiff-capable methods (`Method::Auto`, the default, and `Method::Rodas4`) against known
//! solutions, a tight Dormand–Prince reference on stiff problems, and their failure modes.

use stf_core::numerics::integrate::{
    integrate, Method, OdeSystem, Settings, SimError, Solution, Stats,
};

const STIFF: [Method; 2] = [Method::Auto, Method::Rodas4];

fn settings(method: Method, rtol: f64, atol: f64) -> Settings {
    Settings::default().method(method).rtol(rtol).atol(atol)
}

fn grid(t0: f64, t1: f64, n: usize) -> Vec<f64> {
    (0..=n)
        .map(|i| t0 + (t1 - t0) * i as f64 / n as f64)
        .collect()
}

fn max_diff(a: &Solution, b: &Solution, component: usize) -> f64 {
    (0..a.t.len())
        .map(|i| (a.y(i)[component] - b.y(i)[component]).abs())
        .fold(0.0, f64::max)
}

struct Decay;
impl OdeSystem for Decay {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        dy[0] = -y[0];
        Ok(())
    }
}

#[test]
fn default_method_is_auto() {
    assert_eq!(Settings::default().method, Method::Auto);
    assert_eq!(Method::Auto.name(), "auto");
    assert_eq!(Method::Rodas4.name(), "rodas4");
    // Experiment files name methods in snake_case, as `name` does.
    for m in Method::ALL {
        assert_eq!(
            serde_json::to_string(&m).unwrap(),
            format!("\"{}\"", m.name())
        );
        let back: Method = serde_json::from_str(&format!("\"{}\"", m.name())).unwrap();
        assert_eq!(back, m);
    }
}

#[test]
fn linear_decay_at_arbitrary_output_times() {
    // Output times that fall between steps, one at the start, the last at the end.
    let t_out = [0.0, 0.013, 0.5, 1.7, 3.3, 5.0];
    for m in STIFF {
        let sol = integrate(&Decay, 0.0, &[1.0], &t_out, &settings(m, 1e-10, 1e-12)).unwrap();
        for (i, &t) in t_out.iter().enumerate() {
            let err = (sol.y(i)[0] - (-t).exp()).abs();
            assert!(err < 1e-8, "{m:?} at t = {t}: error {err:e}");
        }
    }
}

/// y' = A·(y − g(t)) + g'(t), A with eigenvalues −1 and −1e6 (eigenvectors (1, 1), (1, −1)),
/// g = (sin t, cos 2t): y(t) = g(t) + exp(A·t)·(y0 − g(0)). The slow eigenvalue is the
/// difference of two entries of size 5e5, so a finite-difference Jacobian gets it wrong by
/// about 1 %; `analytic` supplies the exact one through the Jacobian hook.
struct StiffLinear {
    analytic: bool,
}
const A_DIAG: f64 = -500_000.5;
const A_OFF: f64 = 499_999.5;
impl StiffLinear {
    fn exact(t: f64, y0: [f64; 2]) -> [f64; 2] {
        let (d0, d1) = (y0[0] - 0.0, y0[1] - 1.0);
        let (s, d) = (0.5 * (d0 + d1), 0.5 * (d0 - d1));
        let (es, ed) = ((-t).exp() * s, (-1e6 * t).exp() * d);
        [t.sin() + es + ed, (2.0 * t).cos() + es - ed]
    }
}
impl OdeSystem for StiffLinear {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        let (e0, e1) = (y[0] - t.sin(), y[1] - (2.0 * t).cos());
        dy[0] = A_DIAG * e0 + A_OFF * e1 + t.cos();
        dy[1] = A_OFF * e0 + A_DIAG * e1 - 2.0 * (2.0 * t).sin();
        Ok(())
    }
    fn jacobian(&self, t: f64, y: &[f64], fy: &[f64], jac: &mut [f64]) -> Result<u64, SimError> {
        if self.analytic {
            jac.copy_from_slice(&[A_DIAG, A_OFF, A_OFF, A_DIAG]);
            Ok(0)
        } else {
            let mut work = vec![0.0; 2];
            // The default: finite differences (as the trait's default body does).
            let h = [1e-8 * y[0].abs().max(1.0), 1e-8 * y[1].abs().max(1.0)];
            for j in 0..2 {
                let mut yp = y.to_vec();
                yp[j] += h[j];
                self.rhs(t, &yp, &mut work)?;
                for i in 0..2 {
                    jac[i * 2 + j] = (work[i] - fy[i]) / h[j];
                }
            }
            Ok(2)
        }
    }
}

fn stiff_linear_error(m: Method, analytic: bool, rtol: f64) -> (f64, Stats) {
    let y0 = [2.0, -1.0];
    let t_out = grid(0.0, 10.0, 1000);
    let sys = StiffLinear { analytic };
    let sol = integrate(&sys, 0.0, &y0, &t_out, &settings(m, rtol, 1e-2 * rtol)).unwrap();
    let err = (0..t_out.len())
        .map(|i| {
            let e = StiffLinear::exact(t_out[i], y0);
            (sol.y(i)[0] - e[0]).abs().max((sol.y(i)[1] - e[1]).abs())
        })
        .fold(0.0, f64::max);
    eprintln!(
        "{m:?}, analytic Jacobian {analytic}, rtol {rtol:e}: max error {err:.2e}, {:?}",
        sol.stats
    );
    (err, sol.stats)
}

#[test]
fn stiff_linear_system_matches_its_exact_solution_at_low_cost() {
    for m in STIFF {
        for analytic in [true, false] {
            let rtol = 1e-8;
            let (err, stats) = stiff_linear_error(m, analytic, rtol);
            // The problem contracts, so the global error is at most the sum of the local
            // errors, each within the tolerance on |y| ≤ 2.
            let bound = stats.accepted as f64 * rtol * 2.0;
            assert!(err < bound, "{m:?}: max error {err:e} above {bound:e}");
            // Held by stability, an explicit method would need h < 3.3e-6 s: ≥ 3 M steps.
            assert!(stats.rhs_calls < 30_000, "{m:?}: {stats:?}");
        }
    }
}

#[test]
fn stiff_linear_error_follows_the_tolerance() {
    for m in STIFF {
        let (loose, _) = stiff_linear_error(m, true, 1e-6);
        let (tight, _) = stiff_linear_error(m, true, 1e-9);
        assert!(tight < loose / 100.0, "{m:?}: {loose:e} → {tight:e}");
    }
}

/// Van der Pol, y1' = y2, y2' = μ·(1 − y1²)·y2 − y1, μ = 1000, from (1.2, ≈ its slow
/// manifold): a slow drift to y1 = 1, a fast jump to y1 ≈ −2 near t ≈ 38, a slow drift back.
struct VanDerPol;
impl OdeSystem for VanDerPol {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        dy[0] = y[1];
        dy[1] = 1000.0 * (1.0 - y[0] * y[0]) * y[1] - y[0];
        Ok(())
    }
}

#[test]
fn van_der_pol_mu_1000_matches_a_tight_dormand_prince_run() {
    // Samples on the slow branches before and after the jump.
    let t_out = [0.0, 10.0, 20.0, 30.0, 45.0, 60.0, 80.0, 100.0];
    let y0 = [1.2, 1.2 / (1000.0 * (1.0 - 1.44))];
    let reference = integrate(
        &VanDerPol,
        0.0,
        &y0,
        &t_out,
        &settings(Method::Dopri5, 1e-11, 1e-11),
    )
    .unwrap();
    assert!(
        reference.y(3)[0] > 1.0 && reference.y(4)[0] < -1.5,
        "the jump is inside the span"
    );
    for m in STIFF {
        let sol = integrate(&VanDerPol, 0.0, &y0, &t_out, &settings(m, 1e-8, 1e-8)).unwrap();
        let d = max_diff(&sol, &reference, 0);
        eprintln!(
            "{m:?}: max |Δy1| {d:.2e}, {:?} (reference {:?})",
            sol.stats, reference.stats
        );
        assert!(d < 1e-5, "{m:?}: max |Δy1| {d:e}");
        assert!(sol.stats.rhs_calls * 20 < reference.stats.rhs_calls);
    }
}

/// A trolley (m = 1 kg) against a stiff penalty wall (k_w = 1e6 N/m past |x| > gap), driven
/// harmonically, with an internal state z that relaxes in τ = 1e-4 s towards a steep gate of
/// the speed and adds a damping force k_s·z·v: `[x, v, z]`.
struct WallAndGate;
impl OdeSystem for WallAndGate {
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        let (x, v, z) = (y[0], y[1], y[2]);
        let gap = 0.01;
        let wall = if x.abs() > gap {
            1e6 * (x.abs() - gap) * x.signum()
        } else {
            0.0
        };
        let gate = 0.5 * (1.0 + ((v.abs() - 0.05) / 0.002).tanh());
        dy[0] = v;
        dy[1] = 5.0 * (5.0 * t).sin() - 100.0 * x - 0.5 * v - wall - 20.0 * z * v;
        dy[2] = (gate - z) / 1e-4;
        Ok(())
    }
}

#[test]
fn stiff_wall_and_steep_gate_with_an_internal_state() {
    let t_out = grid(0.0, 4.0, 4000);
    let y0 = [0.0, 0.0, 0.0];
    let reference = integrate(
        &WallAndGate,
        0.0,
        &y0,
        &t_out,
        &settings(Method::Dopri5, 1e-11, 1e-13),
    )
    .unwrap();
    let peak = (0..t_out.len())
        .map(|i| reference.y(i)[0].abs())
        .fold(0.0, f64::max);
    // 0.1 mm into the wall: a wall force above 100 N, far above the drive.
    assert!(
        peak > 0.0101,
        "the trolley is pushed into the wall (peak {peak})"
    );
    // Dormand–Prince at the same tolerance, for the accuracy a tolerance of 1e-8 buys: the gate
    // turns within ≈ 2e-4 s inside wall contacts, so z at a fixed time is very sensitive.
    let explicit = integrate(
        &WallAndGate,
        0.0,
        &y0,
        &t_out,
        &settings(Method::Dopri5, 1e-8, 1e-10),
    )
    .unwrap();
    let dz_explicit = max_diff(&explicit, &reference, 2);
    eprintln!(
        "Dopri5: max |Δx| {:.2e} m, |Δz| {dz_explicit:.2e}, {:?}",
        max_diff(&explicit, &reference, 0),
        explicit.stats
    );
    for m in STIFF {
        let sol = integrate(&WallAndGate, 0.0, &y0, &t_out, &settings(m, 1e-8, 1e-10)).unwrap();
        let dx = max_diff(&sol, &reference, 0);
        let dz = max_diff(&sol, &reference, 2);
        eprintln!("{m:?}: max |Δx| {dx:.2e} m, |Δz| {dz:.2e}, {:?}", sol.stats);
        assert!(dx < 1e-6, "{m:?}: max |Δx| {dx:e}");
        assert!(dz <= 2.0 * dz_explicit, "{m:?}: max |Δz| {dz:e}");
        // The default tolerances (what an experiment file gets without [integrator]) keep x
        // within a micrometre of the reference too.
        let default = Settings::default().method(m);
        let sol = integrate(&WallAndGate, 0.0, &y0, &t_out, &default).unwrap();
        let dx = max_diff(&sol, &reference, 0);
        eprintln!(
            "{m:?} at rtol {:e}: max |Δx| {dx:.2e} m, {:?}",
            default.rtol, sol.stats
        );
        assert!(
            dx < 1e-6,
            "{m:?} at the default tolerances: max |Δx| {dx:e}"
        );
    }
}

/// y' = y², y(0) = 1: y = 1/(1 − t) blows up at t = 1.
struct BlowUp;
impl OdeSystem for BlowUp {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        dy[0] = y[0] * y[0];
        Ok(())
    }
}

#[test]
fn a_blow_up_ends_with_an_error_at_its_time() {
    for m in STIFF {
        let e = integrate(
            &BlowUp,
            0.0,
            &[1.0],
            &[0.5, 2.0],
            &Settings::default().method(m),
        )
        .unwrap_err();
        let time = e.time().unwrap();
        assert!(
            matches!(
                e,
                SimError::StepSizeTooSmall { .. } | SimError::NonFinite { .. }
            ),
            "{m:?}: {e}"
        );
        assert!((0.9..1.001).contains(&time), "{m:?}: {e}");
    }
}

#[test]
fn a_failing_right_hand_side_is_returned_as_it_is() {
    struct FailsLate;
    impl OdeSystem for FailsLate {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&self, t: f64, _y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
            if t > 0.5 {
                return Err(SimError::BadSettings(format!("model failed at {t}")));
            }
            dy[0] = 1.0;
            Ok(())
        }
    }
    for m in STIFF {
        let e = integrate(
            &FailsLate,
            0.0,
            &[0.0],
            &[1.0],
            &Settings::default().method(m),
        )
        .unwrap_err();
        assert!(
            matches!(e, SimError::BadSettings(ref s) if s.starts_with("model failed")),
            "{e}"
        );
    }
}

#[test]
fn the_step_budget_is_honoured() {
    for m in STIFF {
        let e = integrate(
            &Decay,
            0.0,
            &[1.0],
            &[100.0],
            &Settings::default().method(m).max_steps(5),
        )
        .unwrap_err();
        assert!(
            matches!(e, SimError::TooManySteps { steps: 5, .. }),
            "{m:?}: {e}"
        );
    }
}

/// A forced oscillator with smoothed dry friction (ε = 1e-6), sliding with a reversal every
/// half period; `named` says whether it names its velocity as the switching component.
struct DryFriction {
    named: bool,
}
impl OdeSystem for DryFriction {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        let v = y[1];
        dy[0] = v;
        dy[1] = -4.0 * y[0] - 0.3 * v / (v * v + 1e-12).sqrt() + 2.0 * (1.5 * t).sin();
        Ok(())
    }
    fn switching_component(&self) -> Option<usize> {
        self.named.then_some(1)
    }
}

#[test]
fn naming_the_switching_component_saves_rejected_steps_at_reversals_not_accuracy() {
    let t_out = grid(0.0, 20.0, 2000);
    let y0 = [0.0, 0.0];
    let reference = integrate(
        &DryFriction { named: false },
        0.0,
        &y0,
        &t_out,
        &settings(Method::Dopri5, 1e-11, 1e-13),
    )
    .unwrap();
    let plain = integrate(
        &DryFriction { named: false },
        0.0,
        &y0,
        &t_out,
        &Settings::default(),
    )
    .unwrap();
    let named = integrate(
        &DryFriction { named: true },
        0.0,
        &y0,
        &t_out,
        &Settings::default(),
    )
    .unwrap();
    let (dx_plain, dx_named) = (
        max_diff(&plain, &reference, 0),
        max_diff(&named, &reference, 0),
    );
    eprintln!(
        "plain: {dx_plain:.2e}, {:?}; named: {dx_named:.2e}, {:?}",
        plain.stats, named.stats
    );
    // Both are error-controlled alike; the cap only shortens steps.
    assert!(
        dx_named < 1e-6 && dx_plain < 1e-6,
        "{dx_named:e} {dx_plain:e}"
    );
    assert!(
        named.stats.rejected * 2 < plain.stats.rejected,
        "{:?} vs {:?}",
        named.stats,
        plain.stats
    );
    assert!(named.stats.rhs_calls < plain.stats.rhs_calls);
}
