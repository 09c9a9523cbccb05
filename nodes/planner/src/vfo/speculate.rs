//! Work taken in a fixed order and done ahead on other threads.
//!
//! Algorithm 2's branches form a tree that is only known as it is explored, and its caps are
//! checked in the serial depth-first order. A caller (the *committer*) walks that order and
//! asks for each item's result with [`Speculation::take`]; items wait in a queue ordered by
//! their key (the serial order), and helper threads take the earliest queued item, work it and
//! queue what it yields. The committer works the earliest queued item itself while the one it
//! needs is not done. Whatever the number of threads, the committer sees the same results in
//! the same order: every result is a function of its item alone. Work done ahead of a cap is
//! thrown away.
//!
//! `std::thread::scope`, `Mutex` and `Condvar` are enough: the tasks are whole virtual robots,
//! coarse enough that one lock per task costs nothing measurable, and the queue must hand out
//! the *earliest* item, which a work-stealing pool does not.

use std::any::Any;
use std::collections::{BinaryHeap, HashMap};
use std::hash::Hash;
use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, Ordering as AtomicOrdering};
use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::Scope;

/// An item of work with its place in the order.
pub(crate) trait Keyed {
    /// Its place: smaller keys are taken first.
    type Key: Ord + Hash + Clone + Send;
    /// The item's key.
    fn key(&self) -> &Self::Key;
}

/// A queued item, ordered so that the heap's top is the smallest key.
struct Queued<W>(W);

impl<W: Keyed> PartialEq for Queued<W> {
    fn eq(&self, other: &Self) -> bool {
        self.0.key() == other.0.key()
    }
}

impl<W: Keyed> Eq for Queued<W> {}

impl<W: Keyed> PartialOrd for Queued<W> {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl<W: Keyed> Ord for Queued<W> {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        other.0.key().cmp(self.0.key())
    }
}

struct State<W: Keyed, R> {
    queue: BinaryHeap<Queued<W>>,
    done: HashMap<W::Key, R>,
    /// Items being worked.
    running: usize,
    /// A helper panicked (its payload, raised again in the caller's thread): its item's result
    /// will never come.
    failed: Option<Box<dyn Any + Send>>,
}

struct Shared<W: Keyed, R> {
    state: Mutex<State<W, R>>,
    changed: Condvar,
    /// The committer has finished: helpers stop (work under way may end early).
    closed: AtomicBool,
}

impl<W: Keyed, R> Shared<W, R> {
    fn lock(&self) -> MutexGuard<'_, State<W, R>> {
        // Nothing panics while holding the lock, so its data is whole even if poisoned.
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn wait<'a>(&self, guard: MutexGuard<'a, State<W, R>>) -> MutexGuard<'a, State<W, R>> {
        self.changed.wait(guard).unwrap_or_else(PoisonError::into_inner)
    }

    /// Files a result and what its work yielded.
    fn file(&self, key: W::Key, result: R, more: Vec<W>) {
        let mut state = self.lock();
        state.running -= 1;
        state.queue.extend(more.into_iter().map(Queued));
        state.done.insert(key, result);
        drop(state);
        self.changed.notify_all();
    }

    fn close(&self) {
        self.closed.store(true, AtomicOrdering::Relaxed);
        drop(self.lock());
        self.changed.notify_all();
    }
}

/// The committer's side: results by key, in the order it asks for them.
pub(crate) struct Speculation<'scope, 'env, W: Keyed, R, F> {
    scope: &'scope Scope<'scope, 'env>,
    shared: &'env Shared<W, R>,
    work: &'env F,
    /// Helper threads still to start.
    helpers: usize,
    /// Results taken so far.
    taken: usize,
}

/// Helpers start at the committer's request for this result (the first being 1): a smaller job
/// is done before a thread would have started (tens of microseconds each).
pub(crate) const HELPERS_AFTER: usize = 8;

impl<'scope, 'env, W, R, F> Speculation<'scope, 'env, W, R, F>
where
    W: Keyed + Send + 'env,
    R: Send + 'env,
    F: Fn(W, &AtomicBool) -> (R, Vec<W>) + Sync,
{
    /// The result for `key`, an item queued or worked already (the first item, or one yielded
    /// by a result taken before). `None` if it can never come: a helper panicked (the panic is
    /// raised again in the caller's thread when [`speculate`] returns) or no such item exists.
    pub(crate) fn take(&mut self, key: &W::Key) -> Option<R> {
        self.taken += 1;
        if self.taken == HELPERS_AFTER {
            for _ in 0..std::mem::take(&mut self.helpers) {
                let (shared, work) = (self.shared, self.work);
                // A thread the system refuses leaves the work to the others.
                if std::thread::Builder::new()
                    .name("vfo-helper".into())
                    .spawn_scoped(self.scope, move || help(shared, work))
                    .is_err()
                {
                    break;
                }
            }
        }
        let mut state = self.shared.lock();
        loop {
            if let Some(result) = state.done.remove(key) {
                return Some(result);
            }
            if state.failed.is_some() {
                return None;
            }
            if let Some(Queued(item)) = state.queue.pop() {
                state.running += 1;
                drop(state);
                let item_key = item.key().clone();
                let (result, more) = (self.work)(item, &self.shared.closed);
                self.shared.file(item_key, result, more);
                state = self.shared.lock();
                continue;
            }
            if state.running == 0 {
                return None;
            }
            state = self.shared.wait(state);
        }
    }
}

/// A helper thread: works the earliest queued item until the committer closes. A panic is
/// kept for the caller's thread, and the committer told not to wait for this thread's result.
fn help<W: Keyed, R, F: Fn(W, &AtomicBool) -> (R, Vec<W>)>(shared: &Shared<W, R>, work: &F) {
    if let Err(payload) = std::panic::catch_unwind(AssertUnwindSafe(|| help_until_closed(shared, work))) {
        shared.lock().failed.get_or_insert(payload);
        shared.changed.notify_all();
    }
}

fn help_until_closed<W: Keyed, R, F: Fn(W, &AtomicBool) -> (R, Vec<W>)>(shared: &Shared<W, R>, work: &F) {
    loop {
        let item = {
            let mut state = shared.lock();
            loop {
                if shared.closed.load(AtomicOrdering::Relaxed) {
                    return;
                }
                if let Some(Queued(item)) = state.queue.pop() {
                    state.running += 1;
                    break item;
                }
                state = shared.wait(state);
            }
        };
        let key = item.key().clone();
        let (result, more) = work(item, &shared.closed);
        shared.file(key, result, more);
    }
}

/// Runs `commit` with a [`Speculation`] seeded with `first`, on up to `threads` threads (the
/// caller's and `threads − 1` helpers, started at the [`HELPERS_AFTER`]th request). `work` gets
/// an item and the flag that says the committer has finished (its result is then thrown away,
/// so it may stop early) and returns its result and the items it yields.
pub(crate) fn speculate<W, R, F, T>(
    threads: usize,
    first: W,
    work: &F,
    commit: impl FnOnce(&mut Speculation<'_, '_, W, R, F>) -> T,
) -> T
where
    W: Keyed + Send,
    R: Send,
    F: Fn(W, &AtomicBool) -> (R, Vec<W>) + Sync,
{
    let shared = Shared {
        state: Mutex::new(State {
            queue: BinaryHeap::from([Queued(first)]),
            done: HashMap::new(),
            running: 0,
            failed: None,
        }),
        changed: Condvar::new(),
        closed: AtomicBool::new(false),
    };
    let out = std::thread::scope(|scope| {
        // Closes on the way out, a panic included, so the helpers end and the scope can join.
        struct Close<'a, W: Keyed, R>(&'a Shared<W, R>);
        impl<W: Keyed, R> Drop for Close<'_, W, R> {
            fn drop(&mut self) {
                self.0.close();
            }
        }
        let _close = Close(&shared);
        let mut speculation = Speculation {
            scope,
            shared: &shared,
            work,
            helpers: threads.saturating_sub(1),
            taken: 0,
        };
        commit(&mut speculation)
    });
    if let Some(payload) = shared.lock().failed.take() {
        std::panic::resume_unwind(payload);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A node of a binary tree of depth 12, keyed by its path (0 left, 1 right): its children
    /// are yielded until the depth is reached; its result is its path's sum, with a spin of
    /// work that depends on the path so that the threads finish out of order.
    struct Node(Vec<u8>);

    impl Keyed for Node {
        type Key = Vec<u8>;
        fn key(&self) -> &Vec<u8> {
            &self.0
        }
    }

    fn work(node: Node, _: &AtomicBool) -> (u64, Vec<Node>) {
        let spin = node
            .0
            .iter()
            .fold(7u64, |h, &b| h.wrapping_mul(31).wrapping_add(u64::from(b)))
            % 2000;
        let mut x = 0u64;
        for i in 0..spin {
            x = std::hint::black_box(x.wrapping_add(i));
        }
        let _ = x;
        let sum = node.0.iter().map(|&b| u64::from(b)).sum();
        let children = if node.0.len() < 12 {
            (0..2u8)
                .map(|b| {
                    let mut k = node.0.clone();
                    k.push(b);
                    Node(k)
                })
                .collect()
        } else {
            Vec::new()
        };
        (sum, children)
    }

    /// Depth-first (left first) over the tree, taking each result; stops after `cap` results.
    fn walk(threads: usize, cap: usize) -> Vec<(Vec<u8>, u64)> {
        speculate(threads, Node(Vec::new()), &work, |s| {
            let mut stack = vec![Vec::new()];
            let mut seen = Vec::new();
            while let Some(key) = stack.pop() {
                if seen.len() == cap {
                    break;
                }
                let result = s.take(&key).expect("queued");
                if key.len() < 12 {
                    for b in [1u8, 0] {
                        let mut k = key.clone();
                        k.push(b);
                        stack.push(k);
                    }
                }
                seen.push((key, result));
            }
            seen
        })
    }

    #[test]
    fn every_thread_count_gives_the_serial_order_and_results() {
        let serial = walk(1, usize::MAX);
        assert_eq!(serial.len(), (1 << 13) - 1);
        // The serial order is the keys' order (a prefix first), each result its key's sum.
        assert!(serial.windows(2).all(|w| w[0].0 < w[1].0));
        assert!(serial
            .iter()
            .all(|(k, r)| *r == k.iter().map(|&b| u64::from(b)).sum::<u64>()));
        for threads in [2, 3, 8] {
            assert_eq!(walk(threads, usize::MAX), serial, "{threads} threads");
            // Stopped early: the same prefix, and the helpers end.
            assert_eq!(walk(threads, 100), serial[..100], "{threads} threads, capped");
        }
    }

    #[test]
    fn a_key_never_queued_gives_none_instead_of_waiting() {
        let got = speculate(2, Node(Vec::new()), &work, |s| {
            let _ = s.take(&Vec::new());
            s.take(&vec![9, 9, 9])
        });
        assert_eq!(got, None);
    }

    #[test]
    fn a_helper_s_panic_reaches_the_caller() {
        let boom = |node: Node, closed: &AtomicBool| {
            assert!(
                node.0.len() < 6 || closed.load(AtomicOrdering::Relaxed),
                "helper failed"
            );
            work(node, closed)
        };
        let outcome = std::panic::catch_unwind(|| {
            speculate(2, Node(Vec::new()), &boom, |s| {
                let mut stack = vec![Vec::new()];
                while let Some(key) = stack.pop() {
                    if s.take(&key).is_none() {
                        return;
                    }
                    if key.len() < 12 {
                        for b in [1u8, 0] {
                            let mut k = key.clone();
                            k.push(b);
                            stack.push(k);
                        }
                    }
                }
            })
        });
        let payload = outcome.expect_err("the panic was lost");
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied());
        assert_eq!(message, Some("helper failed"));
    }
}
