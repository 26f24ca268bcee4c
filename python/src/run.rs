//! Long work off the interpreter: a workflow runs on its own thread while the calling thread
//! waits with the GIL released ([`Python::detach`]), waking every [`POLL`] to honour Ctrl-C
//! (the notebook's stop button: [`Python::check_signals`]) and to pass the run's latest
//! status to an optional Python progress callback.
//!
//! An interrupt raises `stf_lab.Interrupted` at once and asks the run to stop ([`Cancel`]):
//! the study's observer ([`crate::watch`]) answers that it is cancelled, so the study stops
//! between jobs, and unwinds a job at its next progress message with [`Cancelled`], which is
//! caught here and never printed; a step that sends no message (a simulation of the
//! `[simulate]` section) finishes in the background and its result is dropped. The bindings write nothing, so nothing is ever half-written. A panic on
//! the worker thread is caught too and becomes `StfLabError` naming it a bug: no panic
//! reaches Python.

use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;

use stf_study::error::StudyError;

use crate::errors::{other, py_error, to_py};

/// How often the waiting thread looks for Ctrl-C and reports progress.
pub const POLL: Duration = Duration::from_millis(100);

/// The payload a cancelled run unwinds with ([`Cancel::check`]).
#[derive(Debug)]
pub struct Cancelled;

/// The request to stop a run, set by an interrupt and read by the run.
#[derive(Clone, Debug, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// Whether the run was asked to stop.
    pub fn is_set(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    fn set(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Unwind out of the run if it was asked to stop (`resume_unwind`: no panic message).
    pub fn check(&self) {
        if self.is_set() {
            std::panic::resume_unwind(Box::new(Cancelled));
        }
    }
}

/// What a running job shares with the waiting thread: its status line and the stop request.
#[derive(Clone, Debug, Default)]
pub struct Run {
    /// Set by an interrupt.
    pub cancel: Cancel,
    status: Arc<Mutex<String>>,
}

impl Run {
    /// Say what the run is doing now (shown by the progress callback).
    pub fn say(&self, status: impl Into<String>) {
        if let Ok(mut s) = self.status.lock() {
            *s = status.into();
        }
    }

    fn status(&self) -> String {
        self.status.lock().map(|s| s.clone()).unwrap_or_default()
    }
}

/// The message of an interrupted run: the study's own.
pub fn interrupted_message() -> String {
    stf_study::error::Interrupted.to_string()
}

/// What a panic's payload says.
fn panic_text(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(no message)".to_string()
    }
}

/// The outcome of the worker thread as a Python result.
fn outcome<T>(py: Python<'_>, r: std::thread::Result<Result<T, StudyError>>) -> PyResult<T> {
    match r {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(e)) => Err(to_py(py, &e)),
        Err(payload) if payload.is::<Cancelled>() => {
            Err(py_error(py, "Interrupted", interrupted_message()))
        }
        Err(payload) => Err(other(
            py,
            format!(
                "internal error (a bug of stf-lab; please report it): {}",
                panic_text(payload.as_ref())
            ),
        )),
    }
}

/// Call `progress(status, elapsed_s)`; an exception it raises stops the run.
fn report(progress: Option<&Bound<'_, PyAny>>, job: &Run, t0: Instant) -> PyResult<()> {
    match progress {
        Some(cb) => cb
            .call1((job.status(), t0.elapsed().as_secs_f64()))
            .map(|_| ()),
        None => Ok(()),
    }
}

/// A `KeyboardInterrupt` becomes `stf_lab.Interrupted` (itself a `KeyboardInterrupt`).
fn interrupted(py: Python<'_>, e: PyErr) -> PyErr {
    if e.is_instance_of::<PyKeyboardInterrupt>(py) {
        py_error(py, "Interrupted", interrupted_message())
    } else {
        e
    }
}

/// Run `work` on a thread of its own, the GIL released while it runs, Ctrl-C honoured and
/// `progress` (a callable taking the status line and the seconds elapsed) called at the start
/// and every [`POLL`].
pub fn run_interruptible<T, F>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    work: F,
) -> PyResult<T>
where
    T: Send + 'static,
    F: FnOnce(&Run) -> Result<T, StudyError> + Send + 'static,
{
    let job = Run::default();
    job.say("starting");
    let (tx, mut rx) = channel();
    let worker = job.clone();
    let t0 = Instant::now();
    std::thread::Builder::new()
        .name("stf-lab run".into())
        .spawn(move || {
            let r = catch_unwind(AssertUnwindSafe(|| work(&worker)));
            let _ = tx.send(r);
        })
        .map_err(|e| other(py, format!("cannot start the run's thread: {e}")))?;
    let stop = |e: PyErr| {
        job.cancel.set();
        interrupted(py, e)
    };
    report(progress, &job, t0).map_err(stop)?;
    loop {
        // The receiver goes into the detached closure and back (it is not `Sync`).
        let (got, back) = py.detach(move || (rx.recv_timeout(POLL), rx));
        rx = back;
        match got {
            Ok(r) => return outcome(py, r),
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => {
                let msg = "internal error: the run's thread ended without a result";
                return Err(other(py, msg.into()));
            }
        }
        py.check_signals().map_err(stop)?;
        report(progress, &job, t0).map_err(stop)?;
    }
}
