//! The renderer's worker pool: named threads, optionally pinned one to a CPU.
//!
//! Pinning is opt-in ([`RendererOptions::pin_workers`](super::RendererOptions::pin_workers),
//! or [`PIN_ENV`]`=1`). It helps where the operating system keeps workers on fewer CPUs than
//! it has: on a 2-vCPU virtual machine whose kernel packs threads onto fewer virtual CPUs, both
//! workers at times shared one CPU for whole runs, the keep-awake loops ([`super::warm`])
//! handed it back and forth, and a frame took the one-thread time (a full-screen triangle at
//! 2048 × 1536: 0.53 ms instead of 0.29 in 14 of 16 runs; pinned, 0.29 ms in 16 of 16). It
//! costs where other busy threads share the machine: a pinned worker cannot leave a CPU that
//! another process holds, so with one CPU-bound process beside it bunny took 12–16 ms pinned
//! against 10.5–11.3 ms free (docs/design-notes.md, threading). Pinning changes only
//! where threads run, never what is computed.

use core_affinity::CoreId;

/// Environment variable read when
/// [`RendererOptions::pin_workers`](super::RendererOptions::pin_workers) is `None`: `1` pins
/// the workers (one to each CPU the creating thread may use, where there are no more workers
/// than such CPUs), `0`, unset or anything else leaves them free to move.
pub const PIN_ENV: &str = "KANTELE_PIN_WORKERS";

/// Whether pinning is asked for: the option, else [`PIN_ENV`].
fn asked(option: Option<bool>) -> bool {
    option.unwrap_or_else(|| parse_env(std::env::var(PIN_ENV).ok().as_deref()))
}

/// Reads a value of [`PIN_ENV`]: `1` asks for pinning, anything else (or nothing) does not.
fn parse_env(value: Option<&str>) -> bool {
    value.map(str::trim) == Some("1")
}

/// Whether a pool of `workers` threads, asked to pin, can give each its own of `cpus` CPUs.
fn fits(workers: usize, cpus: usize) -> bool {
    workers <= cpus
}

/// A pool of `threads` workers (`None` or 0: one per core) named `kantele-worker-{i}`. Where
/// `pin` (or [`PIN_ENV`]) asks for it and the pool has no more workers than the calling thread
/// has CPUs to run on, worker `i` is pinned to the `i`-th of those CPUs. A worker that cannot
/// be pinned (the platform refuses or does not tell) stays free to move.
pub(super) fn worker_pool(
    threads: Option<usize>,
    pin: Option<bool>,
) -> Result<rayon::ThreadPool, rayon::ThreadPoolBuildError> {
    let mut builder = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .thread_name(|i| format!("kantele-worker-{i}"));
    let cpus: Option<Vec<CoreId>> = asked(pin).then(core_affinity::get_core_ids).flatten();
    if let Some(cpus) = cpus {
        builder = builder.start_handler(move |index| {
            // The handler runs on the new worker, which already belongs to its pool: the count
            // is the pool's own (rayon's default size included).
            if fits(rayon::current_num_threads(), cpus.len()) {
                if let Some(&cpu) = cpus.get(index) {
                    // `false` (refused): the worker stays free to move.
                    let _ = core_affinity::set_for_current(cpu);
                }
            }
        });
    }
    builder.build()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_one_asks_for_pinning() {
        assert!(parse_env(Some("1")) && parse_env(Some(" 1\n")));
        for other in [None, Some(""), Some("0"), Some("yes"), Some("2")] {
            assert!(!parse_env(other), "{other:?}");
        }
        // The renderer option wins over the environment.
        assert!(asked(Some(true)));
        assert!(!asked(Some(false)));
        assert!(fits(1, 16) && fits(16, 16) && !fits(17, 16));
    }

    /// The CPU of each worker of a pool of `threads` that runs on one CPU only (`None` for a
    /// worker free to move), sorted.
    fn worker_cpus(threads: usize, pin: Option<bool>) -> Vec<Option<usize>> {
        let pool = worker_pool(Some(threads), pin).unwrap();
        let mut cpus = pool.broadcast(|_| match core_affinity::get_core_ids()?.as_slice() {
            [only] => Some(only.id),
            _ => None,
        });
        cpus.sort();
        cpus
    }

    #[test]
    fn pinned_workers_each_run_on_their_own_cpu() {
        let Some(cpus) = core_affinity::get_core_ids() else {
            eprintln!("skipped: this platform does not tell a thread's CPUs");
            return;
        };
        let seen = worker_cpus(cpus.len(), Some(true));
        let mut ids: Vec<usize> = seen.iter().map(|c| c.expect("a pinned worker")).collect();
        ids.dedup();
        assert_eq!(ids.len(), cpus.len(), "one CPU per worker: {seen:?}");
    }

    #[test]
    fn workers_stay_free_unless_asked_or_when_they_outnumber_the_cpus() {
        let cpus = core_affinity::get_core_ids().map_or(0, |c| c.len());
        if cpus < 2 {
            eprintln!(
                "skipped: the test thread may run on {cpus} CPU(s); free and pinned look alike"
            );
            return;
        }
        assert_eq!(worker_cpus(2, Some(false)), [None, None]);
        assert_eq!(worker_cpus(cpus + 1, Some(true)), vec![None; cpus + 1]);
    }
}
