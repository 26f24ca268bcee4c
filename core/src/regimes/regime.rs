//! The three regimes of the source study's sweeps — pre-resonance, resonance, post-resonance
//! — by which cycles are labelled and models compared (docs/ARCHITECTURE.md).

use serde::{Deserialize, Serialize};

/// The three behaviours of the STF along a sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Regime {
    /// Below resonance: force negligible (or only starting).
    PreResonance,
    /// Through resonance: large amplitude, force on most of the cycle, strong damping.
    Resonance,
    /// Above resonance: small amplitude, on–off force (or none).
    PostResonance,
}

impl Regime {
    /// The three regimes in sweep order.
    pub const ALL: [Regime; 3] = [
        Regime::PreResonance,
        Regime::Resonance,
        Regime::PostResonance,
    ];

    /// The name used in results (`pre_resonance`, `resonance`, `post_resonance`).
    pub fn name(self) -> &'static str {
        match self {
            Regime::PreResonance => "pre_resonance",
            Regime::Resonance => "resonance",
            Regime::PostResonance => "post_resonance",
        }
    }
}
