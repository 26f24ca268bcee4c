//! Reading a model's parameter values without indexing past the end of the slice.
//!
//! The values arrive as a plain `&[f64]` in the order of the model's specs; a caller that
//! passes too few is told so by a [`ModelError`] instead of a panic.

use stf_core::physics::force_model::ModelError;

/// The first `N` values of `p`, or an error naming `model` when there are fewer.
#[inline]
pub(crate) fn take<const N: usize>(model: &str, p: &[f64]) -> Result<[f64; N], ModelError> {
    p.get(..N)
        .and_then(|head| <[f64; N]>::try_from(head).ok())
        .ok_or_else(|| {
            ModelError::new(
                model,
                format!("expects {N} parameter values, got {}", p.len()),
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn too_few_values_are_an_error_and_extra_ones_are_ignored() {
        assert!(take::<2>("m", &[1.0]).is_err());
        assert_eq!(take::<2>("m", &[1.0, 2.0, 3.0]).unwrap(), [1.0, 2.0]);
    }
}
