//! The state of the Levenberg–Marquardt solver ([`super::levenberg_marquardt`]) between its
//! iterations, as argmin's [`State`] trait sees it.
//!
//! argmin's `IterState` holds a point, its cost and the best of them; a refinement also
//! carries the residuals at its point (the next Jacobian's base, up to 150 000 of them, moved
//! and never copied between iterations), the damping `λ` with its growth factor `ν`, and the
//! words of the rule that ended it (argmin's [`TerminationReason`] has a reason's kind, not
//! its numbers). So it has this state of its own. Its cost is the mean squared residual; the
//! best point is always the current one, since a refinement accepts only steps that lower the
//! cost.

use std::collections::HashMap;
use std::time::Duration;

use argmin::core::{Problem, State, TerminationReason, TerminationStatus};

/// The damping a refinement starts with (Nielsen's `λ₀` relative to the diagonal).
const LAMBDA_START: f64 = 1e-3;

/// A Levenberg–Marquardt refinement between two iterations.
#[derive(Clone, Debug)]
pub struct LmState {
    /// The point, in internal coordinates.
    pub(super) u: Vec<f64>,
    /// The residuals at `u`.
    pub(super) residuals: Vec<f64>,
    /// Their sum of squares (infinite before the start is evaluated).
    pub(super) rss: f64,
    /// The damping.
    pub(super) lambda: f64,
    /// The damping's growth factor after a rejected step.
    pub(super) nu: f64,
    /// The rule that ended the refinement, in words (with its numbers).
    pub(super) rule: Option<String>,
    iter: u64,
    last_best_iter: u64,
    max_iters: u64,
    status: TerminationStatus,
    counts: HashMap<String, u64>,
    time: Option<Duration>,
}

impl LmState {
    /// Start from internal coordinates `u`.
    #[must_use]
    pub fn param(mut self, u: Vec<f64>) -> Self {
        self.u = u;
        self
    }

    /// Stop after `n` iterations (Jacobians).
    #[must_use]
    pub fn max_iters(mut self, n: u64) -> Self {
        self.max_iters = n;
        self
    }

    /// The words of the rule that ended the refinement, if one did.
    pub fn rule(&self) -> Option<&str> {
        self.rule.as_deref()
    }

    /// The mean squared residual at the point.
    fn mean_square(&self) -> f64 {
        self.rss / self.residuals.len().max(1) as f64
    }

    /// End with argmin's `reason`, said in `words`.
    #[must_use]
    pub(super) fn ended(mut self, reason: TerminationReason, words: String) -> Self {
        self.rule = Some(words);
        self.terminate_with(reason)
    }
}

impl State for LmState {
    type Param = Vec<f64>;
    type Float = f64;

    fn new() -> Self {
        LmState {
            u: Vec::new(),
            residuals: Vec::new(),
            rss: f64::INFINITY,
            lambda: LAMBDA_START,
            nu: 2.0,
            rule: None,
            iter: 0,
            last_best_iter: 0,
            max_iters: u64::MAX,
            status: TerminationStatus::NotTerminated,
            counts: HashMap::new(),
            time: None,
        }
    }

    /// Nothing to do: the point is always the best so far.
    fn update(&mut self) {
        self.last_best_iter = self.iter;
    }

    fn get_param(&self) -> Option<&Vec<f64>> {
        Some(&self.u)
    }

    fn get_best_param(&self) -> Option<&Vec<f64>> {
        Some(&self.u)
    }

    fn get_max_iters(&self) -> u64 {
        self.max_iters
    }

    fn increment_iter(&mut self) {
        self.iter += 1;
    }

    fn get_iter(&self) -> u64 {
        self.iter
    }

    fn get_cost(&self) -> f64 {
        self.mean_square()
    }

    fn get_best_cost(&self) -> f64 {
        self.mean_square()
    }

    /// No target: a refinement ends by its own rules or its iterations.
    fn get_target_cost(&self) -> f64 {
        f64::NEG_INFINITY
    }

    fn func_counts<O>(&mut self, problem: &Problem<O>) {
        for (k, &v) in problem.counts.iter() {
            self.counts.insert((*k).to_string(), v);
        }
    }

    fn get_func_counts(&self) -> &HashMap<String, u64> {
        &self.counts
    }

    fn time(&mut self, time: Option<Duration>) -> &mut Self {
        self.time = time;
        self
    }

    fn get_time(&self) -> Option<Duration> {
        self.time
    }

    fn get_last_best_iter(&self) -> u64 {
        self.last_best_iter
    }

    fn is_best(&self) -> bool {
        self.last_best_iter == self.iter
    }

    fn terminate_with(mut self, reason: TerminationReason) -> Self {
        self.status = TerminationStatus::Terminated(reason);
        self
    }

    fn get_termination_status(&self) -> &TerminationStatus {
        &self.status
    }

    fn get_termination_reason(&self) -> Option<&TerminationReason> {
        match &self.status {
            TerminationStatus::Terminated(reason) => Some(reason),
            TerminationStatus::NotTerminated => None,
        }
    }
}
