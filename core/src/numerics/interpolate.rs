//! Interpolation of sampled signals between their samples.
//!
//! Measured signals drive simulations between samples. Holding each sample constant acts as
//! a half-sample delay (which a fitter would then "explain" with a spurious effect), so
//! signals are interpolated: linearly ([`Linear`]) or, where the derivative is known, by
//! cubic Hermite polynomials ([`Hermite`]). Outside the sampled span the end values are held.

/// Locate `t` in increasing `ts`: the index `i` with `ts[i] ≤ t < ts[i+1]`, clamped.
fn locate(ts: &[f64], uniform_step: Option<f64>, t: f64) -> usize {
    let n = ts.len();
    if n < 2 || t <= ts[0] {
        return 0;
    }
    if t >= ts[n - 1] {
        return n - 2;
    }
    if let Some(dt) = uniform_step {
        // On a grid uniform within [`NEARLY_UNIFORM`] (times written with a few decimals,
        // a DAQ's jitter), the guess from the mean step is at most a step or two off: walk.
        let mut i = (((t - ts[0]) / dt) as usize).min(n - 2);
        for _ in 0..WALK {
            if ts[i] > t {
                i -= 1;
            } else if ts[i + 1] <= t {
                i += 1;
            } else {
                return i;
            }
        }
    }
    ts.partition_point(|&x| x <= t).saturating_sub(1).min(n - 2)
}

/// The first sample time strictly after `t` (before the span: the first one; none from the last
/// one on, where the interpolant continues smoothly).
pub(crate) fn next_knot(ts: &[f64], uniform_step: Option<f64>, t: f64) -> Option<f64> {
    let (&first, &last) = (ts.first()?, ts.last()?);
    if t < first {
        return Some(first);
    }
    if t >= last {
        return None;
    }
    let i = locate(ts, uniform_step, t);
    ts[i..].iter().copied().find(|&knot| knot > t)
}

/// How far a step may stray from the mean (as a fraction of it) for the grid to count as
/// uniform: a located guess is then off by at most a step.
const NEARLY_UNIFORM: f64 = 0.1;

/// Steps [`locate`] walks from its guess before it falls back to a binary search.
const WALK: usize = 4;

fn uniform_step(ts: &[f64]) -> Option<f64> {
    let n = ts.len();
    if n < 2 {
        return None;
    }
    let dt = (ts[n - 1] - ts[0]) / (n - 1) as f64;
    let uniform = ts
        .windows(2)
        .all(|w| ((w[1] - w[0]) - dt).abs() <= NEARLY_UNIFORM * dt);
    uniform.then_some(dt)
}

/// Piecewise-linear interpolation of samples `(t_i, y_i)`.
#[derive(Clone, Debug)]
pub struct Linear {
    t: Vec<f64>,
    y: Vec<f64>,
    step: Option<f64>,
}

impl Linear {
    /// Interpolate `y` sampled at increasing times `t` (same length, at least one sample).
    pub fn new(t: Vec<f64>, y: Vec<f64>) -> Self {
        debug_assert_eq!(t.len(), y.len());
        let step = uniform_step(&t);
        Linear { t, y, step }
    }

    /// Samples held by a zero-order hold (a DAC's staircase): each value holds until the
    /// next sample. Built as a linear interpolant whose knots step from one value to the next
    /// within a thousandth of the sample step, so that an integrator, which ends its steps at
    /// knots, sees a constant drive over each step but for a ramp too short to matter (an
    /// equivalent delay of 5e-4 of a step).
    pub fn held(t: Vec<f64>, y: Vec<f64>) -> Self {
        debug_assert_eq!(t.len(), y.len());
        let (times, values) = (0..t.len())
            .flat_map(|i| {
                let ramp = (i > 0).then(|| (t[i] - 1e-3 * (t[i] - t[i - 1]), y[i - 1]));
                ramp.into_iter().chain([(t[i], y[i])])
            })
            .unzip();
        Linear::new(times, values)
    }

    /// Value at time `t`.
    pub fn at(&self, t: f64) -> f64 {
        match self.t.len() {
            0 => 0.0,
            1 => self.y[0],
            _ => {
                let i = locate(&self.t, self.step, t);
                let (t0, t1) = (self.t[i], self.t[i + 1]);
                let s = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
                self.y[i] + s * (self.y[i + 1] - self.y[i])
            }
        }
    }

    /// The sample times.
    pub fn times(&self) -> &[f64] {
        &self.t
    }

    /// The first sample time strictly after `t`, where the interpolant's slope may jump (none
    /// from the last sample on).
    pub fn next_knot(&self, t: f64) -> Option<f64> {
        next_knot(&self.t, self.step, t)
    }
}

/// Cubic Hermite interpolation of samples `(t_i, y_i)` with derivatives `dy_i`.
#[derive(Clone, Debug)]
pub struct Hermite {
    t: Vec<f64>,
    y: Vec<f64>,
    dy: Vec<f64>,
    step: Option<f64>,
}

impl Hermite {
    /// Interpolate `y` with slopes `dy`, sampled at increasing times `t`.
    pub fn new(t: Vec<f64>, y: Vec<f64>, dy: Vec<f64>) -> Self {
        debug_assert!(t.len() == y.len() && t.len() == dy.len());
        let step = uniform_step(&t);
        Hermite { t, y, dy, step }
    }

    /// The first sample time strictly after `t`, where the interpolant's second derivative may
    /// jump (none from the last sample on).
    pub fn next_knot(&self, t: f64) -> Option<f64> {
        next_knot(&self.t, self.step, t)
    }

    /// Value and derivative at time `t` (outside the span: linear continuation of the end).
    pub fn at(&self, t: f64) -> (f64, f64) {
        let n = self.t.len();
        if n == 0 {
            return (0.0, 0.0);
        }
        if n == 1 || t <= self.t[0] {
            return (self.y[0] + self.dy[0] * (t - self.t[0]), self.dy[0]);
        }
        if t >= self.t[n - 1] {
            return (
                self.y[n - 1] + self.dy[n - 1] * (t - self.t[n - 1]),
                self.dy[n - 1],
            );
        }
        let i = locate(&self.t, self.step, t);
        let h = self.t[i + 1] - self.t[i];
        let s = (t - self.t[i]) / h;
        let (y0, y1) = (self.y[i], self.y[i + 1]);
        let (m0, m1) = (self.dy[i] * h, self.dy[i + 1] * h);
        let s2 = s * s;
        let s3 = s2 * s;
        let value = (2.0 * s3 - 3.0 * s2 + 1.0) * y0
            + (s3 - 2.0 * s2 + s) * m0
            + (-2.0 * s3 + 3.0 * s2) * y1
            + (s3 - s2) * m1;
        let slope = ((6.0 * s2 - 6.0 * s) * y0
            + (3.0 * s2 - 4.0 * s + 1.0) * m0
            + (-6.0 * s2 + 6.0 * s) * y1
            + (3.0 * s2 - 2.0 * s) * m1)
            / h;
        (value, slope)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Times written with a few decimals are not exactly uniform: located by a walk from the
    /// mean step, they give the interval a binary search gives.
    #[test]
    fn a_nearly_uniform_grid_is_located_as_a_binary_search_does() {
        let dt = 1.0 / 610.35;
        let ts: Vec<f64> = (0..5000)
            .map(|i| ((66.6 + i as f64 * dt) * 1e7).round() / 1e7)
            .collect();
        let step = uniform_step(&ts);
        assert!(step.is_some());
        for k in 0..20_000 {
            let t = 66.59 + k as f64 * 4.1e-4;
            assert_eq!(locate(&ts, step, t), locate(&ts, None, t), "t = {t}");
        }
    }

    #[test]
    fn a_held_signal_keeps_each_sample_until_the_next() {
        let h = Linear::held(vec![0.0, 1.0, 2.0], vec![1.0, 3.0, -1.0]);
        for (t, want) in [
            (0.0, 1.0),
            (0.5, 1.0),
            (0.998, 1.0),
            (1.0, 3.0),
            (1.7, 3.0),
            (2.5, -1.0),
        ] {
            assert_relative_eq!(h.at(t), want);
        }
        assert_eq!(h.next_knot(0.5), Some(0.999));
        assert_eq!(h.next_knot(0.999), Some(1.0));
    }

    #[test]
    fn linear_is_exact_on_lines_and_holds_ends() {
        let t: Vec<f64> = (0..11).map(|i| i as f64 * 0.1).collect();
        let y: Vec<f64> = t.iter().map(|t| 3.0 * t - 1.0).collect();
        let l = Linear::new(t, y);
        assert_relative_eq!(l.at(0.437), 3.0 * 0.437 - 1.0, max_relative = 1e-12);
        assert_eq!(l.at(-5.0), -1.0);
        assert_relative_eq!(l.at(5.0), 2.0, max_relative = 1e-12);
    }

    #[test]
    fn the_next_knot_is_strictly_after_t_on_uniform_and_uneven_grids() {
        let uniform: Vec<f64> = (0..101).map(|i| 50.0 + i as f64 * 0.01).collect();
        let uneven = vec![0.0, 0.3, 0.35, 1.0, 2.2];
        for ts in [uniform, uneven] {
            let l = Linear::new(ts.clone(), vec![0.0; ts.len()]);
            let h = Hermite::new(ts.clone(), vec![0.0; ts.len()], vec![0.0; ts.len()]);
            assert_eq!(l.next_knot(ts[0] - 1.0), Some(ts[0]));
            for w in ts.windows(2) {
                // From a knot itself, from inside an interval and from just before the next.
                for t in [w[0], 0.5 * (w[0] + w[1]), w[1] - 1e-12] {
                    assert_eq!(l.next_knot(t), Some(w[1]), "{t}");
                    assert_eq!(h.next_knot(t), Some(w[1]), "{t}");
                }
            }
            let end = ts[ts.len() - 1];
            assert_eq!(l.next_knot(end), None);
            assert_eq!(h.next_knot(end + 3.0), None);
        }
    }

    #[test]
    fn hermite_is_exact_on_cubics_nonuniform() {
        let t = vec![0.0, 0.3, 0.35, 1.0, 2.2];
        let f = |t: f64| t * t * t - 2.0 * t + 0.5;
        let df = |t: f64| 3.0 * t * t - 2.0;
        let h = Hermite::new(
            t.clone(),
            t.iter().map(|&t| f(t)).collect(),
            t.iter().map(|&t| df(t)).collect(),
        );
        for q in [0.1, 0.33, 0.9, 1.7] {
            let (v, d) = h.at(q);
            assert_relative_eq!(v, f(q), max_relative = 1e-12);
            assert_relative_eq!(d, df(q), max_relative = 1e-12);
        }
    }
}
