//! What a running study says while it works: an [`Observer`] is handed every job (one per
//! model fit, one per discovery run) and told each step that finishes; a [`Job`] receives the
//! job's messages. The messages are words about the work, built here once for every front end
//! (the command line's spinners, a notebook's progress line): a fit's stage, evaluations and
//! best RMS ([`fit_message`]), several jobs' count and time left ([`jobs_message`]), and a
//! discovery's step, candidate and best held-out score ([`discovery_observer`]). An observer
//! also says whether the run is to stop ([`Observer::cancelled`]): a study checks it between
//! jobs and returns an interrupted [`crate::error::StudyError`] ([`crate::error::ErrorKind::Interrupted`]).

use std::sync::{Arc, Mutex};
use std::time::Instant;

use stf_core::discovery::{DiscoveryEvent, Observer as DiscoveryObserver};
use stf_core::fit::{FitProgress, SolverStage};

/// One running job's message line (a spinner on a terminal).
pub trait Job: Send + Sync {
    /// What the job is doing now.
    fn message(&self, text: &str);
    /// The job is over: its line goes.
    fn finish(&self) {}
}

/// Whoever runs a study: it is handed each job and told each finished step.
pub trait Observer: Sync {
    /// A job called `name` starts.
    fn job(&self, name: &str) -> Arc<dyn Job> {
        let _ = name;
        Arc::new(Silent)
    }
    /// `what` (e.g. "the fit of `power_law`") has finished.
    fn finished(&self, what: &str) {
        let _ = what;
    }
    /// A line about what the run does (e.g. which parameters a discovery refits), said as it
    /// starts.
    fn note(&self, text: &str) {
        let _ = text;
    }
    /// A warning about the inputs (a record that looks wrong), said as soon as it is found.
    fn warning(&self, text: &str) {
        let _ = text;
    }
    /// Whether the run is to stop (checked between jobs).
    fn cancelled(&self) -> bool {
        false
    }
}

/// An observer and job that show nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Job for Silent {
    fn message(&self, _: &str) {}
}

impl Observer for Silent {}

/// The message a fit's progress shows: what it is doing, in words, how many times the model
/// was evaluated (simulated, at trajectory level) and the best RMS residual so far, in `unit`
/// (`scale` from SI: the cost is a mean square in N² or m²).
pub fn fit_message(p: &FitProgress, unit: &str, scale: f64) -> String {
    let doing = match p.stage {
        SolverStage::ParticleSwarm => "searching the parameter box",
        SolverStage::NelderMead | SolverStage::LevenbergMarquardt => "refining the best point",
        SolverStage::Errors => "estimating the standard errors",
    };
    let rms = p.best_cost.sqrt() * scale;
    if rms.is_finite() {
        format!(
            "{doing} · {} evaluations · best RMS {rms:.4} {unit}",
            p.evaluations
        )
    } else {
        format!("{doing} · {} evaluations", p.evaluations)
    }
}

/// The overall line of several jobs running together: how many are done, and the time left
/// from the mean time of those done so far (`None` before the first is done).
pub fn jobs_message(done: usize, of: usize, elapsed_s: f64) -> String {
    let left = (done > 0 && done < of).then(|| {
        let each = elapsed_s / done as f64;
        format!(" · ~{:.0} s left", each * (of - done) as f64)
    });
    format!("{done} of {of} done{}", left.unwrap_or_default())
}

/// The live display of a discovery run on `bar`: the step, the candidate being fitted (i of
/// n), the best held-out score so far in the step (residuals in `unit`, scaled by `scale`
/// from SI) and the time left in the step, from the mean time of its candidates so far.
pub fn discovery_observer(bar: Arc<dyn Job>, unit: &'static str, scale: f64) -> DiscoveryObserver {
    struct StepState {
        step: usize,
        started: Instant,
        done: usize,
        best: Option<(String, f64, f64)>,
    }
    let fresh = |step| StepState {
        step,
        started: Instant::now(),
        done: 0,
        best: None,
    };
    let state = Mutex::new(fresh(0));
    DiscoveryObserver::new(move |event| {
        let Ok(mut s) = state.lock() else {
            return;
        };
        match event {
            DiscoveryEvent::Base => bar.message("fitting the base on the whole record"),
            DiscoveryEvent::Candidate {
                step,
                index,
                of,
                name,
            } => {
                if *step != s.step {
                    *s = fresh(*step);
                }
                let left = (s.done > 0).then(|| {
                    let each = s.started.elapsed().as_secs_f64() / s.done as f64;
                    format!(
                        " · ~{:.0} s left in this step",
                        each * of.saturating_sub(s.done) as f64
                    )
                });
                let best = s.best.as_ref().map(|(n, rms, z)| {
                    format!(
                        " · best `{n}` held-out {:.4} {unit} (z {z:.1})",
                        rms * scale
                    )
                });
                let text = format!(
                    "step {step} · candidate {}/{of} `{name}`{}{}",
                    index + 1,
                    best.unwrap_or_default(),
                    left.unwrap_or_default()
                );
                bar.message(&text);
            }
            DiscoveryEvent::Scored {
                name,
                holdout_rms,
                gain_z,
                ..
            } => {
                s.done += 1;
                if s.best.as_ref().is_none_or(|(_, r, _)| holdout_rms < r) {
                    s.best = Some((name.clone(), *holdout_rms, *gain_z));
                }
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_speak_of_the_work_not_the_solver() {
        let p = FitProgress {
            stage: SolverStage::LevenbergMarquardt,
            evaluations: 42,
            best_cost: 4e-4,
        };
        assert_eq!(
            fit_message(&p, "N", 1.0),
            "refining the best point · 42 evaluations · best RMS 0.0200 N"
        );
        assert_eq!(jobs_message(0, 4, 1.0), "0 of 4 done");
        assert_eq!(jobs_message(2, 4, 6.0), "2 of 4 done · ~6 s left");
        assert_eq!(jobs_message(4, 4, 9.0), "4 of 4 done");
    }
}
