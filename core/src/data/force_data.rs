//! A record's kinematics and its STF force sampled together: the one input of a force-level
//! fit ([`crate::fit::ForceFit`]), of the regime analysis ([`crate::regimes`]) and of
//! force-level discovery. The checks every user of it makes (equal lengths, finite samples,
//! time increasing strictly) are here once; each workflow wraps [`ForceDataError`] in its own
//! error.

use thiserror::Error;

use crate::physics::force_model::ModelState;

/// Kinematics and STF force, sample by sample (SI units, equal lengths).
#[derive(Clone, Copy, Debug)]
pub struct ForceData<'a> {
    /// Time, s.
    pub t: &'a [f64],
    /// Displacement, m.
    pub x: &'a [f64],
    /// Velocity, m/s.
    pub v: &'a [f64],
    /// Acceleration, m/s².
    pub a: &'a [f64],
    /// STF force, N (measured, or a model's on the same kinematics).
    pub f: &'a [f64],
}

/// Why samples cannot be used together.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ForceDataError {
    /// A signal has another number of samples than `t`.
    #[error("signal `{name}` has {len} samples, `t` has {expected}")]
    LengthMismatch {
        /// The signal's name.
        name: &'static str,
        /// Its length.
        len: usize,
        /// The length of `t`.
        expected: usize,
    },
    /// A signal holds a NaN or an infinity.
    #[error("signal `{name}` is not finite at sample {index} ({value})")]
    NonFinite {
        /// The signal's name.
        name: &'static str,
        /// The first bad sample.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// Time does not increase strictly.
    #[error("time does not increase strictly at sample {index}")]
    TimeNotIncreasing {
        /// The first sample whose time is not after the previous one.
        index: usize,
    },
}

impl<'a> ForceData<'a> {
    /// The signals `t, x, v, a, f`, in the order of the fields.
    pub fn new(t: &'a [f64], x: &'a [f64], v: &'a [f64], a: &'a [f64], f: &'a [f64]) -> Self {
        ForceData { t, x, v, a, f }
    }

    /// The state a force model sees at sample `i`, with the internal state `z`.
    pub fn state<'z>(&self, i: usize, z: &'z [f64]) -> ModelState<'z> {
        ModelState {
            t: self.t[i],
            x: self.x[i],
            v: self.v[i],
            z,
        }
    }

    /// The signals by name, `t` first.
    fn named(&self) -> [(&'static str, &'a [f64]); 5] {
        [
            ("t", self.t),
            ("x", self.x),
            ("v", self.v),
            ("a", self.a),
            ("f", self.f),
        ]
    }

    /// Check that every signal has as many samples as `t` and all are finite; the sample
    /// count.
    pub fn check(&self) -> Result<usize, ForceDataError> {
        let n = self.t.len();
        for (name, s) in self.named() {
            if s.len() != n {
                return Err(ForceDataError::LengthMismatch {
                    name,
                    len: s.len(),
                    expected: n,
                });
            }
        }
        for (name, s) in self.named() {
            if let Some(index) = s.iter().position(|v| !v.is_finite()) {
                let value = s[index];
                return Err(ForceDataError::NonFinite { name, index, value });
            }
        }
        Ok(n)
    }

    /// [`ForceData::check`], and time increasing strictly.
    pub fn check_increasing(&self) -> Result<usize, ForceDataError> {
        let n = self.check()?;
        match self.t.windows(2).position(|w| w[1] <= w[0]) {
            Some(i) => Err(ForceDataError::TimeNotIncreasing { index: i + 1 }),
            None => Ok(n),
        }
    }

    /// The same kinematics with another force.
    pub fn with_force(&self, f: &'a [f64]) -> ForceData<'a> {
        ForceData { f, ..*self }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_then_finiteness_then_time_are_checked() {
        let t = [0.0, 1.0, 2.0];
        let ok = ForceData {
            t: &t,
            x: &t,
            v: &t,
            a: &t,
            f: &t,
        };
        assert_eq!(ok.check_increasing(), Ok(3));
        let short = [0.0, 1.0];
        assert_eq!(
            ok.with_force(&short).check(),
            Err(ForceDataError::LengthMismatch {
                name: "f",
                len: 2,
                expected: 3
            })
        );
        let nan = [0.0, f64::NAN, 1.0];
        let e = ForceData { v: &nan, ..ok }.check().unwrap_err();
        assert!(matches!(
            e,
            ForceDataError::NonFinite {
                name: "v",
                index: 1,
                ..
            }
        ));
        assert_eq!(e.to_string(), "signal `v` is not finite at sample 1 (NaN)");
        let back = [0.0, 2.0, 2.0];
        let still = ForceData { t: &back, ..ok };
        assert_eq!(still.check(), Ok(3));
        assert_eq!(
            still.check_increasing(),
            Err(ForceDataError::TimeNotIncreasing { index: 2 })
        );
    }
}
