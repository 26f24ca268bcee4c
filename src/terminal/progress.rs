//! Progress of long work on a terminal (indicatif), silent in CI, with `--quiet`, or when
//! standard error is not a terminal: the command line's [`stf_study::observer::Observer`].
//! Job names and messages quote model names, which may come from script files: their control
//! characters are escaped ([`crate::terminal`]). A finished step is recorded for the interrupt
//! message ([`crate::terminal::interrupt`]).

use std::io::IsTerminal;
use std::sync::Arc;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use stf_study::observer::{Job, Observer};

use crate::terminal::escape_controls;

/// A set of spinners, one per running job.
pub struct Progress {
    multi: Option<MultiProgress>,
    quiet: bool,
}

impl Progress {
    /// Progress shown unless `quiet`, CI is set, or stderr is not a terminal; notes said
    /// unless `quiet`, warnings always.
    pub fn new(quiet: bool) -> Self {
        let visible = !quiet && std::env::var_os("CI").is_none() && std::io::stderr().is_terminal();
        Progress {
            multi: visible.then(|| MultiProgress::with_draw_target(ProgressDrawTarget::stderr())),
            quiet,
        }
    }

    /// A spinner for a job called `name` (hidden when progress is off).
    pub fn bar(&self, name: &str) -> ProgressBar {
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

/// A spinner as a study's job.
struct Spinner(ProgressBar);

impl Job for Spinner {
    fn message(&self, text: &str) {
        self.0.set_message(escape_controls(text).into_owned());
    }
    fn finish(&self) {
        self.0.finish_and_clear();
    }
}

impl Observer for Progress {
    fn job(&self, name: &str) -> Arc<dyn Job> {
        Arc::new(Spinner(self.bar(name)))
    }
    fn note(&self, text: &str) {
        if !self.quiet {
            crate::tell!("{text}");
        }
    }
    fn warning(&self, text: &str) {
        eprintln!("warning: {text}");
    }
    fn finished(&self, what: &str) {
        crate::terminal::interrupt::finished_step(what);
    }
}
