//! A memoryless model's evaluation along a fit's rows, split in two halves that run in
//! parallel.
//!
//! A discovery fits many candidates at once, and both cores are busy while there are two fits
//! left; the last fit of a step, the base's fit and the final model's run alone, and one core
//! waited. Traced on a force-level discovery of the paper's sweep with one hidden effect, the
//! second core idled about 15 % of the run, much of it beside one fit of a memoryless sum
//! (`power_law + added_mass + jamming_on_off`, with its exact Jacobian) ending a step.
//!
//! Without internal state each sample's added mass, force and gradient depend on that sample
//! alone ([`ForceModel::mass_and_force_along`] and [`ForceModel::gradient_along`] write the
//! `k`-th of the rows from sample `rows[k]`), so the two halves of the rows are evaluated
//! apart and give what one pass gives, to the bit. The halves go to rayon's `join`: with the
//! other core busy, the second half runs right after the first on the same thread, at the
//! cost of a queue push; with it idle, it takes the second half. A model with state is
//! integrated along every sample in order and is never split.

use crate::physics::force_model::{ForceModel, ModelError};
use crate::physics::track::Track;

/// Fewest rows an evaluation is split at: below it a half is too short to pay for handing
/// it to the other thread.
pub const SPLIT_ROWS: usize = 8_192;

/// The rows in two halves, when `model` is memoryless and there are at least [`SPLIT_ROWS`]
/// of them; `None` otherwise.
fn halves<'r>(model: &dyn ForceModel, rows: Option<&'r [usize]>) -> Option<[&'r [usize]; 2]> {
    let rows = rows?;
    if model.n_internal() != 0 || rows.len() < SPLIT_ROWS {
        return None;
    }
    let (first, second) = rows.split_at(rows.len() / 2);
    Some([first, second])
}

/// [`ForceModel::mass_and_force_along`] of `model` at `p` along `track` at `rows`, added to
/// `mass` and `force`; a memoryless model's rows in two halves evaluated in parallel. The
/// first half's error first, as one pass meets it first.
pub fn mass_and_force_along(
    model: &dyn ForceModel,
    p: &[f64],
    track: &Track,
    rows: Option<&[usize]>,
    mass: &mut [f64],
    force: &mut [f64],
) -> Result<(), ModelError> {
    let Some([first, second]) = halves(model, rows) else {
        return model.mass_and_force_along(p, track, rows, mass, force);
    };
    let (mass_1, mass_2) = mass.split_at_mut(first.len());
    let (force_1, force_2) = force.split_at_mut(first.len());
    let (one, two) = rayon::join(
        || model.mass_and_force_along(p, track, Some(first), mass_1, force_1),
        || model.mass_and_force_along(p, track, Some(second), mass_2, force_2),
    );
    one.and(two)
}

/// [`ForceModel::gradient_along`] of `model` at `p` along `track` (accelerations `a`) at
/// `rows`, parameter `j`'s entry at the `k`-th row in `grad[j·n + k]`; a memoryless model's
/// rows in two halves evaluated in parallel, then placed as one pass places them.
pub fn gradient_along(
    model: &dyn ForceModel,
    p: &[f64],
    track: &Track,
    a: &[f64],
    rows: Option<&[usize]>,
    grad: &mut [f64],
) -> Result<bool, ModelError> {
    let Some(parts) = halves(model, rows) else {
        return model.gradient_along(p, track, a, rows, grad);
    };
    let n_params = p.len();
    let along = |half: &[usize]| {
        let mut g = vec![0.0; n_params * half.len()];
        model
            .gradient_along(p, track, a, Some(half), &mut g)
            .map(|given| (given, g))
    };
    let (one, two) = rayon::join(|| along(parts[0]), || along(parts[1]));
    let ((given_1, g1), (given_2, g2)) = (one?, two?);
    if !(given_1 && given_2) {
        return Ok(false);
    }
    let (n1, n2) = (parts[0].len(), parts[1].len());
    let n = n1 + n2;
    for j in 0..n_params {
        grad[j * n..j * n + n1].copy_from_slice(&g1[j * n1..(j + 1) * n1]);
        grad[j * n + n1..(j + 1) * n].copy_from_slice(&g2[j * n2..(j + 1) * n2]);
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::param_spec::ParamSpec;
    use crate::physics::test_models::{sine_kinematics, Law};

    /// Both halves give one pass's added mass, force and gradient to the bit, at rows with
    /// gaps, and a failure in either half is the failure one pass meets first.
    #[test]
    fn halves_give_one_pass_to_the_bit() {
        let spec = |n: &str| ParamSpec::new(n, "", 1.0, -10.0, 10.0, "");
        let law = Law(vec![spec("c"), spec("n"), spec("m_a"), spec("limit")]);
        let n = 3 * SPLIT_ROWS;
        let [t, x, v] = sine_kinematics(n, 7.0);
        let a: Vec<f64> = x.iter().map(|x| -49.0 * x).collect();
        let track = Track {
            t: &t,
            x: &x,
            v: &v,
        };
        let rows: Vec<usize> = (0..n).filter(|i| i % 5 != 2).collect();
        let m = rows.len();
        let p = [2.0, 1.4, 0.3, 1.0];
        let (mut mass, mut force) = (vec![0.5; m], vec![0.25; m]);
        let (mut mass_1, mut force_1) = (mass.clone(), force.clone());
        mass_and_force_along(&law, &p, &track, Some(&rows), &mut mass, &mut force).unwrap();
        law.mass_and_force_along(&p, &track, Some(&rows), &mut mass_1, &mut force_1)
            .unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&mass), bits(&mass_1));
        assert_eq!(bits(&force), bits(&force_1));
        let (mut grad, mut grad_1) = (vec![0.0; 4 * m], vec![0.0; 4 * m]);
        assert!(gradient_along(&law, &p, &track, &a, Some(&rows), &mut grad).unwrap());
        assert!(law
            .gradient_along(&p, &track, &a, Some(&rows), &mut grad_1)
            .unwrap());
        assert_eq!(bits(&grad), bits(&grad_1));
        // Too fast in both halves: the first half's error, as one pass.
        let slow = [2.0, 1.4, 0.3, 0.05];
        let err = |e: ModelError| e.to_string();
        let split = mass_and_force_along(&law, &slow, &track, Some(&rows), &mut mass, &mut force);
        let one = law.mass_and_force_along(&slow, &track, Some(&rows), &mut mass, &mut force);
        assert_eq!(split.map_err(err), one.map_err(err));
    }
}
