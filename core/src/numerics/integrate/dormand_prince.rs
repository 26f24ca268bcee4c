//! One step of the explicit Dormand–Prince 5(4) method, with its embedded error estimate,
//! Hairer's fourth-order continuous extension (dense output) and his stiffness indicator
//! `h·λ ≈ h·‖k7 − k6‖ / ‖y1 − y6‖` (both stages sit at `t + h`).
//!
//! The stepper of `ode_solvers` (see `dopri5.rs`) cannot be driven one step at a time nor
//! handed over to a stiff method mid-run, so the stiffness-switching integrator carries this
//! own copy of the same tableau.

use super::{OdeSystem, SimError};

const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// What a trial step produced.
pub(super) struct Trial {
    /// Scaled RMS error estimate (accept if ≤ 1); infinite if a stage was not finite.
    pub err: f64,
    /// Its square, the mean of the squared scaled errors (infinite with it), from which the
    /// step-size controller takes its root without waiting for the square root.
    pub err_squared: f64,
    /// Stiffness indicator h·λ (0 if undefined).
    pub h_lambda: f64,
}

/// Work buffers and the result of the last trial step.
pub(super) struct DormandPrince {
    k: [Vec<f64>; 7],
    ytmp: Vec<f64>,
    ysti: Vec<f64>,
    /// The state at `t + h` of the last trial step.
    pub y_new: Vec<f64>,
    /// Dense-output coefficients of the last accepted step (5 rows of `n`).
    cont: Vec<f64>,
}

impl DormandPrince {
    /// Buffers for `n` states.
    pub(super) fn new(n: usize) -> Self {
        DormandPrince {
            k: std::array::from_fn(|_| vec![0.0; n]),
            ytmp: vec![0.0; n],
            ysti: vec![0.0; n],
            y_new: vec![0.0; n],
            cont: vec![0.0; 5 * n],
        }
    }

    /// Move the last trial step's new state and its derivative `f(t + h, y_new)` (the first
    /// stage of the next step) into `y` and `f`, by swapping buffers (after [`Self::accept`]).
    pub(super) fn advance(&mut self, y: &mut Vec<f64>, f: &mut Vec<f64>) {
        std::mem::swap(y, &mut self.y_new);
        std::mem::swap(f, &mut self.k[6]);
    }

    /// Try a step of size `h` from `(t, y)` with `f0 = f(t, y)`; counts calls in `calls`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn trial(
        &mut self,
        sys: &dyn OdeSystem,
        t: f64,
        y: &[f64],
        f0: &[f64],
        h: f64,
        rtol: f64,
        atol: f64,
        calls: &mut u64,
    ) -> Result<Trial, SimError> {
        let n = y.len();
        // Slices of one known length, so that the loops below carry no bounds checks.
        // The first stage is f0 itself (no copy).
        let k1 = &f0[..n];
        let [_, k2, k3, k4, k5, k6, k7] = &mut self.k;
        let (k2, k3, k4) = (&mut k2[..n], &mut k3[..n], &mut k4[..n]);
        let (k5, k6, k7) = (&mut k5[..n], &mut k6[..n], &mut k7[..n]);
        let yt = &mut self.ytmp[..n];
        for i in 0..n {
            yt[i] = y[i] + h * A21 * k1[i];
        }
        sys.rhs(t + C2 * h, yt, k2)?;
        for i in 0..n {
            yt[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        sys.rhs(t + C3 * h, yt, k3)?;
        for i in 0..n {
            yt[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        sys.rhs(t + C4 * h, yt, k4)?;
        for i in 0..n {
            yt[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        sys.rhs(t + C5 * h, yt, k5)?;
        let ys = &mut self.ysti[..n];
        for i in 0..n {
            ys[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        let t_new = t + h;
        sys.rhs(t_new, ys, k6)?;
        let yn = &mut self.y_new[..n];
        for i in 0..n {
            yn[i] =
                y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        sys.rhs(t_new, yn, k7)?;
        *calls += 6;
        let mut sum = 0.0;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..n {
            let e =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
            let sk = atol + rtol * y[i].abs().max(yn[i].abs());
            sum += (e / sk) * (e / sk);
            num += (k7[i] - k6[i]) * (k7[i] - k6[i]);
            den += (yn[i] - ys[i]) * (yn[i] - ys[i]);
        }
        let err_squared = sum / n as f64;
        let (err, err_squared) = if err_squared.is_finite() {
            (err_squared.sqrt(), err_squared)
        } else {
            (f64::INFINITY, f64::INFINITY)
        };
        let h_lambda = if den > 0.0 {
            h.abs() * (num / den).sqrt()
        } else {
            0.0
        };
        Ok(Trial {
            err,
            err_squared,
            h_lambda,
        })
    }

    /// Keep the dense output of the last trial step from `(y, f0)` (call when accepting it).
    pub(super) fn accept(&mut self, y: &[f64], f0: &[f64], h: f64) {
        let n = y.len();
        let k1 = &f0[..n];
        let [_, _, k3, k4, k5, k6, k7] = &self.k;
        let (k3, k4, k5, k6, k7) = (&k3[..n], &k4[..n], &k5[..n], &k6[..n], &k7[..n]);
        let y_new = &self.y_new[..n];
        let (c0, rest) = self.cont.split_at_mut(n);
        let (c1, rest) = rest.split_at_mut(n);
        let (c2, rest) = rest.split_at_mut(n);
        let (c3, c4) = rest.split_at_mut(n);
        for i in 0..n {
            let ydiff = y_new[i] - y[i];
            let bspl = h * k1[i] - ydiff;
            c0[i] = y[i];
            c1[i] = ydiff;
            c2[i] = bspl;
            c3[i] = ydiff - h * k7[i] - bspl;
            c4[i] =
                h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
        }
    }

    /// The state at fraction `theta ∈ [0, 1]` of the last accepted step.
    #[inline(always)]
    pub(super) fn dense(&self, theta: f64, out: &mut [f64]) {
        let n = out.len();
        let s1 = 1.0 - theta;
        // Rows of one known length and an index loop: no bounds checks, no iterator set-up
        // (this runs once per output sample).
        let c = &self.cont;
        let (c0, c1, c2) = (&c[..n], &c[n..2 * n], &c[2 * n..3 * n]);
        let (c3, c4) = (&c[3 * n..4 * n], &c[4 * n..5 * n]);
        for i in 0..n {
            out[i] = c0[i] + theta * (c1[i] + s1 * (c2[i] + theta * (c3[i] + s1 * c4[i])));
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// y1' = y2, y2' = −y1 + cos(2t): exact y1 = (4/3)·cos t − (1/3)·cos 2t from (1, 0).
    struct Forced;
    impl OdeSystem for Forced {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
            dy[0] = y[1];
            dy[1] = -y[0] + (2.0 * t).cos();
            Ok(())
        }
    }

    fn exact(t: f64) -> f64 {
        4.0 / 3.0 * t.cos() - (2.0 * t).cos() / 3.0
    }

    fn fixed_steps(n: usize) -> (f64, f64) {
        let mut dp = DormandPrince::new(2);
        let (mut t, mut y, mut f0) = (0.0, vec![1.0, 0.0], vec![0.0; 2]);
        Forced.rhs(t, &y, &mut f0).unwrap();
        let h = 4.0 / n as f64;
        let mut calls = 0;
        let mut dense_err: f64 = 0.0;
        let mut mid = [0.0; 2];
        for _ in 0..n {
            dp.trial(&Forced, t, &y, &f0, h, 1.0, 1.0, &mut calls)
                .unwrap();
            dp.accept(&y, &f0, h);
            dp.dense(0.3, &mut mid);
            dense_err = dense_err.max((mid[0] - exact(t + 0.3 * h)).abs());
            dp.advance(&mut y, &mut f0);
            t += h;
        }
        ((y[0] - exact(t)).abs(), dense_err)
    }

    #[test]
    fn converges_with_order_five_and_dense_output_with_order_four() {
        let (e1, d1) = fixed_steps(10);
        let (e2, d2) = fixed_steps(20);
        let (e3, d3) = fixed_steps(40);
        let order = ((e1 / e2).log2() + (e2 / e3).log2()) / 2.0;
        let dense_order = ((d1 / d2).log2() + (d2 / d3).log2()) / 2.0;
        eprintln!("errors {e1:.2e} {e2:.2e} {e3:.2e} (order {order:.2}); dense {d1:.2e} {d2:.2e} {d3:.2e} (order {dense_order:.2})");
        assert!((4.6..5.6).contains(&order), "order {order}");
        assert!(dense_order > 3.7, "dense order {dense_order}");
    }

    #[test]
    fn stiffness_indicator_reads_h_times_the_eigenvalue() {
        // y' = −λ·y: k7 − k6 = −λ·(y1 − y6), so the indicator is exactly h·λ.
        struct Decay;
        impl OdeSystem for Decay {
            fn dim(&self) -> usize {
                1
            }
            fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
                dy[0] = -300.0 * y[0];
                Ok(())
            }
        }
        let mut dp = DormandPrince::new(1);
        let mut calls = 0;
        let trial = dp
            .trial(&Decay, 0.0, &[1.0], &[-300.0], 0.01, 1e-6, 1e-6, &mut calls)
            .unwrap();
        assert!((trial.h_lambda - 3.0).abs() < 1e-9, "{}", trial.h_lambda);
        assert_eq!(calls, 6);
    }
}
