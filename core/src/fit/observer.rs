//! The one observer of a fit's solver stages: it feeds the progress display and, when asked
//! ([`FitSettings::trace`](super::solver::FitSettings::trace)), writes each iteration's cost
//! and parameters.
//!
//! argmin's `Executor` calls an [`argmin::core::observers::Observe`] implementation after a
//! solver's start and after every iteration, whatever the solver; [`FitObserver`] is that
//! implementation for every stage of a fit (Levenberg–Marquardt's [`LmState`], Nelder–Mead's
//! `IterState`, the swarm's `PopulationState`). argmin keeps its observers for the life of the
//! program (`'static`), while a fit's progress callback is borrowed from its caller: the
//! observer therefore sends [`FitProgress`] down a channel, which a scoped thread of the fit
//! ([`Watch::forwarding`]) hands to the callback, in order, before the fit returns. The
//! counts it reports are the objective's ([`Tally`]): every evaluation of every stage.
//!
//! The trace is text, one block a fit, appended to the file when the fit ends (fits of several
//! models running together each append their whole block):
//!
//! ```text
//! # fit, free parameters: K n
//! # levenberg_marquardt: iteration, mean square residual, the free parameters
//! 0 0.0123 12 1.8
//! 1 0.00456 14.2 1.71
//! ```
//!
//! Iteration 0 is the stage's start; the point is the stage's best so far, in the user's
//! units; Nelder–Mead's and the swarm's costs are the mean squares behind their ln costs.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Sender};
use std::sync::{Arc, Mutex};

use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{Error as ArgminError, Executor, IterState, PopulationState, Solver, State, KV};
use argmin::solver::particleswarm::Particle;

use super::error::FitError;
use super::lm_state::LmState;
use super::objective::{lock, Tally};
use super::result::{FitProgress, SolverStage};
use super::transform::BoundTransform;

/// Nelder–Mead's state in a fit.
pub(super) type SimplexState = IterState<Vec<f64>, (), (), (), (), f64>;

/// The swarm's state in a fit.
pub(super) type SwarmState = PopulationState<Particle<Vec<f64>, f64>, f64>;

/// What the observer reads from a stage's state besides its iteration: the best point so
/// far (in internal coordinates) and its mean squared residual.
pub(super) trait Traced: State {
    /// The best point so far and its mean squared residual.
    fn best(&self) -> Option<(&[f64], f64)>;
}

impl Traced for LmState {
    fn best(&self) -> Option<(&[f64], f64)> {
        Some((self.get_best_param()?, self.get_best_cost()))
    }
}

impl Traced for SimplexState {
    fn best(&self) -> Option<(&[f64], f64)> {
        Some((self.get_best_param()?, self.get_best_cost().exp()))
    }
}

impl Traced for SwarmState {
    fn best(&self) -> Option<(&[f64], f64)> {
        let best = self.get_best_param()?;
        Some((&best.position, self.get_best_cost().exp()))
    }
}

/// Appends of traces, one at a time within the program.
static TRACE_FILE: Mutex<()> = Mutex::new(());

/// A fit's trace under way: where it goes, how to show a point, and its text so far.
struct Trace {
    path: PathBuf,
    transforms: Vec<BoundTransform>,
    text: String,
}

/// What watches a fit: its evaluations' counts, the channel to its progress display and its
/// trace; each stage gets an observer from it ([`Watch::observer`]).
pub(super) struct Watch {
    tally: Arc<Tally>,
    display: Option<Sender<FitProgress>>,
    trace: Option<Arc<Mutex<Trace>>>,
}

impl Watch {
    /// The watch of a fit whose objective counts in `tally`, its progress sent to `display`,
    /// its trace (of the free parameters `names`, shown through `transforms`) written to
    /// `trace` when the fit ends.
    pub(super) fn new(
        tally: Arc<Tally>,
        display: Option<Sender<FitProgress>>,
        trace: Option<&Path>,
        (names, transforms): (&[&str], Vec<BoundTransform>),
    ) -> Self {
        let trace = trace.map(|path| {
            let text = format!("# fit, free parameters: {}\n", names.join(" "));
            Arc::new(Mutex::new(Trace {
                path: path.to_path_buf(),
                transforms,
                text,
            }))
        });
        Watch {
            tally,
            display,
            trace,
        }
    }

    /// Run `f` with a channel whose progress reaches `show` (on a scoped thread, in order,
    /// all of it before this returns); without `show`, with none.
    pub(super) fn forwarding<T>(
        show: Option<&(dyn Fn(FitProgress) + Sync)>,
        f: impl FnOnce(Option<Sender<FitProgress>>) -> T,
    ) -> T {
        let Some(show) = show else {
            return f(None);
        };
        std::thread::scope(|scope| {
            let (tx, rx) = mpsc::channel::<FitProgress>();
            let forward = std::thread::Builder::new()
                .name("fit-progress".into())
                .spawn_scoped(scope, move || rx.iter().for_each(show));
            // Without a thread the progress is not shown; the fit goes on.
            f(forward.is_ok().then_some(tx))
        })
    }

    /// The observer of one stage, if anything watches the fit.
    pub(super) fn observer(&self, stage: SolverStage) -> Option<FitObserver> {
        (self.display.is_some() || self.trace.is_some()).then(|| FitObserver {
            stage,
            tally: Arc::clone(&self.tally),
            display: self.display.clone(),
            trace: self.trace.clone(),
        })
    }

    /// Say that the fit is in `stage`, one that is not an argmin solver (the standard
    /// errors' Jacobian).
    pub(super) fn announce(&self, stage: SolverStage) {
        if let Some(observer) = self.observer(stage) {
            observer.show();
        }
    }

    /// Append the trace to its file (nothing without one).
    pub(super) fn write_trace(&self) -> Result<(), FitError> {
        let Some(trace) = &self.trace else {
            return Ok(());
        };
        let trace = lock(trace);
        let _one_at_a_time = lock(&TRACE_FILE);
        std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&trace.path)
            .and_then(|mut file| file.write_all(trace.text.as_bytes()))
            .map_err(|e| FitError::Trace {
                path: trace.path.display().to_string(),
                reason: e.to_string(),
            })
    }
}

/// Run `executor` with `observer` (if any) watching every iteration: the final state.
pub(super) fn run_observed<O, S, I>(
    executor: Executor<O, S, I>,
    observer: Option<FitObserver>,
) -> Result<I, FitError>
where
    S: Solver<O, I>,
    I: State,
    FitObserver: Observe<I>,
{
    let executor = match observer {
        Some(o) => executor.add_observer(o, ObserverMode::Always),
        None => executor,
    };
    executor
        .run()
        .map(|result| result.state)
        .map_err(|e| FitError::Solver(e.to_string()))
}

/// The observer of one stage of a fit (see the module's documentation).
pub(super) struct FitObserver {
    stage: SolverStage,
    tally: Arc<Tally>,
    display: Option<Sender<FitProgress>>,
    trace: Option<Arc<Mutex<Trace>>>,
}

impl FitObserver {
    /// Send the fit's progress to the display.
    fn show(&self) {
        if let Some(display) = &self.display {
            // A display that has gone away only stops showing.
            let _ = display.send(FitProgress {
                stage: self.stage,
                evaluations: self.tally.evaluations(),
                best_cost: self.tally.best(),
            });
        }
    }

    /// Add a line to the trace: `iteration` and the state's best point and cost.
    fn trace(&self, iteration: u64, state: &impl Traced) -> Result<(), ArgminError> {
        let (Some(trace), Some((u, cost))) = (&self.trace, state.best()) else {
            return Ok(());
        };
        let mut trace = lock(trace);
        let Trace {
            transforms, text, ..
        } = &mut *trace;
        write!(text, "{iteration} {cost:e}")?;
        for (t, &u) in transforms.iter().zip(u) {
            write!(text, " {}", t.to_user(u))?;
        }
        text.push('\n');
        Ok(())
    }
}

impl<I: Traced> Observe<I> for FitObserver {
    fn observe_init(&mut self, _name: &str, state: &I, _kv: &KV) -> Result<(), ArgminError> {
        self.show();
        if let Some(trace) = &self.trace {
            let mut trace = lock(trace);
            let stage = stage_name(self.stage);
            writeln!(
                trace.text,
                "# {stage}: iteration, mean square residual, the free parameters"
            )?;
        }
        self.trace(0, state)
    }

    fn observe_iter(&mut self, state: &I, _kv: &KV) -> Result<(), ArgminError> {
        self.show();
        self.trace(state.get_iter() + 1, state)
    }
}

/// A stage's name as the outputs spell it.
fn stage_name(stage: SolverStage) -> &'static str {
    match stage {
        SolverStage::ParticleSwarm => "particle_swarm",
        SolverStage::NelderMead => "nelder_mead",
        SolverStage::LevenbergMarquardt => "levenberg_marquardt",
        SolverStage::Errors => "errors",
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use std::sync::atomic::{AtomicU64, Ordering};

    use crate::fit::{fit_residuals, FitParam, FitSettings, Residuals};

    use super::*;

    /// r_i = y_i − k·x_i.
    struct Line;

    impl Residuals for Line {
        fn len(&self) -> usize {
            40
        }
        fn residuals(&self, k: &[f64], sink: &mut dyn FnMut(usize, f64)) -> Result<(), String> {
            for i in 0..40 {
                let x = i as f64 * 0.1;
                sink(
                    i,
                    3.0 * x + 0.01 * ((i * 7919 % 13) as f64 - 6.0) - k[0] * x,
                );
            }
            Ok(())
        }
    }

    #[test]
    fn one_observer_shows_every_iteration_and_appends_the_trace() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("trace.txt");
        let params = [FitParam::new("k", 1.0).bounds(0.0, 10.0)];
        let settings = FitSettings::default().trace(path.clone());
        let seen = AtomicU64::new(0);
        let show = |_: FitProgress| {
            seen.fetch_add(1, Ordering::Relaxed);
        };
        let fit = fit_residuals(&Line, &params, &settings, Some(&show)).unwrap();
        // The stage's start, each iteration, then the standard errors.
        assert_eq!(seen.load(Ordering::Relaxed), fit.iterations + 2);
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "# fit, free parameters: k");
        assert!(lines[1].starts_with("# levenberg_marquardt: "), "{text}");
        assert_eq!(lines.len() as u64, 2 + fit.iterations + 1, "{text}");
        let last: Vec<f64> = lines[lines.len() - 1]
            .split(' ')
            .map(|w| w.parse().unwrap())
            .collect();
        assert_eq!(last[0], fit.iterations as f64);
        assert!((last[1] - fit.rss / 40.0).abs() <= 1e-12 * last[1]);
        assert_eq!(last[2], fit.value("k").unwrap());
        // A second fit appends its own block; without a trace nothing is written.
        fit_residuals(&Line, &params, &settings, None).unwrap();
        let again = std::fs::read_to_string(&path).unwrap();
        assert_eq!(again, format!("{text}{text}"));
        let quiet = FitSettings::default();
        fit_residuals(&Line, &params, &quiet, None).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), again);
    }

    #[test]
    fn a_trace_that_cannot_be_written_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let settings = FitSettings::default().trace(dir.path().join("no/such/folder/t.txt"));
        let params = [FitParam::new("k", 1.0).bounds(0.0, 10.0)];
        let e = fit_residuals(&Line, &params, &settings, None).unwrap_err();
        assert!(matches!(e, FitError::Trace { .. }), "{e}");
    }
}
