//! Progress of a running discovery, for a live display: which step, which candidate, and how
//! each candidate scored. The settings carry an optional observer ([`Observer`]) that both
//! levels call; without one nothing is reported.

use std::fmt;
use std::sync::Arc;

use super::score::CandidateScore;

/// Something a discovery run has just done.
#[derive(Clone, Debug, PartialEq)]
pub enum DiscoveryEvent {
    /// The base is being fitted (the gap before).
    Base,
    /// Candidate `index` (from 0) of the `of` this step tries, `name`, is being fitted.
    Candidate {
        /// Step, from 1.
        step: usize,
        /// Index among this step's candidates, from 0.
        index: usize,
        /// Number of candidates this step tries.
        of: usize,
        /// The candidate's name.
        name: String,
    },
    /// That candidate is scored.
    Scored {
        /// Step, from 1.
        step: usize,
        /// The candidate's name.
        name: String,
        /// Held-out RMS residual of the sum (N or m).
        holdout_rms: f64,
        /// Paired z of its held-out gain.
        gain_z: f64,
    },
}

/// A function called with every event.
type Callback = dyn Fn(&DiscoveryEvent) + Send + Sync;

/// An observer of [`DiscoveryEvent`]s (none by default). Settings that hold one still
/// compare equal and serialise without it.
#[derive(Clone, Default)]
pub struct Observer(Option<Arc<Callback>>);

impl Observer {
    /// Call `f` with every event.
    pub fn new(f: impl Fn(&DiscoveryEvent) + Send + Sync + 'static) -> Self {
        Observer(Some(Arc::new(f)))
    }

    /// Report that candidate `index` of `of`, `name`, is being fitted in `step`.
    pub(crate) fn candidate(&self, step: usize, index: usize, of: usize, name: &str) {
        self.emit(DiscoveryEvent::Candidate {
            step,
            index,
            of,
            name: name.to_string(),
        });
    }

    /// Report the score of the candidate just tried.
    pub(crate) fn scored(&self, step: usize, score: &CandidateScore) {
        self.emit(DiscoveryEvent::Scored {
            step,
            name: score.name.clone(),
            holdout_rms: score.holdout_rms,
            gain_z: score.gain_z,
        });
    }

    /// Report `event` (nothing without an observer).
    pub(crate) fn emit(&self, event: DiscoveryEvent) {
        if let Some(f) = &self.0 {
            f(&event);
        }
    }
}

impl PartialEq for Observer {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl fmt::Debug for Observer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0.is_some() {
            "Observer(set)"
        } else {
            "Observer(none)"
        })
    }
}
