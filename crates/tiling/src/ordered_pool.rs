//! Running numbered jobs on a thread pool and handing their results on in number order,
//! with a bounded number of results waiting: the engine's bridge between parallel tiles
//! and the sequential writer.

use std::collections::BTreeMap;
use std::sync::mpsc;
use std::sync::{Condvar, Mutex, PoisonError};

use rayon::iter::{ParallelBridge, ParallelIterator};
use rayon::ThreadPool;

/// Runs `work(state, i)` for `i in 0..count` on `pool` and calls `consume(i, result)` on
/// the calling thread in order `0, 1, 2, ...`.
///
/// Jobs are started in number order, each pool thread taking the next. `state` is made by
/// `init` for each of rayon's `map_init` groups, at most one more than the pool's threads
/// (an unused one may be made and dropped), and is used by one thread at a time: it may
/// hold things that must not be shared between threads (make it cheap and open resources
/// lazily on first use). Job `i` starts only once results `0..i - ahead` have been
/// consumed, so at most `ahead` jobs are running or waiting to be consumed: memory is
/// bounded by `ahead` results whatever `count` is, and a slow job holds back the others
/// instead of letting results pile up.
///
/// When `consume` returns an error, no further job starts, running jobs finish and are
/// dropped, and the error is returned.
///
/// # Determinism
/// `consume` sees the same sequence whatever the pool's size or the jobs' timing.
///
/// # Panics
/// A panic in `init` or `work` is passed on to the caller (after the other threads stop).
pub(crate) fn run_ordered<S, T, E>(
    pool: &ThreadPool,
    count: usize,
    ahead: usize,
    init: impl Fn() -> S + Sync + Send,
    work: impl Fn(&mut S, usize) -> T + Sync + Send,
    consume: &mut dyn FnMut(usize, T) -> Result<(), E>,
) -> Result<(), E>
where
    T: Send,
{
    let gate = Gate::new(ahead.max(1));
    let (tx, rx) = mpsc::channel::<(usize, T)>();
    std::thread::scope(|scope| {
        let gate = &gate;
        let (init, work) = (&init, &work);
        let workers = scope.spawn(move || {
            pool.install(|| {
                (0..count)
                    .map_while(|i| gate.admit(i).then_some(i))
                    .par_bridge()
                    .map_init(
                        || {
                            let _cancel = CancelOnPanic(gate);
                            init()
                        },
                        |state, i| {
                            // A panicking job must not leave the others waiting at the gate
                            // for a result that never comes.
                            let _cancel = CancelOnPanic(gate);
                            (i, work(state, i))
                        },
                    )
                    .try_for_each(|item| tx.send(item).map_err(|_| ()))
            })
        });
        let outcome = {
            // Cancels on every way out (error or panic in `consume`): the workers stop.
            let _cancel = CancelOnDrop(gate);
            consume_in_order(count, &rx, gate, consume)
        };
        if let Err(panic) = workers.join() {
            std::panic::resume_unwind(panic);
        }
        outcome
    })
}

/// Receives results and consumes them in order until all `count` are consumed, `consume`
/// fails, or the workers stop (only by a panic, which the caller passes on).
fn consume_in_order<T, E>(
    count: usize,
    rx: &mpsc::Receiver<(usize, T)>,
    gate: &Gate,
    consume: &mut dyn FnMut(usize, T) -> Result<(), E>,
) -> Result<(), E> {
    let mut pending: BTreeMap<usize, T> = BTreeMap::new();
    let mut next = 0;
    while next < count {
        let Ok((i, result)) = rx.recv() else {
            break;
        };
        pending.insert(i, result);
        while let Some(result) = pending.remove(&next) {
            consume(next, result)?;
            next += 1;
            gate.consumed(next);
        }
    }
    Ok(())
}

/// Lets job `i` start only when fewer than `ahead` jobs before it are unconsumed.
struct Gate {
    state: Mutex<GateState>,
    changed: Condvar,
    ahead: usize,
}

struct GateState {
    consumed: usize,
    cancelled: bool,
}

impl Gate {
    fn new(ahead: usize) -> Gate {
        Gate {
            state: Mutex::new(GateState {
                consumed: 0,
                cancelled: false,
            }),
            changed: Condvar::new(),
            ahead,
        }
    }

    /// Waits until job `i` may start; `false` when the run was cancelled.
    fn admit(&self, i: usize) -> bool {
        let mut state = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        while !state.cancelled && i >= state.consumed + self.ahead {
            state = self
                .changed
                .wait(state)
                .unwrap_or_else(PoisonError::into_inner);
        }
        !state.cancelled
    }

    fn consumed(&self, consumed: usize) {
        let mut state = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        state.consumed = consumed;
        self.changed.notify_all();
    }

    fn cancel(&self) {
        let mut state = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        state.cancelled = true;
        self.changed.notify_all();
    }
}

/// Cancels the gate when dropped during a panic.
struct CancelOnPanic<'a>(&'a Gate);

impl Drop for CancelOnPanic<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.cancel();
        }
    }
}

/// Cancels the gate when dropped.
struct CancelOnDrop<'a>(&'a Gate);

impl Drop for CancelOnDrop<'_> {
    fn drop(&mut self) {
        self.0.cancel();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::time::Duration;

    fn pool(threads: usize) -> ThreadPool {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
    }

    #[test]
    fn results_come_in_order_whatever_the_timing() {
        for threads in [1, 2, 4] {
            let mut seen = Vec::new();
            let result: Result<(), ()> = run_ordered(
                &pool(threads),
                40,
                5,
                || (),
                |_, i| {
                    // Later jobs finish first.
                    std::thread::sleep(Duration::from_micros(((40 - i) * 50) as u64));
                    i * i
                },
                &mut |i, r| {
                    seen.push((i, r));
                    Ok(())
                },
            );
            assert!(result.is_ok());
            assert_eq!(seen, (0..40).map(|i| (i, i * i)).collect::<Vec<_>>());
        }
    }

    #[test]
    fn no_job_runs_more_than_ahead_of_the_consumer() {
        let started = AtomicUsize::new(0);
        let ahead = 3;
        let result: Result<(), ()> = run_ordered(
            &pool(4),
            30,
            ahead,
            || (),
            |_, i| {
                started.fetch_max(i + 1, Ordering::SeqCst);
                i
            },
            &mut |i, _| {
                // Jobs started so far: at most `ahead` beyond the ones consumed (i of them).
                assert!(started.load(Ordering::SeqCst) <= i + ahead);
                std::thread::sleep(Duration::from_micros(200));
                Ok(())
            },
        );
        assert!(result.is_ok());
    }

    #[test]
    fn states_in_use_are_one_per_thread() {
        let used = AtomicUsize::new(0);
        let result: Result<(), ()> = run_ordered(
            &pool(2),
            100,
            8,
            || None,
            |state: &mut Option<()>, _| {
                if state.is_none() {
                    used.fetch_add(1, Ordering::SeqCst);
                    *state = Some(());
                }
            },
            &mut |_, _| Ok(()),
        );
        assert!(result.is_ok());
        assert!((1..=2).contains(&used.load(Ordering::SeqCst)));
    }

    #[test]
    fn an_error_stops_the_run() {
        let ran = AtomicUsize::new(0);
        let mut consumed = Vec::new();
        let result = run_ordered(
            &pool(2),
            1000,
            4,
            || (),
            |_, i| {
                ran.fetch_add(1, Ordering::SeqCst);
                i
            },
            &mut |i, _| {
                consumed.push(i);
                if i == 10 {
                    Err("stop")
                } else {
                    Ok(())
                }
            },
        );
        assert_eq!(result, Err("stop"));
        assert_eq!(consumed, (0..=10).collect::<Vec<_>>());
        assert!(ran.load(Ordering::SeqCst) <= 11 + 4);
    }

    #[test]
    fn zero_jobs() {
        let result: Result<(), ()> = run_ordered(&pool(2), 0, 4, || (), |_, i| i, &mut |_, _| {
            panic!("no job")
        });
        assert!(result.is_ok());
    }

    #[test]
    #[should_panic(expected = "job 7 failed")]
    fn a_panicking_job_is_passed_on() {
        let _: Result<(), ()> = run_ordered(
            &pool(2),
            20,
            4,
            || (),
            |_, i| assert!(i != 7, "job 7 failed"),
            &mut |_, _| Ok(()),
        );
    }
}
