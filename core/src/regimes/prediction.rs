//! A prediction's error regime by regime: the RMS of measured − predicted over the samples of
//! the cycles a classification labels pre-resonance, resonance or post-resonance, for any
//! signal sampled with the record (a force, or the displacement of a simulation), so a model
//! scored on a record it was not fitted to says where along the sweep it holds.
//!
//! ```
//! use stf_core::regimes::{rms_by_regime, Cycle, Regime};
//! let cycle = |start, end| Cycle { start, end, t_mid: 0.0, omega: 1.0 };
//! let measured = [1.0, -1.0, 2.0, -2.0, 0.0];
//! let predicted = [1.0, -1.0, 1.0, -1.0, 9.0];
//! let cycles = [cycle(0, 2), cycle(2, 4)];
//! let e = rms_by_regime(&measured, &predicted, &cycles, &[Regime::PreResonance, Regime::Resonance]).unwrap();
//! assert_eq!(e.pre_resonance.unwrap().rms, 0.0);
//! assert_eq!(e.resonance.unwrap().normalised, 0.5);
//! assert!(e.post_resonance.is_none());
//! ```

use serde::Serialize;

use super::cycles::Cycle;
use super::error::{check_len, RegimeError};
use super::metrics::PerRegime;
use super::regime::Regime;

/// The error of a prediction over the cycles of one regime.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RegimeRms {
    /// Cycles in the regime.
    pub cycles: usize,
    /// Their samples.
    pub samples: usize,
    /// RMS of measured − predicted over those samples (the signal's unit).
    pub rms: f64,
    /// RMS of the measured signal there.
    pub measured_rms: f64,
    /// `rms / measured_rms` (NaN where the measured signal is all zeros).
    pub normalised: f64,
}

/// The RMS error of `predicted` against `measured` over the cycles of each regime, cycle `i`
/// labelled `labels[i]`; a regime without cycles is `None`.
pub fn rms_by_regime(
    measured: &[f64],
    predicted: &[f64],
    cycles: &[Cycle],
    labels: &[Regime],
) -> Result<PerRegime<RegimeRms>, RegimeError> {
    let n = measured.len();
    check_len("predicted", predicted, n)?;
    check_len("labels", labels, cycles.len())?;
    let mut out = PerRegime::default();
    for regime in Regime::ALL {
        let (mut cycles_in, mut samples, mut e2, mut m2) = (0, 0, 0.0, 0.0);
        for (c, _) in cycles.iter().zip(labels).filter(|(_, &l)| l == regime) {
            if c.end > n || c.start > c.end {
                return Err(RegimeError::BadCycle {
                    start: c.start,
                    end: c.end,
                    len: n,
                });
            }
            cycles_in += 1;
            samples += c.len();
            for i in c.start..c.end {
                e2 += (measured[i] - predicted[i]).powi(2);
                m2 += measured[i].powi(2);
            }
        }
        if cycles_in > 0 && samples > 0 {
            let (rms, measured_rms) = ((e2 / samples as f64).sqrt(), (m2 / samples as f64).sqrt());
            out.set(
                regime,
                Some(RegimeRms {
                    cycles: cycles_in,
                    samples,
                    rms,
                    measured_rms,
                    normalised: rms / measured_rms,
                }),
            );
        }
    }
    Ok(out)
}
