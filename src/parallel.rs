//! The one parallel mechanism: rayon. The solvers' windows and the re-simulation's chunks run
//! on a pool of the number of threads their options give (0: as many as the machine has), or,
//! when called from a task already on a pool (a span of an adaptive round), on that pool; the
//! sweep's steps on rayon's global pool.

use rayon::prelude::*;

/// A thread count as the options give it: 0 means as many as the machine has.
pub(crate) fn resolve_threads(threads: usize) -> usize {
    if threads == 0 {
        std::thread::available_parallelism().map_or(1, |t| t.get())
    } else {
        threads
    }
}

/// `f` applied to every item on `threads` workers, each item a task of its own (items differ
/// in cost, so a worker takes the next one when it is done); results in item order. One
/// worker, or a pool that cannot be built, maps in turn on the calling thread.
pub(crate) fn par_map<T: Sync, R: Send>(
    items: &[T],
    threads: usize,
    f: impl Fn(&T) -> R + Sync,
) -> Vec<R> {
    let workers = threads.min(items.len()).max(1);
    if workers == 1 {
        return items.iter().map(f).collect();
    }
    // Called from a task already running on a pool (a span of a refinement round): the items
    // join that pool's queue. A pool of its own here would put threads × threads workers on
    // the cores, and cost a pool's start and end per call.
    if rayon::current_thread_index().is_some() {
        return items.par_iter().with_max_len(1).map(&f).collect();
    }
    match rayon::ThreadPoolBuilder::new().num_threads(workers).build() {
        Ok(pool) => pool.install(|| items.par_iter().with_max_len(1).map(&f).collect()),
        Err(_) => items.iter().map(f).collect(),
    }
}
