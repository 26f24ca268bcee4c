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
    integrate(m, p, track, rows, &mut |k, ma, f| {
        mass[k] += ma;
        force[k] += f;
    })
}

/// Integrate the internal state of `m` along `track`, calling `each(k, m_a, f)` at the
/// `k`-th of `rows`, as [`mass_and_force_along`] says.
fn integrate<M: ForceModel + ?Sized>(
    m: &M,
    p: &[f64],
    track: &Track,
    rows: Option<&[usize]>,
    each: &mut dyn FnMut(usize, f64, f64),
) -> Result<(), ModelError> {
    let nz = m.n_internal();
    // z, stage rates k1..k4, stage state.
    let mut buf = vec![0.0; 6 * nz];
    let (z, rest) = buf.split_at_mut(nz);
    let (k1, rest) = rest.split_at_mut(nz);
    let (k2, rest) = rest.split_at_mut(nz);
    let (k3, rest) = rest.split_at_mut(nz);
    let (k4, zs) = rest.split_at_mut(nz);
    m.initial_internal(p, z);
    let (t, x, v) = (track.t, track.x, track.v);
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
        let h = t[i + 1] - t[i];
        let (tm, xm, vm) = (
            0.5 * (t[i] + t[i + 1]),
            0.5 * (x[i] + x[i + 1]),
            0.5 * (v[i] + v[i + 1]),
        );
        // The intermediate stages need only the rates, not the force.
        for j in 0..nz {
            zs[j] = z[j] + 0.5 * h * k1[j];
        }
        m.rates(
            p,
            &ModelState {
                t: tm,
                x: xm,
                v: vm,
                z: zs,
            },
            k2,
        )?;
        for j in 0..nz {
            zs[j] = z[j] + 0.5 * h * k2[j];
        }
        m.rates(
            p,
            &ModelState {
                t: tm,
                x: xm,
                v: vm,
                z: zs,
            },
            k3,
        )?;
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
