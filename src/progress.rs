//! Progress of long work on a terminal (indicatif), silent in CI, with `--quiet`, or when
//! standard error is not a terminal. Job names and messages quote model names, which may come
//! from script files: their control characters are escaped ([`crate::terminal`]).

use std::io::IsTerminal;

use std::sync::Mutex;
use std::time::Instant;

use crate::terminal::escape_controls;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use stf_core::discovery::{DiscoveryEvent, Observer};
use stf_core::fit::{FitProgress, SolverStage};

/// A set of spinners, one per running job.
pub struct Progress {
    multi: Option<MultiProgress>,
}

impl Progress {
    /// Progress shown unless `quiet`, CI is set, or stderr is not a terminal.
    pub fn new(quiet: bool) -> Self {
        let visible = !quiet && std::env::var_os("CI").is_none() && std::io::stderr().is_terminal();
        Progress {
            multi: visible.then(|| MultiProgress::with_draw_target(ProgressDrawTarget::stderr())),
        }
    }

    /// A spinner for a job called `name` (hidden when progress is off).
    pub fn job(&self, name: &str) -> ProgressBar {
        match &self.multi {
            None => ProgressBar::hidden(),
            Some(m) => {
                let bar = m.add(ProgressBar::new_spinner());
                if let Ok(style) =
                    ProgressStyle::with_template("{spinner} {prefix:<28} {msg} [{elapsed}]")
                {
                    bar.set_style(style);
                }
                bar.set_prefix(escape_controls(name).into_owned());
                bar.enable_steady_tick(std::time::Duration::from_millis(120));
                bar
            }
        }
    }
}

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
pub fn discovery_observer(bar: ProgressBar, unit: &'static str, scale: f64) -> Observer {
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
    Observer::new(move |event| {
        let Ok(mut s) = state.lock() else {
            return;
        };
        match event {
            DiscoveryEvent::Base => bar.set_message("fitting the base on the whole record"),
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
                bar.set_message(escape_controls(&text).into_owned());
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
