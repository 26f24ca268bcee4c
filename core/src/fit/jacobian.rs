//! Forward-difference Jacobians of residual vectors, column by column.
//!
//! A step that fails (the model errs there) is retried in the opposite direction; a column
//! whose both steps fail is NaN, and the parameter's standard error with it.

use nalgebra::DMatrix;

/// Fill `jac` (N × p) with ∂r/∂x_j at `x`, where `r0` are the residuals at `x`, `steps[j]`
/// the signed step of parameter j and `eval(x, out)` computes residuals (false on failure).
/// `flip(j, x)` tells whether parameter j's step must go the other way (a bound ahead).
pub fn forward_difference(
    x: &[f64],
    r0: &[f64],
    steps: &[f64],
    flip: &dyn Fn(usize, f64) -> bool,
    eval: &mut dyn FnMut(&[f64], &mut [f64]) -> bool,
    jac: &mut DMatrix<f64>,
) {
    let mut point = x.to_vec();
    for (j, &h0) in steps.iter().enumerate() {
        let mut h = if flip(j, x[j] + h0) { -h0 } else { h0 };
        let mut column = jac.column_mut(j);
        let col = column.as_mut_slice();
        let mut ok = false;
        for _ in 0..2 {
            point[j] = x[j] + h;
            let dx = point[j] - x[j];
            if dx != 0.0 && eval(&point, col) {
                for (c, r) in col.iter_mut().zip(r0) {
                    *c = (*c - r) / dx;
                }
                ok = true;
                break;
            }
            h = -h;
        }
        if !ok {
            col.fill(f64::NAN);
        }
        point[j] = x[j];
    }
}
