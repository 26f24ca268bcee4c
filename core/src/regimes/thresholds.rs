//! The thresholds of the regime classifier, with defaults that reproduce the source study's
//! description of its sweep (docs/ARCHITECTURE.md §1), overridable from an experiment file.
//!
//! | key | default | meaning |
//! |---|---|---|
//! | `noise_sigma` | estimated | σ of the force noise, N ([`super::noise_floor`] if absent) |
//! | `on_k` | 3 | the force is *on* where \|F\| > max(`on_k`·σ, `on_min`) |
//! | `on_min` | 0.05 N | floor of the on-threshold (noise-free records have σ ≈ 0) |
//! | `min_off_fraction` | 0.05 | an *off* stretch shorter than this fraction of the cycle is bridged: a force that only passes through zero stays on |
//! | `negligible_force` | 0.2 N | a cycle whose peak \|F\| (lightly smoothed, see [`super::features`]) ≤ max(`negligible_force`, `negligible_k`·σ) has negligible force (the paper's pre-resonance: F_STF ≤ 0.2 N) |
//! | `negligible_k` | 5 | see above; the largest of a cycle's noise samples reaches ≈ 3–4 σ |
//! | `resonance_duty` | 0.5 | a cycle's force is *on* (a damper: on most of the cycle) when it is on for at least this fraction of the cycle, and *on–off* when it is zero for more than 1 − this (the stated share: half the cycle) |
//! | `amplitude_rule` | false | the amplitude criterion, an option: resonance cycles also need … |
//! | `resonance_amplitude` | 0.6 | … a displacement amplitude of at least this fraction of the record's largest (used only with `amplitude_rule`) |
//! | `smoothing_cycles` | 5 | width of the median filter over the labels (odd; 1: none) |
//!
//! By default the boundaries follow the source study's behavioural definitions
//! ([`super::rules`]): pre-resonance is "F_STF ≤ 0.2 N", hence `negligible_force`;
//! post-resonance is the on–off force, zero between impact-like pulses, hence the zero-force
//! share 1 − `resonance_duty`.
//!
//! With `amplitude_rule = true` the earlier classifier runs instead. Its amplitude ratio 0.6 is a little below the half-power ratio 1/√2 of a
//! linear resonance, because the measured boundary to post-resonance (9.22 rad/s) lies lower on
//! the peak's flank than the half-power point: on a simulated 0.0333 rad/s² sweep with the
//! on–off jamming law of `jamming_on_off` (K = 100, v_c = 0.05 m/s), whose amplitudes resemble
//! the paper's (peak ≈ 15 mm near 6.2 rad/s, ≈ 8 mm at 10 rad/s), the amplitude falls to
//! 0.6 of its peak near 9.4 rad/s and to 1/√2 near 8.3 rad/s. There the jammed plug is on for
//! ≈ 0.6–0.67 of every cycle, through resonance as after it, so duty alone does not separate
//! the two for that law; `resonance_duty` = 0.5 ("on for most of the cycle") separates the
//! damper from the first short pulses of a force that is only starting, and from sparse
//! impact spikes.
//!
//! In a file:
//!
//! ```toml
//! [regimes]
//! resonance_duty = 0.6
//! noise_sigma = 0.03
//! ```

use serde::{Deserialize, Serialize};

use super::error::RegimeError;

/// Thresholds of the regime classifier; see the [module doc](self) for each key and default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RegimeThresholds {
    /// σ of the force noise, N; `None`: estimated from the record.
    pub noise_sigma: Option<f64>,
    /// Multiple of σ above which the force is on.
    pub on_k: f64,
    /// Floor of the on-threshold, N.
    pub on_min: f64,
    /// Off stretches shorter than this fraction of a cycle count as on.
    pub min_off_fraction: f64,
    /// Peak force at or below which a cycle's force is negligible, N.
    pub negligible_force: f64,
    /// Multiple of σ at or below which a cycle's peak force is negligible.
    pub negligible_k: f64,
    /// Least duty of a resonance cycle.
    pub resonance_duty: f64,
    /// Use the amplitude criterion (resonance cycles need `resonance_amplitude` of the largest
    /// amplitude) instead of the study's behavioural definitions.
    pub amplitude_rule: bool,
    /// Least amplitude of a resonance cycle, as a fraction of the record's largest amplitude
    /// (with `amplitude_rule` only).
    pub resonance_amplitude: f64,
    /// Width of the median filter over the labels, cycles.
    pub smoothing_cycles: usize,
}

impl Default for RegimeThresholds {
    fn default() -> Self {
        RegimeThresholds {
            noise_sigma: None,
            on_k: 3.0,
            on_min: 0.05,
            min_off_fraction: 0.05,
            negligible_force: 0.2,
            negligible_k: 5.0,
            resonance_duty: 0.5,
            amplitude_rule: false,
            resonance_amplitude: 0.6,
            smoothing_cycles: 5,
        }
    }
}

impl RegimeThresholds {
    /// Check every threshold lies in its range.
    pub fn check(&self) -> Result<(), RegimeError> {
        let bad = |name, value, why| Err(RegimeError::BadThreshold { name, value, why });
        let nonneg = |x: f64| x >= 0.0 && x.is_finite();
        let frac = |x: f64| (0.0..=1.0).contains(&x);
        for (name, value) in [
            ("noise_sigma", self.noise_sigma.unwrap_or(0.0)), // absent: estimated
            ("on_k", self.on_k),
            ("on_min", self.on_min),
            ("negligible_force", self.negligible_force),
            ("negligible_k", self.negligible_k),
        ] {
            if !nonneg(value) {
                return bad(name, value, "must be finite and ≥ 0");
            }
        }
        for (name, value) in [
            ("min_off_fraction", self.min_off_fraction),
            ("resonance_duty", self.resonance_duty),
            ("resonance_amplitude", self.resonance_amplitude),
        ] {
            if !frac(value) {
                return bad(name, value, "must lie in [0, 1]");
            }
        }
        if self.smoothing_cycles == 0 || self.smoothing_cycles.is_multiple_of(2) {
            return bad(
                "smoothing_cycles",
                self.smoothing_cycles as f64,
                "must be odd and ≥ 1",
            );
        }
        Ok(())
    }

    /// The on-threshold for noise σ, N: max(`on_k`·σ, `on_min`).
    pub fn on_threshold(&self, sigma: f64) -> f64 {
        (self.on_k * sigma).max(self.on_min)
    }

    /// The negligible-force level for noise σ, N: max(`negligible_k`·σ, `negligible_force`).
    pub fn negligible_level(&self, sigma: f64) -> f64 {
        (self.negligible_k * sigma).max(self.negligible_force)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_a_file_overrides_some_keys() {
        RegimeThresholds::default().check().unwrap();
        let t: RegimeThresholds =
            serde_json::from_str(r#"{"resonance_duty": 0.6, "noise_sigma": 0.03}"#).unwrap();
        assert_eq!(t.resonance_duty, 0.6);
        assert_eq!(t.noise_sigma, Some(0.03));
        assert_eq!(t.on_k, RegimeThresholds::default().on_k);
        assert!((t.on_threshold(0.03) - 0.09).abs() < 1e-12);
        assert_eq!(t.negligible_level(0.01), 0.2);
    }

    #[test]
    fn a_misspelled_key_is_an_error() {
        let e = serde_json::from_str::<RegimeThresholds>(r#"{"resonance_dutty": 0.6}"#);
        assert!(e.unwrap_err().to_string().contains("resonance_dutty"));
    }

    #[test]
    fn out_of_range_thresholds_are_rejected() {
        let mut t = RegimeThresholds {
            resonance_duty: 1.5,
            ..Default::default()
        };
        assert!(t.check().is_err());
        t.resonance_duty = 0.7;
        t.smoothing_cycles = 4;
        assert!(t.check().is_err());
        t.smoothing_cycles = 3;
        t.noise_sigma = Some(f64::NAN);
        assert!(t.check().is_err());
    }
}
