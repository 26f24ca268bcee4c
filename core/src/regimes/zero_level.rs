//! How far the boundaries move with the "zero force" level: the resonance → post-resonance
//! boundary is where the force becomes on–off, zero for most of the cycle, and what counts as
//! zero is the on-threshold, max(`on_k`·σ, `on_min`) (3σ of the force noise by default). The
//! mixed zone's ± ([`super::Boundary::uncertainty`]) says how noisy the change is at that one
//! level; the level itself is a choice, and the boundary moves with it. So the record is
//! classified again with the zero level at each of [`ZERO_LEVEL_FACTORS`] times the one used
//! (σ held), and the span of every boundary found, each with its own ±, is the range the
//! boundary can really lie in. The onset (pre → resonance) follows the negligible level, not
//! the zero level, so it stays put.

use serde::Serialize;

use super::boundaries::{Boundaries, Boundary};
use super::classify::{classify, Classification};
use super::cycles::Cycle;
use super::error::RegimeError;
use super::thresholds::RegimeThresholds;
use crate::data::force_data::ForceData;

/// The multiples of the zero level the boundaries are recomputed at.
pub const ZERO_LEVEL_FACTORS: [f64; 2] = [0.5, 2.0];

/// The boundaries found with the zero level at `factor` times the one used.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LevelBoundaries {
    /// The multiple of the zero level used.
    pub factor: f64,
    /// The zero level, N.
    pub zero_level: f64,
    /// The boundaries found, ω in rad/s.
    pub boundaries: Boundaries,
}

/// The zero level used, and the boundaries at other levels with the ranges they span.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ZeroLevelSpread {
    /// The zero level the labels use, N: |F| at or below it counts as zero.
    pub zero_level: f64,
    /// Where it comes from, in words (`3σ of the force noise, σ = 0.0200 N`).
    pub zero_level_rule: String,
    /// The boundaries at each of [`ZERO_LEVEL_FACTORS`] times the zero level.
    pub at_levels: Vec<LevelBoundaries>,
    /// `[low, high]` ω, rad/s, spanned by the pre → resonance boundary over the zero levels,
    /// each with its ±; null when no level finds it.
    pub pre_resonance_range: Option<[f64; 2]>,
    /// The same for the resonance → post-resonance boundary.
    pub resonance_post_range: Option<[f64; 2]>,
}

/// The range `[low, high]` spanned by `found` (each ω ± its uncertainty); `None` if empty.
fn span(found: impl Iterator<Item = Option<Boundary>>) -> Option<[f64; 2]> {
    found.flatten().fold(None, |r, b| {
        let (lo, hi) = (b.omega - b.uncertainty, b.omega + b.uncertainty);
        Some(r.map_or([lo, hi], |[a, c]: [f64; 2]| [a.min(lo), c.max(hi)]))
    })
}

/// How the boundaries of `base` (the classification of `sig` over `cycles` with `th`) move
/// with the zero level; see the [module doc](self).
pub fn zero_level_spread(
    sig: &ForceData,
    cycles: &[Cycle],
    th: &RegimeThresholds,
    base: &Classification,
) -> Result<ZeroLevelSpread, RegimeError> {
    let at_levels = ZERO_LEVEL_FACTORS
        .iter()
        .map(|&factor| {
            let scaled = RegimeThresholds {
                noise_sigma: Some(base.noise_sigma),
                on_k: th.on_k * factor,
                on_min: th.on_min * factor,
                ..th.clone()
            };
            let c = classify(sig, cycles.to_vec(), &scaled)?;
            Ok(LevelBoundaries {
                factor,
                zero_level: c.on_threshold,
                boundaries: c.boundaries,
            })
        })
        .collect::<Result<Vec<_>, RegimeError>>()?;
    let all = || std::iter::once(&base.boundaries).chain(at_levels.iter().map(|l| &l.boundaries));
    let sigma_rule = th.on_k * base.noise_sigma >= th.on_min;
    let zero_level_rule = if sigma_rule {
        format!(
            "{}σ of the force noise, σ = {:.4} N",
            th.on_k, base.noise_sigma
        )
    } else {
        format!(
            "the floor on_min = {} N ({}σ of the force noise, σ = {:.4} N, is below it)",
            th.on_min, th.on_k, base.noise_sigma
        )
    };
    Ok(ZeroLevelSpread {
        zero_level: base.on_threshold,
        zero_level_rule,
        pre_resonance_range: span(all().map(|b| b.pre_resonance)),
        resonance_post_range: span(all().map(|b| b.resonance_post)),
        at_levels,
    })
}

#[cfg(test)]
mod tests {
    use super::super::boundaries::BoundaryRule;
    use super::*;

    fn at(omega: f64, uncertainty: f64) -> Option<Boundary> {
        Some(Boundary {
            omega,
            uncertainty,
            cycle: 0,
            rule: BoundaryRule::OnOff,
        })
    }

    #[test]
    fn the_range_spans_every_level_with_its_uncertainty() {
        let r = span([at(7.0, 0.02), None, at(7.3, 0.05), at(6.9, 0.01)].into_iter());
        let [lo, hi] = r.unwrap();
        assert!(
            (lo - 6.89).abs() < 1e-12 && (hi - 7.35).abs() < 1e-12,
            "{lo} {hi}"
        );
        assert_eq!(span([None, None].into_iter()), None);
    }
}
