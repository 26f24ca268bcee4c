//! Progress of long work on a terminal (indicatif), silent in CI, with `--quiet`, or when
//! standard error is not a terminal.

use std::io::IsTerminal;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use stf_core::fit::FitProgress;

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
                bar.set_prefix(name.to_string());
                bar.enable_steady_tick(std::time::Duration::from_millis(120));
                bar
            }
        }
    }
}

/// The message a fit's progress shows.
pub fn fit_message(p: &FitProgress) -> String {
    format!(
        "{:?}: {} evaluations, best cost {:.4e}",
        p.stage, p.evaluations, p.best_cost
    )
}
