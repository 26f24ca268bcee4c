//! Regimes of a sweep and metrics that compare force models regime by regime.
//!
//! The source study's STF behaves in three ways along a frequency sweep (docs/ARCHITECTURE.md §1):
//! negligible force before resonance, a strong damper through resonance, an on–off impact
//! force after it. This module makes that measurable on any record, measured or simulated:
//!
//! 1. [`cycles`] cuts the record into rotor cycles (φ crossing multiples of 2π), or into
//!    cycles of x (upward zero crossings) when there is no rotor;
//! 2. [`noise`] estimates the force's noise floor from the record (users may override it);
//! 3. [`features`](mod@features) computes per-cycle features: ω, displacement amplitude, peak and RMS force,
//!    duty (fraction of the cycle the force is on), ∮F dx and the alignment of |F| with
//!    |x|, |v|, |a|, the equivalent viscous damping and the phase of the force's fundamental;
//! 4. [`classify`](mod@classify) labels each cycle [`Regime::PreResonance`], [`Regime::Resonance`] or
//!    [`Regime::PostResonance`] by the source study's behavioural definitions ([`rules`]; the
//!    amplitude criterion is an option) and finds the [`boundaries`] in rad/s, each with an
//!    uncertainty and the rule that placed it;
//! 5. [`metrics`] compares a model's force on the same kinematics with the measured force,
//!    per measured regime — force error and what the field reads from loops ([`loops`]:
//!    energy per cycle, equivalent viscous damping, phase of the force's fundamental against x
//!    and v, on-fraction, peak force) — and [`ranking`] names the best model per regime and
//!    overall by the force error, [`loop_ranking`] by each loop metric with the paired test
//!    behind each ranking;
//!    [`prediction`] gives any prediction's RMS error per regime (a model scored on a second
//!    record).
//!
//! Everything works on plain slices; nothing here fits or simulates.
//!
//! ```
//! use stf_core::data::force_data::ForceData;
//! use stf_core::regimes::{classify, cycles_from_phase, Regime, RegimeThresholds};
//! // 20 s at ω = 6 rad/s, 200 Hz, x = 10 mm·sin φ, a viscous force 20·v.
//! let t: Vec<f64> = (0..4000).map(|i| i as f64 / 200.0).collect();
//! let phi: Vec<f64> = t.iter().map(|t| 6.0 * t).collect();
//! let x: Vec<f64> = phi.iter().map(|p| 0.01 * p.sin()).collect();
//! let v: Vec<f64> = phi.iter().map(|p| 0.06 * p.cos()).collect();
//! let a: Vec<f64> = phi.iter().map(|p| -0.36 * p.sin()).collect();
//! let f: Vec<f64> = v.iter().map(|v| 20.0 * v).collect();
//! let sig = ForceData::new(&t, &x, &v, &a, &f);
//! let cycles = cycles_from_phase(&t, &phi).unwrap();
//! let c = classify(&sig, cycles, &RegimeThresholds::default()).unwrap();
//! assert!(!c.no_stf);
//! assert!(c.labels.iter().all(|&r| r == Regime::Resonance)); // force on all the cycle
//! ```

pub mod boundaries;
pub mod classify;
pub mod cycles;
pub mod error;
pub mod features;
pub mod loop_ranking;
pub mod loops;
pub mod median;
pub mod metrics;
pub mod noise;
pub mod prediction;
pub mod ranking;
pub mod regime;
pub mod rules;
pub mod thresholds;
pub mod zero_level;

pub use boundaries::{find_boundaries, Boundaries, Boundary, BoundaryRule};
pub use classify::{classify, label_cycles, Classification};
pub use cycles::{cycles_from_phase, cycles_from_x, phase_from_omega, segments, Cycle};
pub use error::RegimeError;
pub use features::{cycle_features, duty, features, CycleFeatures};
pub use loop_ranking::{rank_on_loops, LoopMetric, MetricRanking, PairedTest, RegimeRank};
pub use median::median_filter;
pub use metrics::{compare, BoundaryErrors, Comparison, PerRegime, RegimeMetrics};
pub use noise::noise_floor;
pub use prediction::{rms_by_regime, RegimeRms};
pub use ranking::{rank_models, OverallScore, Ranking, Score};
pub use regime::Regime;
pub use rules::{behaviour, place, Behaviour};
pub use thresholds::RegimeThresholds;
pub use zero_level::{zero_level_spread, LevelBoundaries, ZeroLevelSpread, ZERO_LEVEL_FACTORS};
