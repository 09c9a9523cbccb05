//! Computations of 10–500 ms (a search, a plan) off the event loop, pre-empted by newer requests.
//!
//! [`OffLoop::start`] runs a job on tokio's blocking pool with a [`CancelToken`] the algorithm
//! checks now and then; starting a newer job cancels the running one, and a cancelled (stale)
//! job's result is discarded, never delivered. One thread at most: the newer job waits until
//! the cancelled one has returned, and a still newer one replaces it. [`OffLoop::result`] is cancel-safe, so it sits in
//! the node's `select!` beside the ticker and the subscriptions, which keep being served while
//! the search runs. [`ReplyPool`] computes several requests at once, up to a limit, each
//! answered from the thread that computed it.
//!
//! ```
//! # #[tokio::main(flavor = "current_thread")]
//! # async fn main() {
//! use mobil_ros::offloop::OffLoop;
//! let mut search = OffLoop::new();
//! search.start(|cancel| (0..1000u64).take_while(|_| !cancel.is_cancelled()).sum::<u64>());
//! search.start(|_| 7); // pre-empts the first: its sum, if it finishes, is thrown away
//! assert_eq!(search.result().await, 7);
//! # }
//! ```

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::mpsc;

/// Tells a running job it has been pre-empted; the algorithm checks it between steps and
/// returns early (any value: it is discarded).
#[derive(Debug, Clone, Default)]
pub struct CancelToken(Arc<AtomicBool>);

impl CancelToken {
    /// A token not cancelled.
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether the job should stop.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// Asks the job to stop.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

/// A job waiting for the thread of a cancelled one.
type Job<R> = Box<dyn FnOnce(&CancelToken) -> R + Send>;

/// One computation at a time off the event loop; the newest request wins. At most one thread
/// runs: a newer request cancels the running job and waits (pending) until that job has
/// noticed its token and returned; a still newer request replaces the pending one, which then
/// never runs. So requests at any rate cost one running job and one pending, never a pile of
/// stale threads.
pub struct OffLoop<R> {
    generation: u64,
    /// The newest job, wanted (not cancelled), running or pending.
    running: Option<(u64, CancelToken)>,
    /// Whether a thread is running (maybe a cancelled job that has not yet returned).
    busy: bool,
    pending: Option<(u64, CancelToken, Job<R>)>,
    tx: mpsc::UnboundedSender<(u64, Option<R>)>,
    rx: mpsc::UnboundedReceiver<(u64, Option<R>)>,
}

impl<R> std::fmt::Debug for OffLoop<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OffLoop")
            .field("generation", &self.generation)
            .field("running", &self.running)
            .field("busy", &self.busy)
            .field("pending", &self.pending.as_ref().map(|(g, _, _)| *g))
            .finish()
    }
}

impl<R: Send + 'static> Default for OffLoop<R> {
    fn default() -> Self {
        Self::new()
    }
}

impl<R: Send + 'static> OffLoop<R> {
    /// Nothing running.
    pub fn new() -> Self {
        let (tx, rx) = mpsc::unbounded_channel();
        OffLoop {
            generation: 0,
            running: None,
            busy: false,
            pending: None,
            tx,
            rx,
        }
    }

    /// Starts `job` on the blocking pool, cancelling the job still running (whose result will
    /// be discarded). While the cancelled job's thread has not returned, `job` waits as the
    /// pending one and starts from [`OffLoop::result`] when that thread is done. Must be called
    /// inside a tokio runtime.
    pub fn start(&mut self, job: impl FnOnce(&CancelToken) -> R + Send + 'static) {
        self.cancel();
        self.generation += 1;
        let generation = self.generation;
        let token = CancelToken::new();
        self.running = Some((generation, token.clone()));
        if self.busy {
            self.pending = Some((generation, token, Box::new(job)));
        } else {
            self.spawn(generation, token, Box::new(job));
        }
    }

    fn spawn(&mut self, generation: u64, token: CancelToken, job: Job<R>) {
        self.busy = true;
        let tx = self.tx.clone();
        tokio::task::spawn_blocking(move || {
            let result = job(&token);
            let result = (!token.is_cancelled()).then_some(result);
            // The receiver lives as long as the OffLoop; if it is gone nobody waits.
            let _ = tx.send((generation, result));
        });
    }

    /// Cancels the running job, if any (its result will be discarded), and drops a pending one.
    pub fn cancel(&mut self) {
        if let Some((_, token)) = self.running.take() {
            token.cancel();
        }
        self.pending = None;
    }

    /// Whether a job is wanted (started, not cancelled, result not yet taken), running or
    /// pending.
    pub fn is_running(&self) -> bool {
        self.running.is_some()
    }

    /// Threads of the blocking pool in use: 1 while a job (maybe a cancelled one not yet
    /// returned) runs, else 0. For a limit shared with other computations.
    pub fn threads(&self) -> usize {
        usize::from(self.busy)
    }

    /// The result of the newest job, when it is done; pending for ever while nothing runs.
    /// Starts the pending job when the thread before it returns, so it must be polled (it sits
    /// in the node's `select!`). Cancel-safe (for `select!`).
    pub async fn result(&mut self) -> R {
        loop {
            let Some((generation, result)) = self.rx.recv().await else {
                // Unreachable: `self.tx` keeps the channel open.
                std::future::pending::<()>().await;
                continue;
            };
            self.busy = false;
            if let Some((g, token, job)) = self.pending.take() {
                self.spawn(g, token, job);
            }
            if let Some(result) = result
                && self.running.as_ref().is_some_and(|(g, _)| *g == generation)
            {
                self.running = None;
                return result;
            }
        }
    }
}

/// Requests computed and answered on the blocking pool several at once, up to a limit (a
/// service whose requests each take up to a second of one core): each job's answer (the reply
/// sent) runs on the thread that computed it, without a hand-off back to the event loop; beyond
/// the limit a request is turned away at once, for the caller to answer BUSY, so a burst of
/// requests never piles up threads. A job's place is free again before its answer goes out, so
/// a client that calls again as soon as it is answered finds its own place free again.
pub struct ReplyPool {
    limit: usize,
    /// Jobs computing: the places taken.
    running: Arc<AtomicUsize>,
    /// Jobs not yet finished, their answers included.
    in_flight: Arc<AtomicUsize>,
}

/// Takes one from its counter when dropped: a place of a [`ReplyPool`] after the job, before its
/// answer; a job in flight after its answer; either while a panicking job unwinds.
struct Taken(Arc<AtomicUsize>);

impl Drop for Taken {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::AcqRel);
    }
}

impl ReplyPool {
    /// A pool of at most `limit` jobs at once.
    pub fn new(limit: usize) -> Self {
        ReplyPool {
            limit,
            running: Arc::new(AtomicUsize::new(0)),
            in_flight: Arc::new(AtomicUsize::new(0)),
        }
    }

    /// Jobs under way (computing; an answer being sent no longer counts).
    pub fn running(&self) -> usize {
        self.running.load(Ordering::Acquire)
    }

    /// Computes `job` on the blocking pool, then `answer`s with its result on the same thread,
    /// or, with `limit` jobs under way already, refuses with their number (`job` and `answer`
    /// never run). Must be called inside a tokio runtime. A job that panics is not answered.
    pub fn start<R: Send + 'static>(
        &self,
        job: impl FnOnce() -> R + Send + 'static,
        answer: impl FnOnce(R) + Send + 'static,
    ) -> Result<(), usize> {
        self.running.fetch_update(Ordering::AcqRel, Ordering::Acquire, |n| {
            (n < self.limit).then_some(n + 1)
        })?;
        let place = Taken(Arc::clone(&self.running));
        self.in_flight.fetch_add(1, Ordering::AcqRel);
        let flight = Taken(Arc::clone(&self.in_flight));
        tokio::task::spawn_blocking(move || {
            let result = job();
            drop(place);
            answer(result);
            drop(flight);
        });
        Ok(())
    }

    /// Waits until every job has finished, its answer sent, at most `limit` (checking every
    /// millisecond): before a node leaves, so that no answer is sent by a server whose
    /// participant is gone. The jobs not finished then, or 0.
    pub async fn until_idle(&self, limit: Duration) -> usize {
        let until = tokio::time::Instant::now() + limit;
        loop {
            let left = self.in_flight.load(Ordering::Acquire);
            if left == 0 || tokio::time::Instant::now() >= until {
                return left;
            }
            tokio::time::sleep(Duration::from_millis(1)).await;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    /// A search that takes `ms` of real work, checking the token every millisecond; returns its
    /// label, or "cancelled" (which must never be delivered).
    fn search(label: &'static str, ms: u64, saw_cancel: Arc<AtomicBool>) -> impl FnOnce(&CancelToken) -> &'static str {
        move |cancel| {
            let until = Instant::now() + Duration::from_millis(ms);
            while Instant::now() < until {
                if cancel.is_cancelled() {
                    saw_cancel.store(true, Ordering::Relaxed);
                    return "cancelled";
                }
                std::thread::sleep(Duration::from_millis(1));
            }
            label
        }
    }

    // A single-threaded runtime: if a search ran on the event loop, no tick could happen.
    #[tokio::test(flavor = "current_thread")]
    async fn a_newer_request_preempts_and_the_loop_keeps_ticking() {
        let first_cancelled = Arc::new(AtomicBool::new(false));
        let second_cancelled = Arc::new(AtomicBool::new(false));
        let mut off = OffLoop::new();
        let mut tick = tokio::time::interval(Duration::from_millis(10));
        let start = Instant::now();
        off.start(search("first", 2000, first_cancelled.clone()));
        assert!(off.is_running());
        let mut ticks = 0u32;
        let mut restarted = false;
        let result = loop {
            tokio::select! {
                r = off.result() => break r,
                _ = tick.tick() => {
                    ticks += 1;
                    // After 50 ms a newer request comes in.
                    if !restarted && start.elapsed() >= Duration::from_millis(50) {
                        off.start(search("second", 200, second_cancelled.clone()));
                        restarted = true;
                    }
                }
            }
        };
        let elapsed = start.elapsed();
        assert_eq!(result, "second", "the stale result is never delivered");
        assert!(
            first_cancelled.load(Ordering::Relaxed),
            "the first search saw its cancellation"
        );
        assert!(!second_cancelled.load(Ordering::Relaxed));
        assert!(!off.is_running());
        // 50 ms + 200 ms of search; far below the first search's 2 s.
        assert!(
            elapsed >= Duration::from_millis(250) && elapsed < Duration::from_millis(1500),
            "{elapsed:?}"
        );
        // The loop ticked every 10 ms meanwhile: about 25 ticks; at least half of them, allowing
        // for a loaded machine.
        assert!(ticks >= 12, "only {ticks} ticks in {elapsed:?}: the loop was blocked");
    }

    #[tokio::test(flavor = "current_thread")]
    async fn cancel_discards_and_result_then_waits_for_the_next_job() {
        let mut off = OffLoop::new();
        off.start(|_| 1);
        off.cancel();
        assert!(!off.is_running());
        // The cancelled job's 1 may already be in the channel; it must be skipped.
        tokio::time::sleep(Duration::from_millis(20)).await;
        off.start(|_| 2);
        assert_eq!(off.result().await, 2);
        // Nothing running: result() stays pending.
        assert!(tokio::time::timeout(Duration::from_millis(50), off.result())
            .await
            .is_err());
    }

    /// Requests at a high rate keep one thread busy, never more: the first job runs until it
    /// sees its token, the middle ones are replaced while pending and never run, the newest
    /// runs after the first has returned.
    #[tokio::test(flavor = "multi_thread", worker_threads = 2)]
    async fn requests_at_a_high_rate_run_one_job_at_a_time() {
        use std::sync::atomic::AtomicUsize;
        let (now, most, ran) = (
            Arc::new(AtomicUsize::new(0)),
            Arc::new(AtomicUsize::new(0)),
            Arc::new(std::sync::Mutex::new(Vec::new())),
        );
        let job = |label: u32, now: Arc<AtomicUsize>, most: Arc<AtomicUsize>, ran: Arc<std::sync::Mutex<Vec<u32>>>| {
            move |cancel: &CancelToken| {
                let n = now.fetch_add(1, Ordering::SeqCst) + 1;
                most.fetch_max(n, Ordering::SeqCst);
                if let Ok(mut r) = ran.lock() {
                    r.push(label);
                }
                // 30 ms of work, checking the token every millisecond.
                for _ in 0..30 {
                    if cancel.is_cancelled() {
                        break;
                    }
                    std::thread::sleep(Duration::from_millis(1));
                }
                now.fetch_sub(1, Ordering::SeqCst);
                label
            }
        };
        let mut off = OffLoop::new();
        off.start(job(0, now.clone(), most.clone(), ran.clone()));
        assert_eq!(off.threads(), 1);
        for label in 1..=10 {
            off.start(job(label, now.clone(), most.clone(), ran.clone()));
        }
        assert!(off.is_running());
        assert_eq!(off.threads(), 1, "the cancelled first job still holds the one thread");
        let result = tokio::time::timeout(Duration::from_secs(5), off.result()).await;
        assert_eq!(result.ok(), Some(10));
        assert_eq!(most.load(Ordering::SeqCst), 1, "never two jobs at once");
        assert_eq!(
            ran.lock().map(|r| r.clone()).ok(),
            Some(vec![0, 10]),
            "jobs 1–9 never ran"
        );
        assert_eq!((off.threads(), off.is_running()), (0, false));
    }

    #[tokio::test(flavor = "current_thread")]
    async fn a_pool_runs_up_to_its_limit_and_turns_the_next_away() {
        let (release_tx, release_rx) = std::sync::mpsc::channel::<()>();
        let release = Arc::new(std::sync::Mutex::new(release_rx));
        let (answers_tx, answers) = std::sync::mpsc::channel::<(i32, usize)>();
        let pool = ReplyPool::new(2);
        let running = Arc::clone(&pool.running);
        let start = |key: i32| {
            let (release, answers_tx, running) = (release.clone(), answers_tx.clone(), Arc::clone(&running));
            let job = move || {
                // Held until released, so both are under way when the third comes.
                let _ = release.lock().map(|r| r.recv());
                key * 10
            };
            // Each answer notes how many jobs were under way as it went out.
            let answer = move |reply| {
                let _ = answers_tx.send((reply, running.load(Ordering::Acquire)));
            };
            pool.start(job, answer)
        };
        assert!(start(1).is_ok() && start(2).is_ok());
        assert_eq!(start(3).unwrap_err(), 2, "the third is turned away");
        release_tx.send(()).expect("job waits");
        let (first, under_way) = answers.recv_timeout(Duration::from_secs(5)).expect("an answer");
        assert!(first == 10 || first == 20);
        assert_eq!(under_way, 1, "its place was free before it answered");
        assert_eq!(pool.running(), 1);
        assert!(start(3).is_ok(), "a place is free again");
        release_tx.send(()).expect("job waits");
        release_tx.send(()).expect("job waits");
        let mut rest: Vec<i32> = (0..2)
            .map(|_| answers.recv_timeout(Duration::from_secs(5)).expect("an answer").0)
            .collect();
        rest.sort();
        assert!(rest.contains(&30) && !rest.contains(&first));
        assert_eq!(pool.until_idle(Duration::from_secs(5)).await, 0);
        assert_eq!(pool.running(), 0);
    }

    #[tokio::test(flavor = "current_thread")]
    async fn idle_only_once_the_answer_is_sent() {
        let pool = ReplyPool::new(1);
        let (release_tx, release_rx) = std::sync::mpsc::channel::<()>();
        // The answer waits, as a reply's write may.
        assert!(pool
            .start(
                || 1,
                move |_| {
                    let _ = release_rx.recv();
                }
            )
            .is_ok());
        assert_eq!(
            pool.until_idle(Duration::from_millis(50)).await,
            1,
            "the answer is still going out"
        );
        assert_eq!(pool.running(), 0, "its place is free meanwhile");
        release_tx.send(()).expect("the answer waits");
        assert_eq!(pool.until_idle(Duration::from_secs(5)).await, 0);
    }

    #[tokio::test(flavor = "current_thread")]
    async fn a_panicking_job_frees_its_place_and_is_not_answered() {
        let pool = ReplyPool::new(1);
        let answered = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&answered);
        assert!(pool
            .start(
                || -> i32 { panic!("a failing job") },
                move |_| flag.store(true, Ordering::SeqCst)
            )
            .is_ok());
        assert_eq!(pool.until_idle(Duration::from_secs(5)).await, 0, "the place comes back");
        assert!(pool.start(|| 1, |_| ()).is_ok());
        assert!(!answered.load(Ordering::SeqCst));
    }
}
