//! A force model evaluated along a whole record at once.
//!
//! A force-level fit evaluates its model at every sample of a record hundreds of times. Called
//! sample by sample through `dyn ForceModel` — and, for a sum, once more through each part's
//! `dyn` — the calls themselves cost more than a simple law: on the source study's 150 001
//! samples, `ModelSum::mass_and_force` spent most of its own time returning from its parts'
//! indirect calls. [`ForceModel::mass_and_force_along`] and [`ForceModel::gradient_along`]
//! take the record instead: their provided versions ([`mass_and_force_along`],
//! [`gradient_along`]) are compiled for each model, so the per-sample calls inside are direct
//! and inlined, and a sum ([`crate::physics::model_sum::ModelSum`]) hands each part the whole
//! record once. The parts of a sum have independent internal states, so each part integrates
//! its own; the arithmetic is that of integrating them together, sample by sample, and the
//! added masses and forces add in the parts' order, so the results are the same to the bit.

use crate::physics::force_model::{ForceModel, ModelError, ModelState};

/// The kinematics a model is evaluated along: time (s), displacement (m) and velocity (m/s)
/// at every sample, of equal lengths, time strictly increasing.
#[derive(Clone, Copy, Debug)]
pub struct Track<'a> {
    /// Time, s.
    pub t: &'a [f64],
    /// Displacement, m.
    pub x: &'a [f64],
    /// Velocity, m/s.
    pub v: &'a [f64],
}

impl<'a> Track<'a> {
    /// The model's state at sample `i` with internal variables `z`.
    pub fn state<'z>(&self, i: usize, z: &'z [f64]) -> ModelState<'z> {
        ModelState {
            t: self.t[i],
            x: self.x[i],
            v: self.v[i],
            z,
        }
    }

    /// How many results an evaluation at `rows` (`None`: every sample) gives.
    pub fn len_at(&self, rows: Option<&[usize]>) -> usize {
        rows.map_or(self.t.len(), <[usize]>::len)
    }
}

/// The provided [`ForceModel::mass_and_force_along`]: adds `m`'s added mass and the rest of
/// its force at the `k`-th of `rows` (strictly increasing; `None`: every sample) to `mass[k]`
/// and `force[k]`. A model with internal state is integrated along every sample with one RK4
/// step per sample interval (the kinematics linear within it), its force taken at `rows`
/// only; elsewhere only the state's rates are evaluated.
pub fn mass_and_force_along<M: ForceModel + ?Sized>(
    m: &M,
    p: &[f64],
    track: &Track,
    rows: Option<&[usize]>,
    mass: &mut [f64],
    force: &mut [f64],
) -> Result<(), ModelError> {
    if m.n_internal() == 0 {
        for k in 0..track.len_at(rows) {
            let i = rows.map_or(k, |r| r[k]);
            let (ma, f) = m.mass_and_force(p, &track.state(i, &[]), &mut [])?;
            mass[k] += ma;
            force[k] += f;
        }
        return Ok(());
    }
    integrate(m, p, track, rows, |k, ma, f| {
        mass[k] += ma;
        force[k] += f;
    })
}

/// Integrate the internal state of `m` along `track`, calling `each(k, m_a, f)` at the
/// `k`-th of `rows`, as [`mass_and_force_along`] says.
///
/// A model with one or two internal variables (every built-in) keeps its state and stage
/// rates in fixed-size arrays: with the model's law inlined they live in registers, not in
/// memory between the stages, which shortens each step's chain of dependent operations. The
/// operations and their order are those of any other size, so the results are the same to
/// the bit.
fn integrate<M, F>(
    m: &M,
    p: &[f64],
    track: &Track,
    rows: Option<&[usize]>,
    each: F,
) -> Result<(), ModelError>
where
    M: ForceModel + ?Sized,
    F: FnMut(usize, f64, f64),
{
    match m.n_internal() {
        1 => {
            let mut b = [[0.0; 1]; 6];
            let [z, k1, k2, k3, k4, zs] = &mut b;
            steps(m, p, track, rows, each, [z, k1, k2, k3, k4, zs])
        }
        2 => {
            let mut b = [[0.0; 2]; 6];
            let [z, k1, k2, k3, k4, zs] = &mut b;
            steps(m, p, track, rows, each, [z, k1, k2, k3, k4, zs])
        }
        nz => {
            // z, stage rates k1..k4, stage state.
            let mut buf = vec![0.0; 6 * nz];
            let (z, rest) = buf.split_at_mut(nz);
            let (k1, rest) = rest.split_at_mut(nz);
            let (k2, rest) = rest.split_at_mut(nz);
            let (k3, rest) = rest.split_at_mut(nz);
            let (k4, zs) = rest.split_at_mut(nz);
            steps(m, p, track, rows, each, [z, k1, k2, k3, k4, zs])
        }
    }
}

/// The RK4 steps of [`integrate`] with the state `z`, the stage rates `k1`..`k4` and the
/// stage state `zs` in the buffers given (each of the model's number of internal variables).
#[inline(always)]
fn steps<M, F>(
    m: &M,
    p: &[f64],
    track: &Track,
    rows: Option<&[usize]>,
    mut each: F,
    [z, k1, k2, k3, k4, zs]: [&mut [f64]; 6],
) -> Result<(), ModelError>
where
    M: ForceModel + ?Sized,
    F: FnMut(usize, f64, f64),
{
    let nz = z.len();
    m.initial_internal(p, z);
    let t = track.t;
    let last = t.len() - 1;
    let mut next = 0;
    for i in 0..=last {
        let s = track.state(i, z);
        let k = rows.map_or(Some(i), |r| (r.get(next) == Some(&i)).then_some(next));
        if let Some(k) = k {
            let (ma, f) = m.mass_and_force(p, &s, k1)?;
            each(k, ma, f);
            next += 1;
        } else {
            m.rates(p, &s, k1)?;
        }
        if i == last {
            break;
        }
        let (h, tm, xm, vm) = interval(track, i);
        // The intermediate stages need only the rates, not the force.
        for j in 0..nz {
            zs[j] = z[j] + 0.5 * h * k1[j];
        }
        m.rates(p, &midpoint(tm, xm, vm, zs), k2)?;
        for j in 0..nz {
            zs[j] = z[j] + 0.5 * h * k2[j];
        }
        m.rates(p, &midpoint(tm, xm, vm, zs), k3)?;
        for j in 0..nz {
            zs[j] = z[j] + h * k3[j];
        }
        m.rates(p, &track.state(i + 1, zs), k4)?;
        for j in 0..nz {
            z[j] += h / 6.0 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
        }
    }
    Ok(())
}

/// The most parameter vectors [`mass_and_force_lanes`] integrates side by side: a Jacobian's
/// trial point and a four-parameter part's four columns go in one pass (with at most four,
/// the fifth was integrated alone: force-level discovery with one hidden effect took 2 % more
/// wall and CPU).
pub const MAX_LANES: usize = 6;

/// The provided [`ForceModel::mass_and_force_lanes`]: `m`'s added mass and force at `rows`
/// (`None`: every sample) for each of the parameter vectors `ps`, as
/// [`mass_and_force_along`] gives them into zeroed buffers, to the bit — or `None` when they
/// are not integrated side by side (a model without exactly one internal variable, fewer than
/// two or more than [`MAX_LANES`] vectors) or when the model errs for any of them: then each
/// is evaluated on its own, which gives its error.
///
/// A model's state is integrated sample by sample, each RK4 stage waiting on the one before:
/// one integration keeps a core's arithmetic units mostly idle. Integrating the difference
/// columns of a Jacobian together, stage by stage, gives the core independent chains to run
/// at once: three `bouc_wen` integrations of 150 001 samples took 10.2–10.4 ms side by side
/// against 22.7–24.2 ms one after another (a stand-alone measurement of the same loop, the
/// same bits). Each lane does the operations of [`steps`] in their order.
pub fn mass_and_force_lanes<M: ForceModel + ?Sized>(
    m: &M,
    ps: &[&[f64]],
    track: &Track,
    rows: Option<&[usize]>,
) -> Option<Vec<(Vec<f64>, Vec<f64>)>> {
    if m.n_internal() != 1 || track.t.is_empty() {
        return None;
    }
    match ps.len() {
        2 => lanes::<M, 2>(m, ps.try_into().ok()?, track, rows),
        3 => lanes::<M, 3>(m, ps.try_into().ok()?, track, rows),
        4 => lanes::<M, 4>(m, ps.try_into().ok()?, track, rows),
        5 => lanes::<M, 5>(m, ps.try_into().ok()?, track, rows),
        6 => lanes::<M, 6>(m, ps.try_into().ok()?, track, rows),
        _ => None,
    }
}

/// [`mass_and_force_lanes`] for `L` parameter vectors of a model with one internal variable.
fn lanes<M: ForceModel + ?Sized, const L: usize>(
    m: &M,
    ps: [&[f64]; L],
    track: &Track,
    rows: Option<&[usize]>,
) -> Option<Vec<(Vec<f64>, Vec<f64>)>> {
    let n = track.len_at(rows);
    let mut out: Vec<(Vec<f64>, Vec<f64>)> = (0..L).map(|_| (vec![0.0; n], vec![0.0; n])).collect();
    let mut z = [[0.0_f64; 1]; L];
    for (zl, p) in z.iter_mut().zip(ps) {
        m.initial_internal(p, zl);
    }
    let (mut k1, mut k2, mut k3, mut k4, mut zs) = (
        [[0.0_f64; 1]; L],
        [[0.0; 1]; L],
        [[0.0; 1]; L],
        [[0.0; 1]; L],
        [[0.0; 1]; L],
    );
    let t = track.t;
    let last = t.len() - 1;
    let mut next = 0;
    for i in 0..=last {
        let k = rows.map_or(Some(i), |r| (r.get(next) == Some(&i)).then_some(next));
        for l in 0..L {
            let s = track.state(i, &z[l]);
            if let Some(k) = k {
                let (ma, f) = m.mass_and_force(ps[l], &s, &mut k1[l]).ok()?;
                out[l].0[k] += ma;
                out[l].1[k] += f;
            } else {
                m.rates(ps[l], &s, &mut k1[l]).ok()?;
            }
        }
        if k.is_some() {
            next += 1;
        }
        if i == last {
            break;
        }
        let (h, tm, xm, vm) = interval(track, i);
        for l in 0..L {
            zs[l][0] = z[l][0] + 0.5 * h * k1[l][0];
            m.rates(ps[l], &midpoint(tm, xm, vm, &zs[l]), &mut k2[l])
                .ok()?;
        }
        for l in 0..L {
            zs[l][0] = z[l][0] + 0.5 * h * k2[l][0];
            m.rates(ps[l], &midpoint(tm, xm, vm, &zs[l]), &mut k3[l])
                .ok()?;
        }
        for l in 0..L {
            zs[l][0] = z[l][0] + h * k3[l][0];
            m.rates(ps[l], &track.state(i + 1, &zs[l]), &mut k4[l])
                .ok()?;
        }
        for l in 0..L {
            z[l][0] += h / 6.0 * (k1[l][0] + 2.0 * (k2[l][0] + k3[l][0]) + k4[l][0]);
        }
    }
    Some(out)
}

/// The sample interval from `i` to `i + 1` of `track`: its length and the kinematics at its
/// midpoint (linear within it).
#[inline(always)]
fn interval(track: &Track, i: usize) -> (f64, f64, f64, f64) {
    let (t, x, v) = (track.t, track.x, track.v);
    (
        t[i + 1] - t[i],
        0.5 * (t[i] + t[i + 1]),
        0.5 * (x[i] + x[i + 1]),
        0.5 * (v[i] + v[i + 1]),
    )
}

/// The state at an interval's midpoint: kinematics `t`, `x`, `v` with stage state `z`.
fn midpoint(t: f64, x: f64, v: f64, z: &[f64]) -> ModelState<'_> {
    ModelState { t, x, v, z }
}

/// The provided [`ForceModel::gradient_along`]: the gradient of `m`'s whole force
/// (`m_a·a + f`) at the `k`-th of `rows` (`None`: every sample), with acceleration `a[i]` at
/// sample `i`, written column by column to `grad` (parameter `j`'s entry at `k` in
/// `grad[j·n + k]`, `n` results); `Ok(false)` as soon as `m` gives no gradient at a sample.
/// The model's internal state is taken as zero (only models without state give one).
pub fn gradient_along<M: ForceModel + ?Sized>(
    m: &M,
    p: &[f64],
    track: &Track,
    a: &[f64],
    rows: Option<&[usize]>,
    grad: &mut [f64],
) -> Result<bool, ModelError> {
    let n = track.len_at(rows);
    let zeros = vec![0.0; m.n_internal()];
    let mut g = vec![0.0; m.params().len()];
    for k in 0..n {
        let i = rows.map_or(k, |r| r[k]);
        if !m.gradient(p, &track.state(i, &zeros), a[i], &mut g)? {
            return Ok(false);
        }
        for (j, gj) in g.iter().enumerate() {
            grad[j * n + k] = *gj;
        }
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::model_sum::ModelSum;
    use crate::physics::param_spec::ParamSpec;
    use crate::physics::test_models::{sine_kinematics, Relax};
    use std::sync::Arc;

    /// `c·v^3 + m_a` as added mass: memoryless, with a gradient.
    struct Cubic(Vec<ParamSpec>);
    impl ForceModel for Cubic {
        fn name(&self) -> &str {
            "cubic"
        }
        fn params(&self) -> &[ParamSpec] {
            &self.0
        }
        fn added_mass(&self, p: &[f64], _s: &ModelState) -> Result<f64, ModelError> {
            Ok(p[1])
        }
        fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
            Ok(p[0] * s.v.powi(3))
        }
        fn gradient(
            &self,
            _p: &[f64],
            s: &ModelState,
            a: f64,
            grad: &mut [f64],
        ) -> Result<bool, ModelError> {
            grad[..2].copy_from_slice(&[s.v.powi(3), a]);
            Ok(true)
        }
    }

    fn spec(name: &str) -> ParamSpec {
        ParamSpec::new(name, "", 1.0, 0.0, 10.0, "")
    }

    /// The sum's force sample by sample, its states integrated together (RK4 a sample
    /// interval): what a fit computed before models were evaluated along the record.
    fn sample_by_sample(m: &dyn ForceModel, p: &[f64], tr: &Track, rows: &[usize]) -> Vec<f64> {
        let nz = m.n_internal();
        let (mut z, mut k1, mut k2, mut k3, mut k4, mut zs) = (
            vec![0.0; nz],
            vec![0.0; nz],
            vec![0.0; nz],
            vec![0.0; nz],
            vec![0.0; nz],
            vec![0.0; nz],
        );
        m.initial_internal(p, &mut z);
        let mut out = Vec::new();
        let last = tr.t.len() - 1;
        for i in 0..=last {
            let (ma, f) = m.mass_and_force(p, &tr.state(i, &z), &mut k1).unwrap();
            if rows.contains(&i) {
                out.push(ma * 0.5 + f);
            }
            if i == last {
                break;
            }
            let h = tr.t[i + 1] - tr.t[i];
            let mid = |z: &[f64]| -> (f64, f64, f64, Vec<f64>) {
                (
                    0.5 * (tr.t[i] + tr.t[i + 1]),
                    0.5 * (tr.x[i] + tr.x[i + 1]),
                    0.5 * (tr.v[i] + tr.v[i + 1]),
                    z.to_vec(),
                )
            };
            let rates = |z: &[f64], k: &mut [f64]| {
                let (t, x, v, z) = mid(z);
                m.rates(p, &ModelState { t, x, v, z: &z }, k).unwrap();
            };
            for j in 0..nz {
                zs[j] = z[j] + 0.5 * h * k1[j];
            }
            rates(&zs, &mut k2);
            for j in 0..nz {
                zs[j] = z[j] + 0.5 * h * k2[j];
            }
            rates(&zs, &mut k3);
            for j in 0..nz {
                zs[j] = z[j] + h * k3[j];
            }
            m.rates(p, &tr.state(i + 1, &zs), &mut k4).unwrap();
            for j in 0..nz {
                z[j] += h / 6.0 * (k1[j] + 2.0 * (k2[j] + k3[j]) + k4[j]);
            }
        }
        out
    }

    /// `nz` coupled relaxations, each towards the one before (the first towards `c·v`).
    struct Chain(usize, Vec<ParamSpec>);
    impl ForceModel for Chain {
        fn name(&self) -> &str {
            "chain"
        }
        fn params(&self) -> &[ParamSpec] {
            &self.1
        }
        fn n_internal(&self) -> usize {
            self.0
        }
        fn force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, ModelError> {
            let mut towards = p[0] * s.v;
            for (j, (rate, &z)) in dz.iter_mut().zip(s.z).enumerate() {
                *rate = (towards - z) / (p[1] * (j + 1) as f64);
                towards = z;
            }
            Ok(s.z[self.0 - 1])
        }
    }

    /// Each state size (the fixed-size arrays of one and two variables, the buffer of more)
    /// integrates as the plain loop does, to the bit.
    #[test]
    fn every_state_size_integrates_as_sample_by_sample_to_the_bit() {
        let n = 400;
        let [t, x, v] = sine_kinematics(n, 30.0);
        let track = Track {
            t: &t,
            x: &x,
            v: &v,
        };
        let rows: Vec<usize> = (0..n).filter(|i| i % 4 != 2).collect();
        for nz in 1..=4 {
            let m = Chain(nz, vec![spec("c"), spec("tau")]);
            let p = [2.5, 0.02];
            let want = sample_by_sample(&m, &p, &track, &rows);
            let (mut mass, mut force) = (vec![0.0; rows.len()], vec![0.0; rows.len()]);
            m.mass_and_force_along(&p, &track, Some(&rows), &mut mass, &mut force)
                .unwrap();
            let got: Vec<f64> = mass.iter().zip(&force).map(|(m, f)| m * 0.5 + f).collect();
            assert_eq!(got, want, "{nz} internal variables");
            assert!(got.iter().any(|f| f.abs() > 1e-3), "{nz}: the state moved");
        }
    }

    /// Side by side, each parameter vector's integration is its own to the bit; a model
    /// error in any of them, or a model without exactly one internal variable, gives `None`.
    #[test]
    fn lanes_integrate_as_one_at_a_time_to_the_bit() {
        let n = 300;
        let [t, x, v] = sine_kinematics(n, 30.0);
        let track = Track {
            t: &t,
            x: &x,
            v: &v,
        };
        let rows: Vec<usize> = (0..n).filter(|i| i % 4 != 2).collect();
        let relax = Relax("slow", vec![spec("c"), spec("tau")]);
        let ps: Vec<[f64; 2]> = vec![
            [2.5, 0.02],
            [2.5000001, 0.02],
            [2.5, 0.0200001],
            [1.0, 0.5],
            [0.3, 0.07],
            [4.0, 0.011],
        ];
        let bits = |a: &[f64]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        for rows in [None, Some(rows.as_slice())] {
            for lanes in 2..=MAX_LANES {
                let p: Vec<&[f64]> = ps[..lanes].iter().map(|p| p.as_slice()).collect();
                let got = relax.mass_and_force_lanes(&p, &track, rows).unwrap();
                for (p, (mass, force)) in p.iter().zip(&got) {
                    let k = track.len_at(rows);
                    let (mut m1, mut f1) = (vec![0.0; k], vec![0.0; k]);
                    relax
                        .mass_and_force_along(p, &track, rows, &mut m1, &mut f1)
                        .unwrap();
                    assert_eq!(bits(&m1), bits(mass));
                    assert_eq!(bits(&f1), bits(force));
                    assert!(force.iter().any(|f| f.abs() > 1e-3), "the state moved");
                }
            }
        }
        let p: Vec<&[f64]> = ps.iter().map(|p| p.as_slice()).collect();
        assert!(relax.mass_and_force_lanes(&p[..1], &track, None).is_none());
        let chain = Chain(2, vec![spec("c"), spec("tau")]);
        assert!(chain.mass_and_force_lanes(&p[..2], &track, None).is_none());
        // A model error in one lane: none, so each is evaluated on its own and gives its own.
        struct Strict(Vec<ParamSpec>);
        impl ForceModel for Strict {
            fn name(&self) -> &str {
                "strict"
            }
            fn params(&self) -> &[ParamSpec] {
                &self.0
            }
            fn n_internal(&self) -> usize {
                1
            }
            fn force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, ModelError> {
                if p[1] <= 0.0 {
                    return Err(ModelError::new("strict", "tau must be positive"));
                }
                dz[0] = (p[0] * s.v - s.z[0]) / p[1];
                Ok(s.z[0])
            }
        }
        let strict = Strict(vec![spec("c"), spec("tau")]);
        assert!(strict.mass_and_force_lanes(&p[..2], &track, None).is_some());
        let bad: Vec<&[f64]> = vec![&[2.5, 0.02], &[2.5, 0.0]];
        assert!(strict.mass_and_force_lanes(&bad, &track, None).is_none());
    }

    #[test]
    fn a_sum_along_the_record_is_the_sum_sample_by_sample_to_the_bit() {
        let parts: Vec<Arc<dyn ForceModel>> = vec![
            Arc::new(Relax("slow", vec![spec("c1"), spec("tau1")])),
            Arc::new(Cubic(vec![spec("c"), spec("m_a")])),
            Arc::new(Relax("fast", vec![spec("c2"), spec("tau2")])),
        ];
        let sum = ModelSum::new(parts).unwrap();
        let p = [3.0, 0.2, 1.7, 0.4, 0.9, 0.03];
        let n = 500;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
        let x: Vec<f64> = t.iter().map(|t| 0.01 * (40.0 * t).sin()).collect();
        let v: Vec<f64> = t.iter().map(|t| 0.4 * (40.0 * t).cos()).collect();
        let track = Track {
            t: &t,
            x: &x,
            v: &v,
        };
        let rows: Vec<usize> = (0..n).filter(|i| i % 3 != 1).collect();
        let want = sample_by_sample(&sum, &p, &track, &rows);
        let (mut mass, mut force) = (vec![0.0; rows.len()], vec![0.0; rows.len()]);
        sum.mass_and_force_along(&p, &track, Some(&rows), &mut mass, &mut force)
            .unwrap();
        let got: Vec<f64> = mass.iter().zip(&force).map(|(m, f)| m * 0.5 + f).collect();
        assert_eq!(got, want);
        // The gradient: the memoryless part's columns, NaN for the parts with state.
        let a = vec![0.5; n];
        let mut grad = vec![0.0; rows.len() * p.len()];
        assert!(sum
            .gradient_along(&p, &track, &a, Some(&rows), &mut grad)
            .unwrap());
        let k = rows.len();
        assert!(grad[..2 * k].iter().all(|g| g.is_nan()));
        assert_eq!(grad[2 * k + 7], v[rows[7]].powi(3));
        assert_eq!(grad[3 * k + 7], 0.5);
        assert!(grad[4 * k..].iter().all(|g| g.is_nan()));
    }
}
