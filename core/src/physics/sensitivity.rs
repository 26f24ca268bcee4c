//! The exact gradient, along a record, of a force model with internal state.
//!
//! A model with state `ż = g(t, x, v, z; p)`, `F = m_a·a + f(t, x, v, z; p)` is integrated
//! along a record with one classical Runge–Kutta (RK4) step a sample interval
//! ([`crate::physics::track`]). Its force at a sample depends on the parameters through the
//! state too, so its gradient needs the state's sensitivities `S = ∂z/∂p`. They are carried
//! beside the state through the very same RK4 steps, the step map differentiated exactly:
//!
//! ```text
//! k₁ = g(z)          dk₁ = g_z(z)·S + g_p(z)
//! k₂ = g(z + h/2·k₁)  dk₂ = g_z(·)·(S + h/2·dk₁) + g_p(·)      (k₃, k₄ likewise)
//! z ← z + h/6·(k₁ + 2k₂ + 2k₃ + k₄)      S ← S + h/6·(dk₁ + 2dk₂ + 2dk₃ + dk₄)
//! ∂F/∂p = f_p + f_z·S
//! ```
//!
//! so the gradient is that of the residual a force fit minimises, not of the continuous
//! model, at the cost of one pass along the record (where forward differences take one pass
//! per parameter, each integrating the model again). A model gives its partial derivatives at
//! one state ([`ForceModel::state_partials`], [`StatePartials`]); the sensitivities start at
//! zero, so a model whose initial state depends on its parameters must not give them.

use crate::physics::force_model::{ForceModel, ModelError, ModelState};
use crate::physics::track::Track;

/// The partial derivatives of a model with internal state at one state, as
/// [`ForceModel::state_partials`] writes them (`np` parameters, `nz` internal states).
#[derive(Clone, Debug, PartialEq)]
pub struct StatePartials {
    /// ∂(m_a·a + f)/∂p_j at a fixed state: `np` entries.
    pub force_p: Vec<f64>,
    /// ∂(m_a·a + f)/∂z_i: `nz` entries.
    pub force_z: Vec<f64>,
    /// ∂ż_i/∂p_j at `i·np + j`: `nz·np` entries.
    pub rate_p: Vec<f64>,
    /// ∂ż_i/∂z_k at `i·nz + k`: `nz·nz` entries.
    pub rate_z: Vec<f64>,
}

impl StatePartials {
    /// Zeros for a model of `np` parameters and `nz` internal states.
    pub fn new(np: usize, nz: usize) -> Self {
        StatePartials {
            force_p: vec![0.0; np],
            force_z: vec![0.0; nz],
            rate_p: vec![0.0; nz * np],
            rate_z: vec![0.0; nz * nz],
        }
    }

    /// `ds = rate_z·s + rate_p`: the sensitivities' rate at stage sensitivities `s`
    /// (`nz × np`, row-major).
    fn rate_of(&self, s: &[f64], ds: &mut [f64]) {
        let (nz, np) = (self.force_z.len(), self.force_p.len());
        ds.copy_from_slice(&self.rate_p);
        for i in 0..nz {
            for k in 0..nz {
                let g = self.rate_z[i * nz + k];
                if g != 0.0 {
                    for j in 0..np {
                        ds[i * np + j] += g * s[k * np + j];
                    }
                }
            }
        }
    }
}

/// The provided [`ForceModel::gradient_along`] of a model with internal state: the gradient
/// of its whole force at the `k`-th of `rows` (`None`: every sample), acceleration `a[i]` at
/// sample `i`, parameter `j`'s entry at `grad[j·n + k]`, from its state and sensitivities
/// integrated along every sample as the module doc says; `Ok(false)` when the model gives no
/// partial derivatives.
pub fn gradient_along<M: ForceModel + ?Sized>(
    m: &M,
    p: &[f64],
    track: &Track,
    a: &[f64],
    rows: Option<&[usize]>,
    grad: &mut [f64],
) -> Result<bool, ModelError> {
    let (nz, np, n) = (m.n_internal(), p.len(), track.len_at(rows));
    let mut d = StatePartials::new(np, nz);
    let mut z = vec![0.0; nz];
    m.initial_internal(p, &mut z);
    let mut stepper = Stepper::new(nz, np, z);
    let (t, x, v) = (track.t, track.x, track.v);
    let last = t.len() - 1;
    let mut next = 0;
    for i in 0..=last {
        let s = track.state(i, &stepper.z);
        if !m.state_partials(p, &s, a[i], &mut stepper.k[0], &mut d)? {
            return Ok(false);
        }
        let k = rows.map_or(Some(i), |r| (r.get(next) == Some(&i)).then_some(next));
        if let Some(k) = k {
            for j in 0..np {
                let through: f64 = (0..nz).map(|q| d.force_z[q] * stepper.s[q * np + j]).sum();
                grad[j * n + k] = d.force_p[j] + through;
            }
            next += 1;
        }
        if i == last {
            break;
        }
        let h = t[i + 1] - t[i];
        let mid = (
            0.5 * (t[i] + t[i + 1]),
            0.5 * (x[i] + x[i + 1]),
            0.5 * (v[i] + v[i + 1]),
        );
        stepper.stage_derivative(0, &d);
        // Stages 2 and 3 at the interval's midpoint, 4 at its end (as the force's own RK4).
        for stage in 1..4 {
            let weight = if stage == 3 { h } else { 0.5 * h };
            stepper.stage_point(stage, weight);
            let zs = &stepper.zs;
            let s = if stage == 3 {
                track.state(i + 1, zs)
            } else {
                ModelState {
                    t: mid.0,
                    x: mid.1,
                    v: mid.2,
                    z: zs,
                }
            };
            if !m.state_partials(p, &s, 0.0, &mut stepper.k[stage], &mut d)? {
                return Ok(false);
            }
            stepper.stage_derivative(stage, &d);
        }
        stepper.advance(h);
    }
    Ok(true)
}

/// The state, its sensitivities and the RK4 stages of both along one interval.
struct Stepper {
    /// The state at the interval's start.
    z: Vec<f64>,
    /// Its sensitivities, `nz × np` row-major.
    s: Vec<f64>,
    /// The stages' rates of the state.
    k: [Vec<f64>; 4],
    /// The stages' rates of the sensitivities.
    dk: [Vec<f64>; 4],
    /// The current stage's state and sensitivities.
    zs: Vec<f64>,
    ss: Vec<f64>,
}

impl Stepper {
    fn new(nz: usize, np: usize, z: Vec<f64>) -> Self {
        let stage = || [vec![0.0; nz], vec![0.0; nz], vec![0.0; nz], vec![0.0; nz]];
        let sens = || {
            [
                vec![0.0; nz * np],
                vec![0.0; nz * np],
                vec![0.0; nz * np],
                vec![0.0; nz * np],
            ]
        };
        Stepper {
            z,
            s: vec![0.0; nz * np],
            k: stage(),
            dk: sens(),
            zs: vec![0.0; nz],
            ss: vec![0.0; nz * np],
        }
    }

    /// The point of stage `stage` (1–3): the start plus `weight` times the previous stage's
    /// rates, for the state (the same arithmetic as the force's RK4) and its sensitivities.
    fn stage_point(&mut self, stage: usize, weight: f64) {
        for (j, zs) in self.zs.iter_mut().enumerate() {
            *zs = self.z[j] + weight * self.k[stage - 1][j];
        }
        for (j, ss) in self.ss.iter_mut().enumerate() {
            *ss = self.s[j] + weight * self.dk[stage - 1][j];
        }
    }

    /// The sensitivities' rate at stage `stage` from the partials `d` there.
    fn stage_derivative(&mut self, stage: usize, d: &StatePartials) {
        let at = if stage == 0 { &self.s } else { &self.ss };
        d.rate_of(at, &mut self.dk[stage]);
    }

    /// One RK4 step of length `h` for the state and its sensitivities.
    fn advance(&mut self, h: f64) {
        let [k1, k2, k3, k4] = &self.k;
        for j in 0..self.z.len() {
            self.z[j] += h / 6.0 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
        }
        let [d1, d2, d3, d4] = &self.dk;
        for j in 0..self.s.len() {
            self.s[j] += h / 6.0 * (d1[j] + 2.0 * (d2[j] + d3[j]) + d4[j]);
        }
    }
}
