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
//! it: `tests/files/regression/compress_batch_hangs.rs`).
//!
//! The rule here: a pool thread never waits outside rayon. The helpers
//! below run the work in place when they are called on a pool thread (the
//! caller takes part in it and progress is reported when it is done), and
//! overlap work with polling or consuming only on a thread that is not in
//! the pool, whose waiting keeps no pool thread from running the work.

use std::collections::VecDeque;
use std::sync::{Condvar, Mutex, MutexGuard, mpsc};
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

/// Produces items `0 .. n` (`produce(i)`, which may use rayon) and hands
/// them to `consume` in order on this thread, at most `ahead` items
/// produced beyond the one being consumed. Off the pool, as many threads
/// as rayon's pool has do the work: this one and the others each take the
/// next item not yet taken and produce it, and this one consumes the
/// items in order, producing only while the next one to consume is not
/// ready. Production and consumption overlap; no thread waits for the
/// slowest item of a batch; and there are no more threads than cores
/// (with one more, a consumer that must keep up gets a third of each
/// core's time instead of the half it needs). On a pool thread each item
/// is produced in place, then consumed (see the module docs). Stops at
/// the first error of `consume`; a panic in `produce` is resumed on this
/// thread.
pub fn produce_consume<T: Send, E>(
    n: usize,
    ahead: usize,
    produce: impl Fn(usize) -> T + Sync,
    consume: impl FnMut(usize, T) -> Result<(), E>,
) -> Result<(), E> {
    if on_pool_thread() {
        return threads_produce_consume(1, n, ahead, produce, consume);
    }
    threads_produce_consume(rayon::current_num_threads(), n, ahead, produce, consume)
}

/// [`produce_consume`] off the pool on `threads` threads (this one and
/// `threads - 1` others), or in place on this one for 1.
fn threads_produce_consume<T: Send, E>(
    threads: usize,
    n: usize,
    ahead: usize,
    produce: impl Fn(usize) -> T + Sync,
    mut consume: impl FnMut(usize, T) -> Result<(), E>,
) -> Result<(), E> {
    if threads <= 1 {
        for i in 0..n {
            consume(i, produce(i))?;
        }
        return Ok(());
    }
    let stream = Stream {
        state: Mutex::new(StreamState {
            next: 0,
            consumed: 0,
            ready: VecDeque::new(),
            stop: false,
        }),
        n,
        ahead: ahead.max(1),
        ready: Condvar::new(),
        room: Condvar::new(),
    };
    let others = threads.min(n).saturating_sub(1);
    std::thread::scope(|scope| {
        let (stream, produce) = (&stream, &produce);
        let producers: Vec<_> = (0..others)
            .map(|_| scope.spawn(move || stream.produce_all(produce)))
            .collect();
        let result = {
            // A panic here (in `produce` or `consume`) must release the
            // other threads before the scope waits for them.
            let _guard = StopOnPanic(stream);
            (0..n).try_for_each(|i| match stream.take(produce) {
                Some(item) => consume(i, item),
                None => Ok(()), // A producer panicked: resumed below.
            })
        };
        stream.stop();
        for p in producers {
            if let Err(p) = p.join() {
                std::panic::resume_unwind(p);
            }
        }
        result
    })
}

/// [`produce_consume`]'s items between its threads.
struct Stream<T> {
    state: Mutex<StreamState<T>>,
    n: usize,
    ahead: usize,
    /// Signalled when the next item to consume is ready (or production
    /// stopped).
    ready: Condvar,
    /// Signalled when an item is consumed (or production stopped).
    room: Condvar,
}

struct StreamState<T> {
    /// The next item no thread has taken.
    next: usize,
    /// Items consumed so far.
    consumed: usize,
    /// Items `consumed ..`: produced (`Some`) or not yet.
    ready: VecDeque<Option<T>>,
    /// Set when the consumer stops or a thread panicked.
    stop: bool,
}

/// Sets `stop` when dropped during a panic, so that the other threads
/// stop waiting for an item that will never come.
struct StopOnPanic<'a, T>(&'a Stream<T>);

impl<T> Drop for StopOnPanic<'_, T> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.stop();
        }
    }
}

impl<T> Stream<T> {
    fn lock(&self) -> MutexGuard<'_, StreamState<T>> {
        // Nothing panics while holding the lock: a poisoned lock still
        // holds consistent state.
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn stop(&self) {
        self.lock().stop = true;
        self.ready.notify_all();
        self.room.notify_all();
    }

    /// Take the next item when there is one and it is within `ahead`.
    fn claim(&self, s: &mut StreamState<T>) -> Option<usize> {
        (!s.stop && s.next < self.n && s.next < s.consumed + self.ahead).then(|| {
            s.next += 1;
            s.next - 1
        })
    }

    /// Put produced item `i` in its place.
    fn put(&self, i: usize, item: T) -> MutexGuard<'_, StreamState<T>> {
        let mut s = self.lock();
        let k = i - s.consumed;
        if s.ready.len() <= k {
            s.ready.resize_with(k + 1, || None);
        }
        s.ready[k] = Some(item);
        s
    }

    /// A producing thread: take the next item, produce it, put it in its
    /// place, until every item is taken or production stops.
    fn produce_all(&self, produce: &impl Fn(usize) -> T) {
        let _guard = StopOnPanic(self);
        let mut s = self.lock();
        loop {
            if let Some(i) = self.claim(&mut s) {
                drop(s);
                let item = produce(i);
                s = self.put(i, item);
                if i == s.consumed {
                    self.ready.notify_one();
                }
            } else if s.stop || s.next >= self.n {
                return;
            } else {
                s = self.room.wait(s).unwrap_or_else(|e| e.into_inner());
            }
        }
    }

    /// The consumer: the next item in order, producing items meanwhile
    /// while it is not ready; `None` when production stopped first.
    fn take(&self, produce: &impl Fn(usize) -> T) -> Option<T> {
        let mut s = self.lock();
        loop {
            if let Some(Some(_)) = s.ready.front() {
                let item = s.ready.pop_front().flatten();
                s.consumed += 1;
                drop(s);
                self.room.notify_all();
                return item;
            }
            if let Some(i) = self.claim(&mut s) {
                drop(s);
                let item = produce(i);
                s = self.put(i, item);
            } else if s.stop {
                return None;
            } else {
                s = self.ready.wait(s).unwrap_or_else(|e| e.into_inner());
            }
        }
    }
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
                            3,
                            1,
                            |i| {
                                let k = i as u64 + 1;
                                (0..1000u64).into_par_iter().map(|x| x * k).sum::<u64>()
                            },
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
            6,
            2,
            |i| i * 11,
            |i, v| {
                seen.push(v);
                if i == 2 { Err(i) } else { Ok(()) }
            },
        );
        assert_eq!(r, Err(2));
        assert_eq!(seen, vec![0, 11, 22]);
    }

    /// Every item is produced once and consumed once, in order, never
    /// more than `ahead` beyond the one being consumed, whatever the
    /// threads, counts and production times (pseudo-random, fixed seed).
    #[test]
    fn produce_consume_hands_over_every_item_once_in_order_within_ahead() {
        let mut seed = 0x2545_f491_u64;
        for threads in 1..=4 {
            for n in [0usize, 1, 2, 5, 37] {
                for ahead in [1usize, 2, 16] {
                    let delays: Vec<u64> = (0..n)
                        .map(|_| {
                            seed ^= seed << 13;
                            seed ^= seed >> 7;
                            seed ^= seed << 17;
                            seed % 300
                        })
                        .collect();
                    let produced: Vec<AtomicUsize> = (0..n).map(|_| AtomicUsize::new(0)).collect();
                    let entered = AtomicUsize::new(0);
                    let mut seen = Vec::new();
                    threads_produce_consume(
                        threads,
                        n,
                        ahead,
                        |i| {
                            // Taken within `ahead` of the item being
                            // consumed (the next one may be handed over
                            // and not yet entered).
                            let at = entered.load(Ordering::SeqCst);
                            assert!(i <= at + 1 + ahead, "item {i} taken at {at}, ahead {ahead}");
                            std::thread::sleep(Duration::from_micros(delays[i]));
                            produced[i].fetch_add(1, Ordering::SeqCst);
                            i * 3 + 1
                        },
                        |i, v| {
                            entered.store(i, Ordering::SeqCst);
                            seen.push((i, v));
                            Ok::<(), ()>(())
                        },
                    )
                    .unwrap();
                    let want: Vec<(usize, usize)> = (0..n).map(|i| (i, i * 3 + 1)).collect();
                    assert_eq!(seen, want, "{threads} threads, {n} items, ahead {ahead}");
                    assert!(produced.iter().all(|p| p.load(Ordering::SeqCst) == 1));
                }
            }
        }
    }

    /// A panic in `produce`, on the consuming thread or another, reaches
    /// the caller with its message instead of leaving a thread waiting
    /// (the test gives up after 20 s rather than hang).
    #[test]
    fn produce_consume_resumes_a_panic_of_any_thread() {
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for threads in 1..=3 {
                for bad in [0usize, 1, 4, 9] {
                    let r = std::panic::catch_unwind(|| {
                        threads_produce_consume(
                            threads,
                            10,
                            2,
                            |i| {
                                if i == bad {
                                    panic!("item {i} fails");
                                }
                                std::thread::sleep(Duration::from_micros(50));
                                i
                            },
                            |_, _| Ok::<(), ()>(()),
                        )
                    });
                    let message = r
                        .err()
                        .and_then(|p| p.downcast_ref::<String>().cloned())
                        .unwrap_or_default();
                    let _ = tx.send((threads, bad, message));
                }
            }
        });
        for _ in 0..12 {
            let (threads, bad, message) = rx
                .recv_timeout(Duration::from_secs(20))
                .expect("produce_consume hung after a panic");
            assert_eq!(message, format!("item {bad} fails"), "{threads} threads");
        }
    }
}
