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

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A spinner that has found no work for this long parks its thread as rayon would. A waiting worker can pick
/// a spinner up and run it nested above its own unfinished work (another run's, when runs overlap, as tests
/// do); that work then waits until the spinner's run stops producing work for this long or ends. Every such
/// wait ends, since a spinner's run keeps producing work only until it is done.
const IDLE_LIMIT: Duration = Duration::from_millis(1);

/// The handle `work` gets: [`Warm::rearm`] sends spinners out again after a pause has parked them.
pub struct Warm {
    stop: Arc<AtomicBool>,
    /// Per worker of the pool: whether a spinner of this run is on it. A second copy on a worker returns at
    /// once, so spinners never stack up on one thread.
    spinning: Arc<Vec<AtomicBool>>,
    caller: usize,
    idle_limit: Duration,
}

impl Warm {
    /// Sends a spinner to every other worker that has none (after a pause parked it): call it before each step.
    pub fn rearm(&self) {
        let others_spinning =
            |(index, flag): (usize, &AtomicBool)| index == self.caller || flag.load(Ordering::Acquire);
        if self.spinning.iter().enumerate().all(others_spinning) {
            return;
        }
        let (stop, spinning, caller, idle_limit) =
            (Arc::clone(&self.stop), Arc::clone(&self.spinning), self.caller, self.idle_limit);
        rayon::spawn_broadcast(move |context| {
            // The caller's own copy returns at once: it would run inside a wait of `work`'s.
            let Some(flag) = spinning.get(context.index()).filter(|_| context.index() != caller) else {
                return;
            };
            if flag.swap(true, Ordering::AcqRel) {
                return;
            }
            let mut last_work = Instant::now();
            while !stop.load(Ordering::Acquire) && last_work.elapsed() < idle_limit {
                if rayon::yield_now() == Some(rayon::Yield::Executed) {
                    last_work = Instant::now();
                } else {
                    std::thread::yield_now();
                }
            }
            flag.store(false, Ordering::Release);
        });
    }

    /// How many workers a spinner of this run is on now.
    pub fn spinning_workers(&self) -> usize {
        self.spinning.iter().filter(|f| f.load(Ordering::Acquire)).count()
    }
}

/// Runs `work` on a thread of the current rayon pool (the global one from outside any pool), with the
/// pool's other threads kept awake while work keeps coming (see [`Warm::rearm`]) until it returns. On a pool
/// of one thread it runs `work` where it is.
pub fn run_warm<R: Send>(work: impl FnOnce(&Warm) -> R + Send) -> R {
    run_warm_for(IDLE_LIMIT, work)
}

fn run_warm_for<R: Send>(idle_limit: Duration, work: impl FnOnce(&Warm) -> R + Send) -> R {
    let warm = |caller: usize, threads: usize| Warm {
        stop: Arc::default(),
        spinning: Arc::new((0..threads).map(|_| AtomicBool::new(false)).collect()),
        caller,
        idle_limit,
    };
    if rayon::current_num_threads() <= 1 {
        return work(&warm(0, 0));
    }
    // The scope runs its body on a worker of the pool, so there is always a caller index.
    rayon::scope(|_| {
        let warm = warm(rayon::current_thread_index().unwrap_or(0), rayon::current_num_threads());
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

    /// Polls `done` for up to a second.
    fn within_a_second(done: impl Fn() -> bool) -> bool {
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(1) {
            if done() {
                return true;
            }
            std::thread::sleep(Duration::from_micros(100));
        }
        done()
    }

    #[test]
    fn spinners_park_after_the_idle_limit_and_come_back_when_rearmed() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap();
        pool.install(|| {
            run_warm_for(Duration::from_millis(20), |warm| {
                assert!(within_a_second(|| warm.spinning_workers() == 2), "{} spinning", warm.spinning_workers());
                // Rearming while all spin sends none; nothing stacks on a worker.
                (0..50).for_each(|_| warm.rearm());
                assert!(warm.spinning_workers() <= 2);
                std::thread::sleep(Duration::from_millis(200));
                assert_eq!(warm.spinning_workers(), 0, "spinners outlived a pause ten times their idle limit");
                warm.rearm();
                assert!(within_a_second(|| warm.spinning_workers() == 2), "{} after rearming", warm.spinning_workers());
            })
        });
    }

    #[test]
    fn the_end_of_the_work_stops_its_spinners_also_when_it_panics() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        for panics in [false, true] {
            let (sender, spinners) = std::sync::mpsc::channel();
            let caught = pool.install(|| {
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    // An idle limit far beyond the test: only the end of the work can stop these spinners.
                    run_warm_for(Duration::from_secs(3600), |warm| {
                        assert!(within_a_second(|| warm.spinning_workers() == 1));
                        sender.send(Arc::clone(&warm.spinning)).unwrap();
                        if panics {
                            panic!("stop");
                        }
                    })
                }))
            });
            assert_eq!(caught.is_err(), panics);
            let flags = spinners.recv().unwrap();
            assert!(within_a_second(|| flags.iter().all(|f| !f.load(Ordering::Acquire))), "panics: {panics}");
        }
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
