//! Worker threads kept awake through a frame and a little after it.
//!
//! A rayon worker with nothing to do yields a few dozen times and then sleeps; waking a
//! sleeping thread takes the operating system tens of microseconds, and well over 100 µs on a
//! virtual machine whose idle CPU has halted. A frame of a small mesh is a few such phases of
//! 30–120 µs each (vertex stage, primitive stage, binning, raster), so a helper that sleeps
//! between them arrives when the phase is over: measured on a 2-core VM, the 3644-vertex
//! teapot's geometry stages took as long on two threads as on one.
//!
//! [`WarmWorkers`] keeps every worker looking for work — running any that appears, yielding its
//! CPU to other threads in between — from [`super::Renderer::begin_frame`] until a short while
//! after the frame ends, when the next frame of a loop usually begins. It changes only when
//! work starts, never what is computed.

use std::cell::Cell;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering::SeqCst};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How long workers stay awake once a frame has begun, at most, if it does not end (a caller
/// that queues draws slowly gets its CPUs back).
pub(super) const WARM_WHILE_QUEUING: Duration = Duration::from_millis(20);

/// How long workers stay awake after a frame ends, for the next frame of a loop.
pub(super) const WARM_AFTER_FRAME: Duration = Duration::from_micros(500);

thread_local! {
    /// This thread is in a keep-awake loop (a second one would only nest in it).
    static KEEPING_AWAKE: Cell<bool> = const { Cell::new(false) };
}

/// The keep-awake state shared by a renderer and its workers' loops.
#[derive(Debug)]
pub(super) struct WarmWorkers {
    /// The instant the deadlines count from.
    epoch: Instant,
    /// Nanoseconds after `epoch` until which the loops keep running.
    until_ns: AtomicU64,
    /// Loops running now.
    awake: AtomicUsize,
}

impl WarmWorkers {
    pub(super) fn new() -> Arc<Self> {
        Arc::new(Self {
            epoch: Instant::now(),
            until_ns: AtomicU64::new(0),
            awake: AtomicUsize::new(0),
        })
    }

    fn now_ns(&self) -> u64 {
        u64::try_from(self.epoch.elapsed().as_nanos()).unwrap_or(u64::MAX)
    }

    /// The loops' deadline has passed.
    fn deadline_passed(&self) -> bool {
        self.now_ns() >= self.until_ns.load(SeqCst)
    }

    /// Keeps the workers of `pool` awake for `period` from now (replacing an earlier deadline),
    /// starting a loop on every worker unless all of them run one.
    ///
    /// Only from outside the pool, while it runs no frame: a worker takes a loop before any
    /// other work, so a loop never runs nested above a frame's pending work (which it would
    /// hold up until its deadline).
    pub(super) fn keep_awake(self: &Arc<Self>, pool: &rayon::ThreadPool, period: Duration) {
        let period_ns = u64::try_from(period.as_nanos()).unwrap_or(u64::MAX);
        self.until_ns
            .store(self.now_ns().saturating_add(period_ns), SeqCst);
        // A loop that is leaving re-reads the deadline after counting itself out, so a count
        // read here that still includes it is safe (see `run_loop`).
        if self.awake.load(SeqCst) >= pool.current_num_threads() {
            return;
        }
        let warm = Arc::clone(self);
        pool.spawn_broadcast(move |_| warm.run_loop());
    }

    /// Lets the loops end now.
    pub(super) fn release(&self) {
        self.until_ns.store(0, SeqCst);
    }

    /// On a worker: runs pool work as it appears until the deadline passes.
    fn run_loop(&self) {
        if KEEPING_AWAKE.with(|k| k.replace(true)) {
            return;
        }
        self.awake.fetch_add(1, SeqCst);
        loop {
            if self.deadline_passed() {
                self.awake.fetch_sub(1, SeqCst);
                // Leave unless the deadline moved on after the check above, by a `keep_awake`
                // that saw this loop still counted and started none.
                if self.deadline_passed() {
                    break;
                }
                self.awake.fetch_add(1, SeqCst);
            }
            match rayon::yield_now() {
                Some(rayon::Yield::Executed) => {}
                // Nothing to run: let another thread of the machine have the CPU meanwhile.
                _ => std::thread::yield_now(),
            }
        }
        KEEPING_AWAKE.with(|k| k.set(false));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    fn pool(threads: usize) -> rayon::ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    }

    /// Polls `condition` for up to ten seconds (a loaded test machine can be slow to schedule a
    /// thread; this is not a timing test).
    fn eventually(condition: impl Fn() -> bool) -> bool {
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(10) {
            if condition() {
                return true;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        condition()
    }

    #[test]
    fn every_worker_runs_one_loop_however_often_asked() {
        let pool = pool(3);
        let warm = WarmWorkers::new();
        for _ in 0..20 {
            warm.keep_awake(&pool, Duration::from_secs(30));
        }
        assert!(eventually(|| warm.awake.load(SeqCst) == 3));
        // Asked again while all run one: no second loop on any worker.
        for _ in 0..20 {
            warm.keep_awake(&pool, Duration::from_secs(30));
            assert!(warm.awake.load(SeqCst) <= 3);
        }
        warm.release();
        assert!(eventually(|| warm.awake.load(SeqCst) == 0));
    }

    #[test]
    fn loops_run_the_pools_work_and_end_at_their_deadline() {
        let pool = pool(2);
        let warm = WarmWorkers::new();
        warm.keep_awake(&pool, Duration::from_secs(30));
        assert!(eventually(|| warm.awake.load(SeqCst) == 2));
        // Work given to the pool while both workers loop is done, by both of them.
        let threads: std::collections::BTreeSet<usize> = pool.install(|| {
            (0..64)
                .into_par_iter()
                .with_max_len(1)
                .map(|_| {
                    std::thread::sleep(Duration::from_millis(2));
                    rayon::current_thread_index().unwrap()
                })
                .collect()
        });
        assert_eq!(threads.len(), 2, "work ran on {threads:?}");
        // A short deadline replaces the long one, and the loops end by themselves.
        warm.keep_awake(&pool, Duration::from_millis(1));
        assert!(eventually(|| warm.awake.load(SeqCst) == 0));
    }
}
