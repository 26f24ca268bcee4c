//! Independent jobs of uneven cost run on every core, the costliest started first
//! ([`costly_first`]): a step's candidates, whose fits range from a few milliseconds (a
//! memoryless term) to a second (a model with state integrated along the record at every
//! evaluation). Split in halves as rayon's `par_iter` splits them, a costly candidate near the
//! end of a step's list started late and ended the step alone; here each thread takes the
//! next job from one queue in order of expected cost, the longest-processing-time-first rule.
//! Rayon has no such queue: `par_iter` splits a list into halves, and `scope`'s spawns run
//! most recent first on the spawning thread.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};

/// `run(i)` for each `i` in `0..n` on rayon's threads, returned in index order; started in
/// order of `rank` (largest first, ties in index order), each thread taking the next from one
/// queue when it is done with the last. Each job's result is its own: the order they run in
/// changes when they end, not what they return.
pub(super) fn costly_first<R: Send, K: Ord>(
    n: usize,
    rank: impl Fn(usize) -> K,
    run: impl Fn(usize) -> R + Sync,
) -> Vec<R> {
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(rank(i)));
    let next = AtomicUsize::new(0);
    let done: Vec<Mutex<Option<R>>> = (0..n).map(|_| Mutex::new(None)).collect();
    let take = || loop {
        let Some(&i) = order.get(next.fetch_add(1, Ordering::Relaxed)) else {
            return;
        };
        let r = run(i);
        *done[i].lock().unwrap_or_else(PoisonError::into_inner) = Some(r);
    };
    rayon::scope(|s| {
        for _ in 1..rayon::current_num_threads().min(n) {
            s.spawn(|_| take());
        }
        take();
    });
    done.into_iter()
        .map(|m| m.into_inner().unwrap_or_else(PoisonError::into_inner))
        .map(|r| r.expect("each index is taken from the queue once and run"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_job_runs_once_and_returns_in_index_order() {
        let rank = |i: usize| [1, 5, 1, 9, 0, 5, 2][i];
        let on = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let started = Mutex::new(Vec::new());
            let out = pool.install(|| {
                costly_first(7, rank, |i| {
                    started.lock().unwrap().push(i);
                    10 * i
                })
            });
            (out, started.into_inner().unwrap())
        };
        // One thread: in order of rank, largest first, ties in index order.
        let (out, started) = on(1);
        assert_eq!(out, [0, 10, 20, 30, 40, 50, 60]);
        assert_eq!(started, [3, 1, 5, 6, 0, 2, 4]);
        // Three threads: each job once, the results in index order.
        let (out, mut started) = on(3);
        assert_eq!(out, [0, 10, 20, 30, 40, 50, 60]);
        started.sort();
        assert_eq!(started, [0, 1, 2, 3, 4, 5, 6]);
        assert!(costly_first(0, |i| i, |i| i).is_empty());
    }
}
