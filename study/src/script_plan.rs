//! What the script models of a run will cost, said before the run starts, and a run planned
//! past the scripts' time budget refused (`[scripts] run_seconds`).
//!
//! The plan is a lower estimate, so that only a run sure to be too long is refused (the
//! budget itself stops the rest as it runs): a fit evaluates its model at least ten times per
//! free parameter and once more (a Levenberg–Marquardt fit of ten Jacobians), each
//! evaluation one call a sample at force level, and at trajectory level six (one
//! Dormand–Prince step a sample at the least).

use crate::experiment::FitLevel;
use anyhow::Result;

use crate::experiment::Experiment;
use crate::model_config::ConfiguredModel;
use crate::observer::Observer;

/// Evaluations a fit of `free` free parameters needs at the least.
fn evaluations(free: usize) -> f64 {
    10.0 * (free as f64 + 1.0)
}

/// Script calls a fit of `models` over `samples` samples at `level` needs at the least.
pub fn fit_calls(models: &[Option<ConfiguredModel>], samples: usize, level: FitLevel) -> f64 {
    let per_evaluation = match level {
        FitLevel::Force => samples as f64,
        FitLevel::Trajectory => 6.0 * samples as f64,
    };
    models
        .iter()
        .map(|m| {
            let free = m
                .as_ref()
                .map_or(0, |m| m.params.iter().filter(|p| !p.fixed).count());
            evaluations(free) * per_evaluation
        })
        .sum()
}

/// Runs planned to take at least this long (s) are said before they start.
const SAID_FROM: f64 = 1.0;

/// Say (to `observer`) what the experiment's scripts will cost a run of `calls` calls
/// (`what`: "this fit") when that is a second or more, or refuse it when a script would take
/// longer than its budget.
pub fn check(exp: &Experiment, calls: f64, what: &str, observer: &dyn Observer) -> Result<()> {
    let lines = exp
        .scripts
        .plan(calls, what)
        .map_err(|e| anyhow::anyhow!("{}: {e}", exp.path.display()))?;
    for (line, seconds) in lines {
        if seconds >= SAID_FROM {
            observer.note(&line);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fit_needs_more_calls_at_trajectory_level_and_with_more_parameters() {
        let force = fit_calls(&[None], 1000, FitLevel::Force);
        assert_eq!(force, 10.0 * 1000.0);
        assert_eq!(fit_calls(&[None], 1000, FitLevel::Trajectory), 6.0 * force);
        assert_eq!(fit_calls(&[None, None], 1000, FitLevel::Force), 2.0 * force);
        assert_eq!(fit_calls(&[], 1000, FitLevel::Force), 0.0);
    }
}
