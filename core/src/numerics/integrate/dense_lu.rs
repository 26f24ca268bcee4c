//! A small dense LU factorisation with partial pivoting, for the linear systems of the
//! Rosenbrock method (the state has a handful of components, so no sparse or blocked
//! algebra is worth its setup cost).

/// An `n × n` matrix factorised in place as `P·A = L·U`.
#[derive(Clone, Debug, Default)]
pub(super) struct DenseLu {
    n: usize,
    /// Row-major `L` (unit diagonal, below) and `U` (on and above the diagonal).
    lu: Vec<f64>,
    /// Row swapped with row `k` at elimination step `k`.
    pivots: Vec<usize>,
}

impl DenseLu {
    /// Room for an `n × n` matrix.
    pub(super) fn new(n: usize) -> Self {
        DenseLu {
            n,
            lu: vec![0.0; n * n],
            pivots: vec![0; n],
        }
    }

    /// The matrix to factorise, row-major; fill it, then call [`DenseLu::factor`].
    pub(super) fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.lu
    }

    /// Factorise the matrix in place; false if it is singular (a zero or non-finite pivot).
    pub(super) fn factor(&mut self) -> bool {
        let n = self.n;
        let a = &mut self.lu;
        for k in 0..n {
            let mut p = k;
            let mut best = a[k * n + k].abs();
            for i in k + 1..n {
                let v = a[i * n + k].abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if !(best > 0.0 && best.is_finite()) {
                return false;
            }
            self.pivots[k] = p;
            if p != k {
                for j in 0..n {
                    a.swap(k * n + j, p * n + j);
                }
            }
            let inv = 1.0 / a[k * n + k];
            for i in k + 1..n {
                let l = a[i * n + k] * inv;
                a[i * n + k] = l;
                if l != 0.0 {
                    for j in k + 1..n {
                        a[i * n + j] -= l * a[k * n + j];
                    }
                }
            }
        }
        true
    }

    /// Solve `A·x = b` in place (`b` becomes `x`) with the factorisation.
    pub(super) fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        let a = &self.lu;
        for k in 0..n {
            let p = self.pivots[k];
            if p != k {
                b.swap(k, p);
            }
        }
        for i in 1..n {
            let mut s = b[i];
            for j in 0..i {
                s -= a[i * n + j] * b[j];
            }
            b[i] = s;
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            for j in i + 1..n {
                s -= a[i * n + j] * b[j];
            }
            b[i] = s / a[i * n + i];
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_system_that_needs_pivoting() {
        // First pivot is zero: only a row swap makes it solvable.
        let a = [0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0];
        let x_true = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| a[i * 3 + j] * x_true[j]).sum())
            .collect();
        let mut lu = DenseLu::new(3);
        lu.matrix_mut().copy_from_slice(&a);
        assert!(lu.factor());
        lu.solve(&mut b);
        for (x, t) in b.iter().zip(x_true) {
            assert!((x - t).abs() < 1e-14, "{x} vs {t}");
        }
    }

    #[test]
    fn reports_a_singular_matrix() {
        let mut lu = DenseLu::new(2);
        lu.matrix_mut().copy_from_slice(&[1.0, 2.0, 2.0, 4.0]);
        assert!(!lu.factor());
    }
}
