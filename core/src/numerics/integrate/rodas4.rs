//! One step of Rodas4, the L-stable, stiffly accurate Rosenbrock method of order 4(3) of
//! Hairer & Wanner (Solving ODEs II, §IV.7; coefficients of their code RODAS, method 1),
//! with its embedded error estimate (the last stage) and its third-order dense output.
//!
//! Stage `i` solves `(1/(γh)·I − J)·k_i = f(t + c_i h, y + Σ a_ij k_j) + Σ (c_ij/h)·k_j
//! + h·d_i·∂f/∂t`; the new state is the argument of stage 6 plus `k_6`, and `k_6` is the error
//! estimate. `J` and `∂f/∂t` are taken once per step start (reused after a rejection) from the
//! system's [`OdeSystem::jacobian`] (finite differences unless the system supplies one).

use super::dense_lu::DenseLu;
use super::rhs_jacobian::{fd_time_derivative, spectral_radius};
use super::{OdeSystem, SimError};

const GAMMA: f64 = 0.25;
const C2: f64 = 0.386;
const C3: f64 = 0.21;
const C4: f64 = 0.63;
const D1: f64 = 0.25;
const D2: f64 = -0.1043;
const D3: f64 = 0.1035;
const D4: f64 = -0.036_200_000_000_000_23;
const A21: f64 = 1.544;
const A31: f64 = 0.946_678_528_081_582_6;
const A32: f64 = 0.255_701_169_898_328_4;
const A41: f64 = 3.314_825_187_068_521;
const A42: f64 = 2.896_124_015_972_201;
const A43: f64 = 0.998_641_913_997_781_7;
const A51: f64 = 1.221_224_509_226_641;
const A52: f64 = 6.019_134_481_288_629;
const A53: f64 = 12.537_083_329_320_87;
const A54: f64 = -0.687_886_036_105_895;
const C21: f64 = -5.6688;
const C31: f64 = -2.430_093_356_833_875;
const C32: f64 = -0.206_359_915_709_191_5;
const C41: f64 = -0.107_352_905_815_137_5;
const C42: f64 = -9.594_562_251_023_355;
const C43: f64 = -20.470_286_148_096_16;
const C51: f64 = 7.496_443_313_967_647;
const C52: f64 = -10.246_804_314_643_52;
const C53: f64 = -33.999_903_528_199_05;
const C54: f64 = 11.708_908_932_061_6;
const C61: f64 = 8.083_246_795_921_522;
const C62: f64 = -7.981_132_988_064_893;
const C63: f64 = -31.521_594_328_743_71;
const C64: f64 = 16.319_305_431_231_36;
const C65: f64 = -6.058_818_238_834_054;
const H21: f64 = 10.126_235_083_445_86;
const H22: f64 = -7.487_995_877_610_167;
const H23: f64 = -34.800_918_615_557_47;
const H24: f64 = -7.992_771_707_568_823;
const H25: f64 = 1.025_137_723_295_662;
const H31: f64 = -0.676_280_339_280_125_3;
const H32: f64 = 6.087_714_651_680_015;
const H33: f64 = 16.430_843_208_924_78;
const H34: f64 = 24.767_225_114_183_86;
const H35: f64 = -6.594_389_125_716_872;

/// Work buffers, the Jacobian at the step start and the result of the last trial step.
pub(super) struct Rodas4 {
    n: usize,
    jac: Vec<f64>,
    ft: Vec<f64>,
    lu: DenseLu,
    k: [Vec<f64>; 6],
    ytmp: Vec<f64>,
    ftmp: Vec<f64>,
    /// The state at `t + h` of the last trial step.
    pub y_new: Vec<f64>,
    /// Dense-output coefficients of the last accepted step (4 rows of `n`).
    cont: Vec<f64>,
}

impl Rodas4 {
    /// Buffers for `n` states.
    pub(super) fn new(n: usize) -> Self {
        Rodas4 {
            n,
            jac: vec![0.0; n * n],
            ft: vec![0.0; n],
            lu: DenseLu::new(n),
            k: std::array::from_fn(|_| vec![0.0; n]),
            ytmp: vec![0.0; n],
            ftmp: vec![0.0; n],
            y_new: vec![0.0; n],
            cont: vec![0.0; 4 * n],
        }
    }

    /// Take `J` and `∂f/∂t` at a new step start `(t, y)` with `f0 = f(t, y)`.
    pub(super) fn linearise(
        &mut self,
        sys: &dyn OdeSystem,
        t: f64,
        y: &[f64],
        f0: &[f64],
        calls: &mut u64,
    ) -> Result<(), SimError> {
        *calls += sys.jacobian(t, y, f0, &mut self.jac)?;
        fd_time_derivative(|t, y, dy| sys.rhs(t, y, dy), t, y, f0, &mut self.ft)?;
        *calls += 1;
        Ok(())
    }

    /// Whether the Jacobian and `∂f/∂t` taken by [`Rodas4::linearise`] are finite.
    pub(super) fn jacobian_is_finite(&self) -> bool {
        self.jac.iter().chain(&self.ft).all(|v| v.is_finite())
    }

    /// Spectral radius of the Jacobian at the step start.
    pub(super) fn spectral_radius(&self) -> f64 {
        spectral_radius(&self.jac, self.n)
    }

    /// Try a step of size `h` from `(t, y)` with `f0 = f(t, y)`, after [`Rodas4::linearise`].
    /// Returns the scaled RMS error (infinite if the matrix is singular or a stage is not
    /// finite).
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
    ) -> Result<f64, SimError> {
        let n = self.n;
        let fac = 1.0 / (GAMMA * h);
        {
            let m = self.lu.matrix_mut();
            for (mi, ji) in m.iter_mut().zip(&self.jac) {
                *mi = -ji;
            }
            for i in 0..n {
                m[i * n + i] += fac;
            }
        }
        if !self.lu.factor() {
            return Ok(f64::INFINITY);
        }
        let inv_h = 1.0 / h;
        let [k1, k2, k3, k4, k5, k6] = &mut self.k;
        let (yt, ft, fx) = (&mut self.ytmp, &mut self.ftmp, &self.ft);
        // Stage 1.
        for i in 0..n {
            k1[i] = f0[i] + h * D1 * fx[i];
        }
        self.lu.solve(k1);
        // Stage 2.
        for i in 0..n {
            yt[i] = y[i] + A21 * k1[i];
        }
        sys.rhs(t + C2 * h, yt, ft)?;
        for i in 0..n {
            k2[i] = ft[i] + h * D2 * fx[i] + C21 * k1[i] * inv_h;
        }
        self.lu.solve(k2);
        // Stage 3.
        for i in 0..n {
            yt[i] = y[i] + A31 * k1[i] + A32 * k2[i];
        }
        sys.rhs(t + C3 * h, yt, ft)?;
        for i in 0..n {
            k3[i] = ft[i] + h * D3 * fx[i] + (C31 * k1[i] + C32 * k2[i]) * inv_h;
        }
        self.lu.solve(k3);
        // Stage 4.
        for i in 0..n {
            yt[i] = y[i] + A41 * k1[i] + A42 * k2[i] + A43 * k3[i];
        }
        sys.rhs(t + C4 * h, yt, ft)?;
        for i in 0..n {
            k4[i] = ft[i] + h * D4 * fx[i] + (C41 * k1[i] + C42 * k2[i] + C43 * k3[i]) * inv_h;
        }
        self.lu.solve(k4);
        // Stage 5, at t + h.
        for i in 0..n {
            yt[i] = y[i] + A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i];
        }
        let t_new = t + h;
        sys.rhs(t_new, yt, ft)?;
        for i in 0..n {
            k5[i] = ft[i] + (C51 * k1[i] + C52 * k2[i] + C53 * k3[i] + C54 * k4[i]) * inv_h;
        }
        self.lu.solve(k5);
        // Stage 6, at t + h; its argument plus k6 is the new state, k6 the error.
        for i in 0..n {
            yt[i] += k5[i];
        }
        sys.rhs(t_new, yt, ft)?;
        for i in 0..n {
            k6[i] = ft[i]
                + (C61 * k1[i] + C62 * k2[i] + C63 * k3[i] + C64 * k4[i] + C65 * k5[i]) * inv_h;
        }
        self.lu.solve(k6);
        *calls += 5;
        let mut sum = 0.0;
        for i in 0..n {
            let yn = yt[i] + k6[i];
            self.y_new[i] = yn;
            let sk = atol + rtol * y[i].abs().max(yn.abs());
            sum += (k6[i] / sk) * (k6[i] / sk);
        }
        let err = (sum / n as f64).sqrt();
        Ok(if err.is_finite() { err } else { f64::INFINITY })
    }

    /// Move the last trial step's new state into `y` by swapping buffers (after
    /// [`Self::accept`]).
    pub(super) fn advance(&mut self, y: &mut Vec<f64>) {
        std::mem::swap(y, &mut self.y_new);
    }

    /// Keep the dense output of the last trial step (call when accepting it).
    pub(super) fn accept(&mut self, y: &[f64]) {
        let n = self.n;
        let [k1, k2, k3, k4, k5, _] = &self.k;
        let (c0, rest) = self.cont.split_at_mut(n);
        let (c1, rest) = rest.split_at_mut(n);
        let (c2, c3) = rest.split_at_mut(n);
        for i in 0..n {
            c0[i] = y[i];
            c1[i] = self.y_new[i];
            c2[i] = H21 * k1[i] + H22 * k2[i] + H23 * k3[i] + H24 * k4[i] + H25 * k5[i];
            c3[i] = H31 * k1[i] + H32 * k2[i] + H33 * k3[i] + H34 * k4[i] + H35 * k5[i];
        }
    }

    /// The state at fraction `theta ∈ [0, 1]` of the last accepted step.
    #[inline(always)]
    pub(super) fn dense(&self, theta: f64, out: &mut [f64]) {
        let n = out.len();
        let s1 = 1.0 - theta;
        let c = &self.cont;
        let (c0, c1, c2, c3) = (&c[..n], &c[n..2 * n], &c[2 * n..3 * n], &c[3 * n..4 * n]);
        for i in 0..n {
            out[i] = c0[i] * s1 + theta * (c1[i] + s1 * (c2[i] + theta * c3[i]));
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// y' = −2t·y², y(0) = 1: y = 1/(1 + t²) (non-autonomous, so ∂f/∂t matters).
    struct Riccati;
    impl OdeSystem for Riccati {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
            dy[0] = -2.0 * t * y[0] * y[0];
            Ok(())
        }
    }

    /// Fixed steps over [0, 2]; returns the error at the end and the largest error of the
    /// dense output at the midpoints.
    fn fixed_steps(n: usize) -> (f64, f64) {
        let exact = |t: f64| 1.0 / (1.0 + t * t);
        let mut r = Rodas4::new(1);
        let (mut t, mut y, mut f0) = (0.0, vec![1.0], vec![0.0]);
        let h = 2.0 / n as f64;
        let mut calls = 0;
        let mut dense_err: f64 = 0.0;
        let mut mid = [0.0];
        for _ in 0..n {
            Riccati.rhs(t, &y, &mut f0).unwrap();
            r.linearise(&Riccati, t, &y, &f0, &mut calls).unwrap();
            r.trial(&Riccati, t, &y, &f0, h, 1.0, 1.0, &mut calls)
                .unwrap();
            r.accept(&y);
            r.dense(0.5, &mut mid);
            dense_err = dense_err.max((mid[0] - exact(t + 0.5 * h)).abs());
            y.copy_from_slice(&r.y_new);
            t += h;
        }
        ((y[0] - exact(t)).abs(), dense_err)
    }

    #[test]
    fn converges_with_order_four_and_dense_output_with_order_three() {
        let (e1, d1) = fixed_steps(20);
        let (e2, d2) = fixed_steps(40);
        let (e3, d3) = fixed_steps(80);
        let order = ((e1 / e2).log2() + (e2 / e3).log2()) / 2.0;
        let dense_order = ((d1 / d2).log2() + (d2 / d3).log2()) / 2.0;
        eprintln!("errors {e1:.2e} {e2:.2e} {e3:.2e} (order {order:.2}); dense {d1:.2e} {d2:.2e} {d3:.2e} (order {dense_order:.2})");
        assert!((3.6..4.6).contains(&order), "order {order}");
        assert!(dense_order > 2.7, "dense order {dense_order}");
    }

    #[test]
    fn is_l_stable_on_a_very_stiff_linear_decay() {
        // y' = −1e8·y with one step of h = 1: the exact factor is 0; A-stable but not
        // L-stable methods would leave a factor near ±1.
        struct Fast;
        impl OdeSystem for Fast {
            fn dim(&self) -> usize {
                1
            }
            fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
                dy[0] = -1e8 * y[0];
                Ok(())
            }
        }
        let mut r = Rodas4::new(1);
        let y = [1.0];
        let mut f0 = [0.0];
        Fast.rhs(0.0, &y, &mut f0).unwrap();
        let mut calls = 0;
        r.linearise(&Fast, 0.0, &y, &f0, &mut calls).unwrap();
        r.trial(&Fast, 0.0, &y, &f0, 1.0, 1e-6, 1e-6, &mut calls)
            .unwrap();
        assert!(r.y_new[0].abs() < 1e-6, "{}", r.y_new[0]);
    }
}
