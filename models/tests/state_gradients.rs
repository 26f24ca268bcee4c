//! The built-ins with internal state (`bouc_wen`, `maxwell`) give the exact gradient of their
//! force along a record (`ForceModel::gradient_along`: the state's sensitivities carried
//! through the same RK4 steps as the state), which a force fit uses in place of differences.
//! It must agree with central differences of the force along the record
//! (`mass_and_force_along`) — alone, and in a sum beside memoryless parts — on records through
//! the rig's sensors (the derivative filter's v and a), at two sweep rates and seeds.

mod discovery_support;

use std::sync::Arc;

use discovery_support::{paper_record, record_at, Case};
use stf_core::physics::force_model::ForceModel;
use stf_core::physics::model_sum::ModelSum;
use stf_core::physics::track::Track;
use stf_models::find;

fn track(case: &Case) -> Track<'_> {
    Track {
        t: &case.t,
        x: &case.x,
        v: &case.v,
    }
}

/// The whole force `m_a·a + f` of `model` at `p` at the samples `rows`.
fn total(model: &dyn ForceModel, p: &[f64], case: &Case, rows: &[usize]) -> Vec<f64> {
    let n = rows.len();
    let (mut mass, mut force) = (vec![0.0; n], vec![0.0; n]);
    model
        .mass_and_force_along(p, &track(case), Some(rows), &mut mass, &mut force)
        .unwrap();
    rows.iter()
        .zip(mass.iter().zip(&force))
        .map(|(&i, (m, f))| m * case.a[i] + f)
        .collect()
}

/// The exact gradient of `model` at `p` along `case` against central differences (steps of
/// 1e-6 of each parameter): each column's rms difference within `1e-6` of its rms.
fn check(model: &dyn ForceModel, p: &[f64], case: &Case) {
    let rows: Vec<usize> = (0..case.t.len()).filter(|i| i % 3 != 1).collect();
    let n = rows.len();
    let mut grad = vec![f64::NAN; n * p.len()];
    assert!(model
        .gradient_along(p, &track(case), &case.a, Some(&rows), &mut grad)
        .unwrap());
    for (j, spec) in model.params().iter().enumerate() {
        let h = 1e-6 * p[j].abs();
        let (mut up, mut down) = (p.to_vec(), p.to_vec());
        up[j] += h;
        down[j] -= h;
        let (fu, fd) = (
            total(model, &up, case, &rows),
            total(model, &down, case, &rows),
        );
        let column = &grad[j * n..(j + 1) * n];
        let (mut diff, mut size) = (0.0, 0.0);
        for (g, (u, d)) in column.iter().zip(fu.iter().zip(&fd)) {
            let central = (u - d) / (2.0 * h);
            diff += (g - central).powi(2);
            size += central * central;
        }
        let (diff, size) = ((diff / n as f64).sqrt(), (size / n as f64).sqrt());
        assert!(
            size > 0.0 && diff <= 1e-6 * size,
            "{} ∂/∂{}: rms difference {diff:.3e} against rms {size:.3e}",
            model.name(),
            spec.name
        );
    }
}

fn sum(names: &[&str]) -> Arc<dyn ForceModel> {
    Arc::new(ModelSum::new(names.iter().map(|n| find(n).unwrap()).collect()).unwrap())
}

/// Two records through the rig's sensors: the paper's sweep (0.047 rad/s², 1 kHz, 150 001
/// samples, seed 3) and a faster one (0.1 rad/s², 200 Hz, 60 s, seed 8), each with a
/// hysteretic and a viscoelastic force in the truth.
fn records() -> Vec<Case> {
    let truth: &[(&str, &[f64])] = &[
        ("power_law", &[20.0, 1.5]),
        ("bouc_wen", &[1.0, 2e-3, 0.5]),
        ("maxwell", &[5.0, 0.05]),
    ];
    vec![
        paper_record(truth, 3),
        record_at(truth, 8, false, 200.0, 60.0),
    ]
}

#[test]
fn the_exact_gradients_of_the_models_with_state_match_differences_along_the_record() {
    for case in records() {
        check(find("bouc_wen").unwrap().as_ref(), &[1.0, 2e-3, 0.5], &case);
        check(find("bouc_wen").unwrap().as_ref(), &[3.0, 8e-3, 1.6], &case);
        check(find("maxwell").unwrap().as_ref(), &[5.0, 0.05], &case);
        check(find("maxwell").unwrap().as_ref(), &[40.0, 0.7], &case);
        let all = sum(&["power_law", "added_mass", "bouc_wen", "maxwell"]);
        check(
            all.as_ref(),
            &[20.0, 1.5, 1.5, 0.8, 3e-3, 0.4, 6.0, 0.03],
            &case,
        );
    }
}

/// A script or any model that gives no partials keeps its columns for differences: a sum
/// leaves NaN there and still gives its other parts' columns.
#[test]
fn a_part_without_partials_leaves_its_columns_to_differences() {
    let case = record_at(&[("power_law", &[20.0, 1.5])], 5, false, 200.0, 10.0);
    let bare = stf_core::physics::model_sum::ModelSum::new(vec![
        find("power_law").unwrap(),
        Arc::new(NoPartials(find("maxwell").unwrap())),
    ])
    .unwrap();
    let n = case.t.len();
    let mut grad = vec![0.0; 4 * n];
    assert!(bare
        .gradient_along(
            &[20.0, 1.5, 5.0, 0.05],
            &track(&case),
            &case.a,
            None,
            &mut grad
        )
        .unwrap());
    assert!(grad[..2 * n].iter().all(|g| g.is_finite()));
    assert!(grad[2 * n..].iter().all(|g| g.is_nan()));
}

/// A model with state that does not give its partials (as a script does).
struct NoPartials(Arc<dyn ForceModel>);

impl ForceModel for NoPartials {
    fn name(&self) -> &str {
        "no_partials"
    }
    fn params(&self) -> &[stf_core::physics::param_spec::ParamSpec] {
        self.0.params()
    }
    fn n_internal(&self) -> usize {
        self.0.n_internal()
    }
    fn force(
        &self,
        p: &[f64],
        s: &stf_core::physics::force_model::ModelState,
        dz: &mut [f64],
    ) -> Result<f64, stf_core::physics::force_model::ModelError> {
        self.0.force(p, s, dz)
    }
}
