//! Keeps the rayon pool's threads awake through a run of many short parallel steps (training).
//!
//! rayon parks an idle worker after a few dozen yields, and on a virtual machine waking a parked worker costs
//! tens of microseconds at each end of a parallel region: measured here, a `join` of two 50 µs halves after
//! 200 µs of serial work took 133 µs instead of 51. A training step of PETS' small preset or SAC is a few
//! parallel regions of well under a millisecond, each after some serial work, so that latency was a fifth of
//! the step on two threads. PyTorch's OpenMP threads spin between regions for the same reason.
//!
//! [`run_warm`] runs its closure on a pool thread while every other worker, instead of parking, takes any
//! pending work and otherwise yields the core to the operating system. Which thread runs a piece of work never
//! decides its result in the fused paths (they split work by shape, not by thread), so the bytes stay those
//! of a cold pool.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Runs `work` on a thread of the current rayon pool (the global one from outside any pool), with the
/// pool's other threads kept awake until it returns. On a pool of one thread it runs `work` where it is.
pub fn run_warm<R: Send>(work: impl FnOnce() -> R + Send) -> R {
    if rayon::current_num_threads() <= 1 {
        return work();
    }
    rayon::scope(|_| {
        let stop = Arc::new(AtomicBool::new(false));
        let caller = rayon::current_thread_index();
        let flag = Arc::clone(&stop);
        rayon::spawn_broadcast(move |context| {
            // The caller's own copy must return at once: it would otherwise run inside a wait of `work`'s and
            // spin on a flag only `work`'s return can set.
            if Some(context.index()) == caller {
                return;
            }
            while !flag.load(Ordering::Acquire) {
                if rayon::yield_now() != Some(rayon::Yield::Executed) {
                    std::thread::yield_now();
                }
            }
        });
        let _stop_on_exit = StopOnDrop(stop);
        work()
    })
}

/// Releases the spinning workers also when `work` panics.
struct StopOnDrop(Arc<AtomicBool>);

impl Drop for StopOnDrop {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

#[cfg(test)]
mod tests {
    use rayon::prelude::*;

    use super::*;

    #[test]
    fn work_runs_on_a_pool_thread_and_its_parallel_regions_complete() {
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let (inside, sum) = pool.install(|| {
                run_warm(|| {
                    let inside = rayon::current_thread_index().is_some();
                    let sum: u64 = (0..200).map(|_| (0..1000u64).into_par_iter().sum::<u64>()).sum();
                    (inside, sum)
                })
            });
            assert!(inside, "{threads} threads");
            assert_eq!(sum, 200 * 999 * 1000 / 2);
        }
    }

    #[test]
    fn from_outside_any_pool_the_work_moves_onto_a_worker_and_returns() {
        let outside = std::thread::spawn(|| {
            run_warm(|| rayon::current_thread_index().is_some() || rayon::current_num_threads() == 1)
        });
        assert!(outside.join().unwrap());
    }

    /// CPU ticks (user + system) the pool's threads have used so far.
    #[cfg(target_os = "linux")]
    fn pool_ticks(pool: &rayon::ThreadPool) -> u64 {
        let per_thread = pool.broadcast(|_| {
            let stat = std::fs::read_to_string("/proc/thread-self/stat").unwrap();
            // Fields after the parenthesised name; utime and stime are the 14th and 15th of the line.
            let rest = &stat[stat.rfind(')').unwrap() + 2..];
            let fields: Vec<u64> = rest.split(' ').skip(11).take(2).map(|f| f.parse().unwrap()).collect();
            fields.iter().sum::<u64>()
        });
        per_thread.iter().sum()
    }

    #[test]
    #[cfg(target_os = "linux")]
    fn the_workers_spin_only_while_the_work_runs_also_when_it_panics() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let idle = std::time::Duration::from_millis(300);
        let before = pool_ticks(&pool);
        pool.install(|| run_warm(|| std::thread::sleep(idle)));
        let during = pool_ticks(&pool) - before;
        assert!(during >= 3, "the other worker used {during} ticks while the work slept");

        let caught = pool.install(|| std::panic::catch_unwind(|| run_warm(|| panic!("stop"))));
        assert!(caught.is_err());
        let before = pool_ticks(&pool);
        std::thread::sleep(idle);
        let after = pool_ticks(&pool) - before;
        assert!(after <= 2, "the workers used {after} ticks after the work had ended");
    }
}
