//! Standard errors and correlations from the Jacobian: cov = s²·(JᵀJ)⁻¹, s² = RSS/(N − p).
//!
//! JᵀJ is first scaled to unit diagonal, then inverted through its eigen-decomposition.
//! Directions the data do not determine (eigenvalues below 1e-13 of the largest, a zero or NaN
//! column) give an infinite (or NaN) variance to every parameter that takes part in them —
//! never a small, confident-looking number.

use nalgebra::{DMatrix, SymmetricEigen};

/// Standard errors and correlation matrix of the parameters.
pub struct Covariance {
    /// Standard error of each parameter.
    pub std_errors: Vec<f64>,
    /// Correlations (NaN where a variance is not finite).
    pub correlation: Vec<Vec<f64>>,
}

/// Covariance from Jacobian `jac` (N × p) and residual sum of squares `rss`.
pub fn from_jacobian(jac: &DMatrix<f64>, rss: f64) -> Covariance {
    let (n, p) = jac.shape();
    let dof = n.saturating_sub(p);
    let s2 = if dof > 0 { rss / dof as f64 } else { f64::NAN };
    let bad_col: Vec<bool> = (0..p)
        .map(|j| jac.column(j).iter().any(|v| !v.is_finite()))
        .collect();
    let mut a = DMatrix::<f64>::zeros(p, p);
    for i in 0..p {
        for j in i..p {
            if bad_col[i] || bad_col[j] {
                continue;
            }
            let v = jac.column(i).dot(&jac.column(j));
            a[(i, j)] = v;
            a[(j, i)] = v;
        }
    }
    // Scale to unit diagonal; zero or bad columns are held out of the inversion.
    let live: Vec<bool> = (0..p).map(|j| !bad_col[j] && a[(j, j)] > 0.0).collect();
    let d: Vec<f64> = (0..p)
        .map(|j| if live[j] { 1.0 / a[(j, j)].sqrt() } else { 0.0 })
        .collect();
    let mut c = DMatrix::<f64>::identity(p, p);
    for i in 0..p {
        for j in 0..p {
            if live[i] && live[j] {
                c[(i, j)] = a[(i, j)] * d[i] * d[j];
            }
        }
    }
    let eig = SymmetricEigen::new(c);
    let lmax = eig.eigenvalues.iter().fold(0.0_f64, |m, &l| m.max(l));
    let cutoff = 1e-13 * lmax;
    let mut cov = DMatrix::<f64>::zeros(p, p);
    for i in 0..p {
        for j in 0..p {
            let mut sum = 0.0;
            for k in 0..p {
                let vik = eig.eigenvectors[(i, k)];
                let vjk = eig.eigenvectors[(j, k)];
                let l = eig.eigenvalues[k];
                if l > cutoff {
                    sum += vik * vjk / l;
                } else if vik.abs() > 1e-8 && vjk.abs() > 1e-8 {
                    sum = f64::INFINITY;
                }
            }
            cov[(i, j)] = sum * d[i] * d[j] * s2;
        }
    }
    let variance: Vec<f64> = (0..p)
        .map(|j| {
            if bad_col[j] {
                f64::NAN
            } else if !live[j] {
                f64::INFINITY
            } else {
                cov[(j, j)]
            }
        })
        .collect();
    let std_errors = variance.iter().map(|v| v.sqrt()).collect();
    let correlation = (0..p)
        .map(|i| {
            (0..p)
                .map(|j| {
                    if i == j {
                        1.0
                    } else if variance[i].is_finite() && variance[j].is_finite() {
                        cov[(i, j)] / (variance[i] * variance[j]).sqrt()
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        })
        .collect();
    Covariance {
        std_errors,
        correlation,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_line_matches_the_textbook_formula() {
        // r = y − (a + b·t): J = −[1, t]; var(b) = s² / Σ(t − t̄)².
        let t: Vec<f64> = (0..10).map(f64::from).collect();
        let jac = DMatrix::from_fn(10, 2, |i, j| if j == 0 { -1.0 } else { -t[i] });
        let rss = 8.0;
        let cov = from_jacobian(&jac, rss);
        let s2 = rss / 8.0;
        let sxx: f64 = t.iter().map(|v| (v - 4.5).powi(2)).sum();
        assert!((cov.std_errors[1] - (s2 / sxx).sqrt()).abs() < 1e-12);
        let var_a = s2 * (1.0 / 10.0 + 4.5 * 4.5 / sxx);
        assert!((cov.std_errors[0] - var_a.sqrt()).abs() < 1e-12);
        assert!(cov.correlation[0][1] < 0.0 && cov.correlation[0][1] > -1.0);
    }

    #[test]
    fn an_ignored_or_aliased_parameter_is_not_determined() {
        let jac = DMatrix::from_fn(5, 3, |i, j| match j {
            0 => i as f64 + 1.0,
            1 => 0.0,
            _ => 2.0 * (i as f64 + 1.0),
        });
        let cov = from_jacobian(&jac, 1.0);
        assert!(cov.std_errors.iter().all(|s| !s.is_finite()));
    }
}
