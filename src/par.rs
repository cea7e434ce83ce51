//! Nested parallelism that cannot deadlock.
//!
//! parvo runs parallel work inside parallel work: a batch of files runs its
//! jobs on rayon's pool, and each job encodes its levels, builds its bands
//! or traces its frame with rayon again. Rayon itself nests safely: a
//! worker that waits for a parallel loop it started runs that loop's jobs
//! (or steals others) while it waits. What deadlocks is a thread that waits
//! *outside* rayon — sleeping in a polling loop, blocked on a channel —
//! for work that only a pool thread can run: when every pool thread is
//! such a waiter, nobody runs the work. A batch with `--compress` hung
//! exactly so (every worker polled for progress of an encode queued behind
//! it: `tests/regression/compress_batch_hangs.rs`).
//!
//! The rule here: a pool thread never waits outside rayon. The helpers
//! below run the work in place when they are called on a pool thread (the
//! caller takes part in it and progress is reported when it is done), and
//! overlap work with polling or consuming only on a thread that is not in
//! the pool, whose waiting keeps no pool thread from running the work.

use std::sync::mpsc;
use std::time::Duration;

/// True when the calling thread is a worker of a rayon pool.
pub fn on_pool_thread() -> bool {
    rayon::current_thread_index().is_some()
}

/// Runs `work` (which may use rayon) and calls `poll` on this thread about
/// every `every` while it runs, then returns its result. On a rayon pool
/// thread `work` runs in place and `poll` is not called (see the module
/// docs). A panic in `work` is resumed on this thread.
// The file pipeline's, when it encodes blocks.
#[cfg_attr(not(all(feature = "io", feature = "encode")), allow(dead_code))]
pub fn polled<T: Send>(
    work: impl FnOnce() -> T + Send,
    every: Duration,
    mut poll: impl FnMut(),
) -> T {
    if on_pool_thread() {
        return work();
    }
    let (tx, rx) = mpsc::channel::<()>();
    std::thread::scope(|scope| {
        let worker = scope.spawn(move || {
            let r = work();
            // The receiver only goes away if this thread's caller panicked.
            let _ = tx.send(());
            r
        });
        // Until the worker is done (or panicked: the sender is dropped).
        while let Err(mpsc::RecvTimeoutError::Timeout) = rx.recv_timeout(every) {
            poll();
        }
        match worker.join() {
            Ok(r) => r,
            Err(p) => std::panic::resume_unwind(p),
        }
    })
}

/// Produces one item per element of `inputs` (each production may use
/// rayon) and hands the items to `consume` in order on this thread. Off
/// the pool, production runs on a thread of its own up to `ahead` items
/// ahead of the consumer, so the two overlap; on a pool thread each item
/// is produced in place, then consumed (see the module docs). Stops at
/// the first error of `consume`.
pub fn produce_consume<I: Sync, T: Send, E>(
    inputs: &[I],
    ahead: usize,
    produce: impl Fn(usize, &I) -> T + Sync,
    mut consume: impl FnMut(usize, T) -> Result<(), E>,
) -> Result<(), E> {
    if on_pool_thread() {
        for (i, x) in inputs.iter().enumerate() {
            consume(i, produce(i, x))?;
        }
        return Ok(());
    }
    let (tx, rx) = mpsc::sync_channel::<(usize, T)>(ahead.max(1));
    std::thread::scope(|scope| {
        let produce = &produce;
        let producer = scope.spawn(move || {
            for (i, x) in inputs.iter().enumerate() {
                // The consumer stopped early (an error): stop producing.
                if tx.send((i, produce(i, x))).is_err() {
                    return;
                }
            }
        });
        let mut result = Ok(());
        for (i, item) in rx.iter() {
            if let Err(e) = consume(i, item) {
                result = Err(e);
                break;
            }
        }
        // Dropping the receiver (end of this scope's borrow) lets a
        // producer blocked on a full channel return.
        drop(rx);
        if let Err(p) = producer.join() {
            std::panic::resume_unwind(p);
        }
        result
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// Every pool thread calls the helpers at once, each with parallel
    /// work inside: this deadlocked with a sleeping poll loop.
    #[test]
    fn helpers_nested_on_every_pool_thread_finish() {
        for threads in 1..=3 {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let sums: Vec<u64> = pool.install(|| {
                (0..threads * 3)
                    .into_par_iter()
                    .map(|j| {
                        let a: u64 = polled(
                            || (0..10_000u64).into_par_iter().map(|x| x + j as u64).sum(),
                            Duration::from_millis(1),
                            || {},
                        );
                        let mut b = 0u64;
                        produce_consume(
                            &[1u64, 2, 3],
                            1,
                            |_, &k| (0..1000u64).into_par_iter().map(|x| x * k).sum::<u64>(),
                            |_, s| {
                                b += s;
                                Ok::<(), ()>(())
                            },
                        )
                        .unwrap();
                        a + b
                    })
                    .collect()
            });
            for (j, s) in sums.iter().enumerate() {
                let a: u64 = (0..10_000u64).map(|x| x + j as u64).sum();
                let b: u64 = 6 * (0..1000u64).sum::<u64>();
                assert_eq!(*s, a + b);
            }
        }
    }

    #[test]
    fn polled_off_the_pool_polls_while_working() {
        // The work finishes only once it has seen three polls (or gives
        // up after 10 s and returns 0).
        let polls = AtomicUsize::new(0);
        let r = polled(
            || {
                let t = std::time::Instant::now();
                while polls.load(Ordering::Relaxed) < 3 {
                    if t.elapsed() > Duration::from_secs(10) {
                        return 0;
                    }
                    std::thread::sleep(Duration::from_millis(1));
                }
                7
            },
            Duration::from_millis(2),
            || {
                polls.fetch_add(1, Ordering::Relaxed);
            },
        );
        assert_eq!(r, 7);
    }

    #[test]
    fn produce_consume_stops_at_the_first_error_in_order() {
        let mut seen = Vec::new();
        let r = produce_consume(
            &[0, 1, 2, 3, 4, 5],
            2,
            |i, &x| i * 10 + x,
            |i, v| {
                seen.push(v);
                if i == 2 { Err(i) } else { Ok(()) }
            },
        );
        assert_eq!(r, Err(2));
        assert_eq!(seen, vec![0, 11, 22]);
    }
}
