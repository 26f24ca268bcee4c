//! How the units to run are cut into Slurm jobs: `units_per_task` units per array task (run
//! one after another), at most `max_array_size` tasks per job array (Slurm's `MaxArraySize`:
//! task indices 0 to `max_array_size - 1`), as many arrays as that takes. Only numbers here;
//! [`super::slurm_script`] writes the scripts and [`super::slurm`] submits them.
//!
//! The default units per task follows the units' expected cost ([`expected_seconds`]): a
//! task should hold about [`TASK_SECONDS`] of work, since Slurm spends a second or more
//! starting each task (measured on the single-node test cluster: about two tasks every 2–3 s
//! on 2 CPUs), but a campaign keeps at least [`MIN_TASKS`] tasks when it has that many units,
//! so a small one still spreads over the nodes.

use super::file::CommandName;

/// The work one array task should hold by default, s.
pub const TASK_SECONDS: f64 = 60.0;

/// Tasks a campaign is cut into at least, when it has that many units (default units per
/// task only).
pub const MIN_TASKS: usize = 16;

/// Slurm's own default `MaxArraySize`, used when the cluster's cannot be read.
pub const SLURM_DEFAULT_MAX_ARRAY_SIZE: usize = 1001;

/// The expected wall time of one unit of `command`, s: orders of magnitude of the bundled
/// examples (a `fit` of a record about 1 s, a `compare` several fits and simulations, a
/// `discover` many candidate fits).
pub fn expected_seconds(command: CommandName) -> f64 {
    match command {
        CommandName::Fit => 2.0,
        CommandName::Compare => 10.0,
        CommandName::Discover => 120.0,
    }
}

/// The default units per task for units running `commands` (one entry per unit): about
/// [`TASK_SECONDS`] of the costliest command's units, but no fewer than [`MIN_TASKS`] tasks
/// when there are that many units; at least 1.
pub fn default_units_per_task(commands: &[CommandName]) -> usize {
    let costliest = commands
        .iter()
        .map(|&c| expected_seconds(c))
        .fold(0.0, f64::max);
    if costliest <= 0.0 {
        return 1;
    }
    let by_cost = (TASK_SECONDS / costliest).floor() as usize;
    let by_spread = commands.len().div_ceil(MIN_TASKS);
    by_cost.min(by_spread).max(1)
}

/// One job array: its tasks' units, task `i` (`$SLURM_ARRAY_TASK_ID`) running `tasks[i]`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ArrayPlan {
    /// The units of each task, by task index.
    pub tasks: Vec<Vec<usize>>,
}

impl ArrayPlan {
    /// The units of every task, in order.
    pub fn units(&self) -> impl Iterator<Item = usize> + '_ {
        self.tasks.iter().flatten().copied()
    }
}

/// `units` (ascending numbers) cut into tasks of `per_task` units and arrays of at most
/// `max_array_size` tasks (both at least 1).
pub fn arrays(units: &[usize], per_task: usize, max_array_size: usize) -> Vec<ArrayPlan> {
    let tasks: Vec<Vec<usize>> = units
        .chunks(per_task.max(1))
        .map(<[usize]>::to_vec)
        .collect();
    tasks
        .chunks(max_array_size.max(1))
        .map(|t| ArrayPlan { tasks: t.to_vec() })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_are_cut_into_tasks_and_arrays_within_the_limit() {
        let units: Vec<usize> = (1..=7).collect();
        let a = arrays(&units, 2, 3);
        assert_eq!(a.len(), 2);
        assert_eq!(a[0].tasks, vec![vec![1, 2], vec![3, 4], vec![5, 6]]);
        assert_eq!(a[1].tasks, vec![vec![7]]);
        // 3 000 units one per task on a cluster with MaxArraySize 1001: indices 0..=1000.
        let many: Vec<usize> = (1..=3000).collect();
        let a = arrays(&many, 1, 1001);
        assert_eq!(
            a.iter().map(|a| a.tasks.len()).collect::<Vec<_>>(),
            [1001, 1001, 998]
        );
        let all: Vec<usize> = a.iter().flat_map(ArrayPlan::units).collect();
        assert_eq!(all, many);
        // Unfinished units need not be consecutive.
        let a = arrays(&[2, 5, 9], 2, 1001);
        assert_eq!(a[0].tasks, vec![vec![2, 5], vec![9]]);
    }

    #[test]
    fn the_default_units_per_task_follows_the_commands_and_keeps_tasks_to_spread() {
        use CommandName::*;
        assert_eq!(default_units_per_task(&[Fit; 3]), 1);
        assert_eq!(default_units_per_task(&[Fit; 3000]), 30);
        assert_eq!(default_units_per_task(&[Fit; 100]), 7);
        assert_eq!(default_units_per_task(&[Compare; 3000]), 6);
        let mut mixed = vec![Fit; 2999];
        mixed.push(Discover);
        assert_eq!(default_units_per_task(&mixed), 1);
        assert_eq!(default_units_per_task(&[]), 1);
    }
}
