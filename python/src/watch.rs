//! The study's [`Observer`] for a run started from Python: each job's messages become the
//! run's status line (shown by the Python progress callback), the study's warnings are kept
//! for the result, and an interrupt both answers [`Observer::cancelled`] (the study stops
//! between jobs) and unwinds a job at its next message ([`Cancel::check`]: within a fit, after
//! the evaluation under way).

use std::sync::{Arc, Mutex};

use stf_study::observer::{Job, Observer};

use crate::run::Run;

/// The observer of one run.
pub struct Watch {
    run: Run,
    /// The study's warnings about the inputs (a record that looks wrong), in order.
    pub warnings: Arc<Mutex<Vec<String>>>,
}

impl Watch {
    /// The observer of `run`.
    pub fn new(run: &Run) -> Self {
        Watch {
            run: run.clone(),
            warnings: Arc::default(),
        }
    }

    /// The warnings said so far.
    pub fn warnings(&self) -> Vec<String> {
        self.warnings.lock().map(|w| w.clone()).unwrap_or_default()
    }
}

/// One job's line: its name and its latest message.
struct Line {
    name: String,
    run: Run,
}

impl Job for Line {
    fn message(&self, text: &str) {
        self.run.cancel.check();
        self.run.say(format!("{}  {text}", self.name));
    }
}

impl Observer for Watch {
    fn job(&self, name: &str) -> Arc<dyn Job> {
        self.run.cancel.check();
        self.run.say(name);
        Arc::new(Line {
            name: name.to_string(),
            run: self.run.clone(),
        })
    }

    fn finished(&self, what: &str) {
        self.run.say(format!("finished {what}"));
    }

    fn note(&self, text: &str) {
        self.run.say(text);
    }

    fn warning(&self, text: &str) {
        if let Ok(mut w) = self.warnings.lock() {
            w.push(text.to_string());
        }
    }

    fn cancelled(&self) -> bool {
        self.run.cancel.is_set()
    }
}
