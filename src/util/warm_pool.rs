//! Keeps the rayon pool's threads awake through a run of many short parallel steps (training).
//!
//! rayon parks an idle worker after a few dozen yields, and on a virtual machine waking a parked worker costs
//! tens of microseconds at each end of a parallel region: measured here, a `join` of two 50 µs halves after
//! 200 µs of serial work took 133 µs instead of 51. A training step of PETS' small preset or SAC is a few
//! parallel regions of well under a millisecond, each after some serial work, so that latency was a fifth of
//! the step on two threads. PyTorch's OpenMP threads spin between regions for the same reason.
//!
//! [`run_warm`] runs its closure on a pool thread while every other worker, instead of parking, takes any
//! pending work and otherwise yields the core to the operating system, until it has found no work for a
//! millisecond (a validation pass, a checkpoint write); the run's loop re-arms the spinners before each step. Which thread runs a piece of work never
//! decides its result in the fused paths (they split work by shape, not by thread), so the bytes stay those
//! of a cold pool.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A spinner that has found no work for this long parks its thread as rayon would. A waiting worker can pick
/// a spinner up and run it nested above its own work (another run's, when runs overlap); the limit bounds how
/// long that work waits, and two runs whose spinners sit above each other's work cannot wait forever.
const IDLE_LIMIT: Duration = Duration::from_millis(1);

/// The handle `work` gets: [`Warm::rearm`] sends spinners out again after a pause has parked them.
pub struct Warm {
    stop: Arc<AtomicBool>,
    live: Arc<AtomicUsize>,
    caller: Option<usize>,
    others: usize,
}

impl Warm {
    /// Sends a spinner to each other worker unless all are still spinning: call it before each step of a run.
    pub fn rearm(&self) {
        if self.others == 0 || self.live.load(Ordering::Acquire) >= self.others {
            return;
        }
        let (stop, live, caller) = (Arc::clone(&self.stop), Arc::clone(&self.live), self.caller);
        rayon::spawn_broadcast(move |context| {
            // The caller's own copy must return at once: it would run inside a wait of `work`'s.
            if Some(context.index()) == caller {
                return;
            }
            live.fetch_add(1, Ordering::AcqRel);
            let mut last_work = Instant::now();
            while !stop.load(Ordering::Acquire) && last_work.elapsed() < IDLE_LIMIT {
                if rayon::yield_now() == Some(rayon::Yield::Executed) {
                    last_work = Instant::now();
                } else {
                    std::thread::yield_now();
                }
            }
            live.fetch_sub(1, Ordering::AcqRel);
        });
    }
}

/// Runs `work` on a thread of the current rayon pool (the global one from outside any pool), with the
/// pool's other threads kept awake while work keeps coming (see [`Warm::rearm`]) until it returns. On a pool
/// of one thread it runs `work` where it is.
pub fn run_warm<R: Send>(work: impl FnOnce(&Warm) -> R + Send) -> R {
    if rayon::current_num_threads() <= 1 {
        let idle = Warm { stop: Arc::default(), live: Arc::default(), caller: None, others: 0 };
        return work(&idle);
    }
    rayon::scope(|_| {
        let caller = rayon::current_thread_index();
        let others = rayon::current_num_threads() - usize::from(caller.is_some());
        let warm = Warm { stop: Arc::default(), live: Arc::default(), caller, others };
        let _stop = StopOnDrop(Arc::clone(&warm.stop));
        warm.rearm();
        work(&warm)
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
                run_warm(|_| {
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
            run_warm(|_| rayon::current_thread_index().is_some() || rayon::current_num_threads() == 1)
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

    /// Short parallel regions 0.2 ms apart for about 0.3 s, re-arming before each as `fit` does per step.
    fn regions_with_short_pauses(warm: &Warm) {
        for _ in 0..1500 {
            warm.rearm();
            (0..64u64).into_par_iter().for_each(|x| _ = std::hint::black_box(x));
            std::thread::sleep(std::time::Duration::from_micros(200));
        }
    }

    #[test]
    #[cfg(target_os = "linux")]
    fn the_workers_spin_through_short_pauses_and_park_after_long_ones_or_the_end() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let ticks_of = |run: &dyn Fn()| {
            let before = pool_ticks(&pool);
            run();
            pool_ticks(&pool) - before
        };
        let busy = ticks_of(&|| pool.install(|| run_warm(regions_with_short_pauses)));
        assert!(busy >= 3, "the other worker used {busy} ticks through 0.3 s of short pauses");

        let pause = std::time::Duration::from_millis(300);
        let paused = ticks_of(&|| pool.install(|| run_warm(|_| std::thread::sleep(pause))));
        assert!(paused <= 2, "the workers used {paused} ticks through one long pause");

        let caught = pool.install(|| {
            std::panic::catch_unwind(|| {
                run_warm(|warm| {
                    regions_with_short_pauses(warm);
                    panic!("stop")
                })
            })
        });
        assert!(caught.is_err());
        let after = ticks_of(&|| std::thread::sleep(pause));
        assert!(after <= 2, "the workers used {after} ticks after the work had ended");
    }

    /// Runs started together from several threads (tests, or methods trained side by side) all finish.
    #[test]
    fn concurrent_runs_all_finish() {
        let pool = std::sync::Arc::new(rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap());
        let (done, finished) = std::sync::mpsc::channel();
        for run in 0..4u64 {
            let (pool, done) = (std::sync::Arc::clone(&pool), done.clone());
            std::thread::spawn(move || {
                let sum: u64 = pool.install(|| {
                    run_warm(|_| {
                        (0..200).map(|_| (0..200_000u64).into_par_iter().map(|x| (x ^ run) % 7).sum::<u64>()).sum()
                    })
                });
                done.send(sum).unwrap();
            });
        }
        for _ in 0..4 {
            let sum = finished.recv_timeout(std::time::Duration::from_secs(60)).expect("a run did not finish");
            assert!(sum > 200 * 200_000);
        }
    }
}
