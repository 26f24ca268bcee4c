//! The latest contributions of a sum's parts along a record, kept between the evaluations of
//! a force fit.
//!
//! A force fit of a sum with a part that has internal state differences that part's columns
//! of the Jacobian: each difference changes one parameter and evaluates the whole sum along
//! the record again, the parts whose parameters did not change included (a power law's `pow`
//! at every sample, another part's state integrated along every sample). Here each part's
//! added mass and force along the record are kept for the last few values of its own
//! parameters ([`SLOTS`]), and an evaluation recomputes only the parts whose values are not
//! among them. The parts' contributions are then added in the sum's order, sample by sample,
//! exactly as [`crate::physics::model_sum::ModelSum`] adds them along the record: the
//! residuals are the same to the bit, so the fit takes the same steps and ends at the same
//! point.
//!
//! Only a sum of single terms is cached: a part of one term (a model, or a sum of one model,
//! as a base named alone is) adds its force once a sample, while a part that is a sum of
//! several adds its own parts one by one, and their total added at once would round
//! differently.

use std::collections::VecDeque;
use std::ops::Range;
use std::sync::{Arc, Mutex};

use super::objective::{lock, same_bits};
use crate::physics::force_model::{ForceModel, ModelError};
use crate::physics::track::{self, Track};

/// Values of one part's parameters kept, per part: the point where the Jacobian is taken,
/// the noise probes around it, and the columns being differenced in parallel.
pub const SLOTS: usize = 6;

/// A part's added mass and force at the fit's samples for the values `values`.
struct Contribution {
    values: Vec<f64>,
    mass: Vec<f64>,
    force: Vec<f64>,
}

/// The parts of a sum, their parameters' place among the sum's, and their kept
/// contributions (most recent first).
pub(super) struct PartCache {
    parts: Vec<(Arc<dyn ForceModel>, Range<usize>)>,
    kept: Vec<Mutex<VecDeque<Arc<Contribution>>>>,
}

impl PartCache {
    /// The cache of `model`'s parts, when it is a sum of at least two single terms with
    /// internal state among them (the parts whose columns are differenced); `None` otherwise.
    pub(super) fn of(model: &dyn ForceModel) -> Option<Self> {
        let summands = model.summands()?;
        let single = |p: &Arc<dyn ForceModel>| p.terms().len() == 1;
        if summands.len() < 2 || model.n_internal() == 0 || !summands.iter().all(single) {
            return None;
        }
        let mut start = 0;
        let parts = summands
            .iter()
            .map(|p| {
                let range = start..start + p.params().len();
                start = range.end;
                (p.clone(), range)
            })
            .collect();
        (start == model.params().len()).then(|| PartCache {
            parts,
            kept: summands
                .iter()
                .map(|_| Mutex::new(VecDeque::new()))
                .collect(),
        })
    }

    /// The sum's added mass and force at `p` along `track` at `rows` (`None`: every sample),
    /// added to `mass` and `force` as the sum's own `mass_and_force_along` adds them; a part
    /// whose values are kept is not evaluated again. A cache serves one track and one set of
    /// rows (a force fit's).
    pub(super) fn mass_and_force_along(
        &self,
        p: &[f64],
        track: &Track,
        rows: Option<&[usize]>,
        mass: &mut [f64],
        force: &mut [f64],
    ) -> Result<(), ModelError> {
        for (i, (part, range)) in self.parts.iter().enumerate() {
            let values = &p[range.clone()];
            let c = match self.find(i, values, mass.len()) {
                Some(c) => c,
                None => {
                    let n = mass.len();
                    let (mut m, mut f) = (vec![0.0; n], vec![0.0; n]);
                    part.mass_and_force_along(values, track, rows, &mut m, &mut f)?;
                    let c = Arc::new(Contribution {
                        values: values.to_vec(),
                        mass: m,
                        force: f,
                    });
                    self.keep(i, c.clone());
                    c
                }
            };
            // 0 + m is m bit for bit (a −0 becomes +0, which adds to a running sum alike).
            for (s, m) in mass.iter_mut().zip(&c.mass) {
                *s += m;
            }
            for (s, f) in force.iter_mut().zip(&c.force) {
                *s += f;
            }
        }
        Ok(())
    }

    /// Ahead of evaluations of the sum at each of `points` (a Jacobian's difference columns):
    /// each part with internal state whose values at two or more of them are not kept is
    /// integrated at those values (the first [`track::MAX_LANES`] of them) side by side
    /// ([`ForceModel::mass_and_force_lanes`]) and kept, so the evaluations that follow find
    /// it. Nothing changes in what they return: a
    /// contribution integrated so is the one an evaluation computes, to the bit, and a part
    /// that cannot be integrated side by side is left to the evaluations.
    pub(super) fn prefetch(&self, points: &[Vec<f64>], track: &Track, rows: Option<&[usize]>) {
        let n = track.len_at(rows);
        for (i, (part, range)) in self.parts.iter().enumerate() {
            if part.n_internal() == 0 {
                continue;
            }
            let mut missing: Vec<&[f64]> = Vec::new();
            for p in points {
                let values = &p[range.clone()];
                let known = missing.iter().any(|m| same_bits(m, values));
                if !known && self.find(i, values, n).is_none() {
                    missing.push(values);
                }
            }
            // More than fit side by side: the first ones, the rest left to the evaluations.
            missing.truncate(track::MAX_LANES.min(SLOTS));
            if missing.len() < 2 {
                continue;
            }
            let Some(found) = part.mass_and_force_lanes(&missing, track, rows) else {
                continue;
            };
            for (values, (mass, force)) in missing.iter().zip(found) {
                let c = Contribution {
                    values: values.to_vec(),
                    mass,
                    force,
                };
                self.keep(i, Arc::new(c));
            }
        }
    }

    /// Part `i`'s kept contribution at exactly `values` with `n` results, moved to the front.
    fn find(&self, i: usize, values: &[f64], n: usize) -> Option<Arc<Contribution>> {
        let mut kept = lock(&self.kept[i]);
        let at = kept
            .iter()
            .position(|c| c.mass.len() == n && same_bits(&c.values, values))?;
        let c = kept.remove(at)?;
        kept.push_front(c.clone());
        Some(c)
    }

    /// Keep part `i`'s contribution `c` in front, the oldest beyond [`SLOTS`] dropped.
    fn keep(&self, i: usize, c: Arc<Contribution>) {
        let mut kept = lock(&self.kept[i]);
        kept.push_front(c);
        kept.truncate(SLOTS);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::model_sum::ModelSum;
    use crate::physics::param_spec::ParamSpec;
    use crate::physics::test_models::{sine_kinematics, Law, Relax};

    fn spec(name: &str) -> ParamSpec {
        ParamSpec::new(name, "", 1.0, -10.0, 10.0, "")
    }

    /// Two parts with state around a memoryless law, itself a sum of one term (as a base
    /// named alone is).
    fn sum() -> ModelSum {
        let law: Arc<dyn ForceModel> = Arc::new(Law(vec![spec("c"), spec("n"), spec("m_a")]));
        ModelSum::new(vec![
            Arc::new(Relax("slow", vec![spec("c1"), spec("tau1")])),
            Arc::new(ModelSum::new(vec![law]).unwrap()),
            Arc::new(Relax("fast", vec![spec("c2"), spec("tau2")])),
        ])
        .unwrap()
    }

    #[test]
    fn kept_parts_give_the_sums_own_arithmetic_to_the_bit() {
        let sum = sum();
        let n = 700;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
        let x: Vec<f64> = t.iter().map(|t| 0.01 * (40.0 * t).sin()).collect();
        // Through zero and with negative zeros, where a signed zero could round differently.
        let v: Vec<f64> = t
            .iter()
            .map(|t| {
                if *t == 0.0 {
                    -0.0
                } else {
                    0.4 * (40.0 * t).cos()
                }
            })
            .collect();
        let track = Track {
            t: &t,
            x: &x,
            v: &v,
        };
        let rows: Vec<usize> = (0..n).filter(|i| i % 4 != 1).collect();
        let base = [3.0, 0.2, 1.7, 1.5, -0.0, 0.9, 0.03];
        // The point, then each parameter changed in turn (a difference column), the point
        // again, and a point where every part changes (a trial step).
        let mut points = vec![base.to_vec()];
        for j in 0..base.len() {
            let mut p = base.to_vec();
            p[j] += 1e-3;
            points.push(p);
            points.push(base.to_vec());
        }
        points.push(base.iter().map(|v| v * 1.01).collect());
        for rows in [None, Some(rows.as_slice())] {
            let cache = PartCache::of(&sum).unwrap();
            for p in &points {
                let k = track.len_at(rows);
                let (mut m1, mut f1) = (vec![0.0; k], vec![0.0; k]);
                sum.mass_and_force_along(p, &track, rows, &mut m1, &mut f1)
                    .unwrap();
                let (mut m2, mut f2) = (vec![0.0; k], vec![0.0; k]);
                cache
                    .mass_and_force_along(p, &track, rows, &mut m2, &mut f2)
                    .unwrap();
                let bits = |a: &[f64]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&m1), bits(&m2));
                assert_eq!(bits(&f1), bits(&f2));
            }
        }
        // The model's error, as the sum gives it.
        let mut bad = base.to_vec();
        bad[6] = -1.0;
        let cache = PartCache::of(&sum).unwrap();
        let (mut m, mut f) = (vec![0.0; n], vec![0.0; n]);
        let err = cache
            .mass_and_force_along(&bad, &track, None, &mut m, &mut f)
            .unwrap_err();
        assert!(err.to_string().contains("tau must be positive"), "{err}");
    }

    /// Difference columns prefetched side by side: each part with state is kept at every
    /// column's values, and the evaluations that follow are the sum's own to the bit.
    #[test]
    fn prefetched_columns_give_the_sums_own_arithmetic_to_the_bit() {
        let sum = sum();
        let n = 600;
        let [t, x, v] = sine_kinematics(n, 40.0);
        let track = Track {
            t: &t,
            x: &x,
            v: &v,
        };
        let rows: Vec<usize> = (0..n).filter(|i| i % 4 != 1).collect();
        let base = [3.0, 0.2, 1.7, 1.5, 0.5, 0.9, 0.03];
        let columns: Vec<Vec<f64>> = (0..base.len())
            .map(|j| {
                let mut p = base.to_vec();
                p[j] += 1e-3;
                p
            })
            .collect();
        let cache = PartCache::of(&sum).unwrap();
        let k = rows.len();
        let (mut m, mut f) = (vec![0.0; k], vec![0.0; k]);
        cache
            .mass_and_force_along(&base, &track, Some(&rows), &mut m, &mut f)
            .unwrap();
        cache.prefetch(&columns, &track, Some(&rows));
        // Both parts with state (the first and the last) are kept at their two columns' values.
        for (part, values) in [(0, &columns[1][..2]), (2, &columns[5][5..])] {
            assert!(cache.find(part, values, k).is_some(), "part {part}");
        }
        let bits = |a: &[f64]| a.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        for p in &columns {
            let (mut m1, mut f1) = (vec![0.0; k], vec![0.0; k]);
            sum.mass_and_force_along(p, &track, Some(&rows), &mut m1, &mut f1)
                .unwrap();
            let (mut m2, mut f2) = (vec![0.0; k], vec![0.0; k]);
            cache
                .mass_and_force_along(p, &track, Some(&rows), &mut m2, &mut f2)
                .unwrap();
            assert_eq!(bits(&m1), bits(&m2));
            assert_eq!(bits(&f1), bits(&f2));
        }
    }

    #[test]
    fn only_sums_of_single_terms_with_state_are_kept() {
        let memoryless = ModelSum::new(vec![
            Arc::new(Law(vec![spec("c"), spec("n"), spec("m_a")])) as Arc<dyn ForceModel>,
        ])
        .unwrap();
        assert!(PartCache::of(&memoryless).is_none());
        assert!(PartCache::of(&Relax("slow", vec![spec("c1"), spec("tau1")])).is_none());
        let nested = ModelSum::new(vec![
            Arc::new(sum()) as Arc<dyn ForceModel>,
            Arc::new(Relax("other", vec![spec("c3"), spec("tau3")])),
        ])
        .unwrap();
        assert!(PartCache::of(&nested).is_none());
        // A sum of one term as a part (a base named alone) adds once a sample: kept.
        let one = ModelSum::new(vec![
            Arc::new(
                ModelSum::new(vec![
                    Arc::new(Law(vec![spec("c"), spec("n"), spec("m_a")])) as Arc<dyn ForceModel>
                ])
                .unwrap(),
            ) as Arc<dyn ForceModel>,
            Arc::new(Relax("other", vec![spec("c3"), spec("tau3")])),
        ])
        .unwrap();
        assert!(PartCache::of(&one).is_some());
        assert!(PartCache::of(&sum()).is_some());
    }
}
