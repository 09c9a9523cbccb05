//! Computations of 10–500 ms (a search, a plan) off the event loop, pre-empted by newer requests.
//!
//! [`OffLoop::start`] runs a job on tokio's blocking pool with a [`CancelToken`] the algorithm
//! checks now and then; starting a newer job cancels the running one, and a cancelled (stale)
//! job's result is discarded, never delivered. One thread at most: the newer job waits until
//! the cancelled one has returned, and a still newer one replaces it. [`OffLoop::result`] is cancel-safe, so it sits in
//! the node's `select!` beside the ticker and the subscriptions, which keep being served while
//! the search runs. [`ServiceThreads`] answers a service's requests on threads of its own,
//! several at once up to a limit, each woken by its request and answering it itself.
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

use futures::future::Either;
use std::future::Future;
use std::panic::AssertUnwindSafe;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
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

/// The places of a [`ServiceThreads`]: how many requests may be computed at once. A request
/// that finds none free is answered at once (BUSY) by the thread that took it.
#[derive(Debug, Clone)]
pub struct Places {
    limit: usize,
    taken: Arc<AtomicUsize>,
}

/// A place taken: free again when dropped (before the reply goes out, so that a client that
/// calls again as soon as it is answered finds its own place free).
#[derive(Debug)]
pub struct Place(Arc<AtomicUsize>);

impl Drop for Place {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::AcqRel);
    }
}

impl Places {
    /// `limit` places, none taken.
    pub fn new(limit: usize) -> Self {
        Places {
            limit,
            taken: Arc::new(AtomicUsize::new(0)),
        }
    }

    /// A free place, or the number of places taken (all of them).
    pub fn take(&self) -> Result<Place, usize> {
        self.taken.fetch_update(Ordering::AcqRel, Ordering::Acquire, |n| {
            (n < self.limit).then_some(n + 1)
        })?;
        Ok(Place(Arc::clone(&self.taken)))
    }

    /// Places taken now.
    pub fn taken(&self) -> usize {
        self.taken.load(Ordering::Acquire)
    }
}

/// What the threads of a [`ServiceThreads`] share.
struct Served {
    /// Held by the thread waiting for the next request (the leader); the others wait here for
    /// their turn.
    leader: Mutex<()>,
    stop: AtomicBool,
    /// Wakes the leader out of its wait when the service stops.
    wake: tokio::sync::Notify,
    places: Places,
    /// Threads not yet ended.
    live: AtomicUsize,
}

/// A service answered on threads of its own (leader/followers), for requests that each take
/// up to a second of one core: one thread waits for the next request and, once it has one,
/// hands the wait to the next free thread and answers the request itself: it checks it, takes
/// a [`Place`] (or answers BUSY at once) and computes and sends the reply. A request thus wakes
/// the thread that answers it directly, with no hand-off through the event loop or a pool, and
/// the reply leaves from the thread that computed it. There is one thread more than places, so
/// a request beyond the limit is taken and turned away as soon as that thread is free (it is
/// busy only while it checks or answers a request of its own), not left waiting for a check.
///
/// The service must not touch the event loop's state: what it reads (configuration, the latest
/// odometry, transforms) the loop shares with it.
pub struct ServiceThreads {
    served: Arc<Served>,
}

impl ServiceThreads {
    /// Starts `places + 1` threads named `name`. Each in turn waits for `receive()` (a future
    /// polled on the thread itself) and gives what it yields to `serve` with the places; a
    /// `serve` that panics loses its request (not answered; the panic is logged) and its thread
    /// goes on.
    pub fn start<R, F>(
        name: &str,
        places: usize,
        receive: impl Fn() -> F + Send + Sync + 'static,
        serve: impl Fn(R, &Places) + Send + Sync + 'static,
    ) -> std::io::Result<Self>
    where
        F: Future<Output = R>,
    {
        let served = Arc::new(Served {
            leader: Mutex::new(()),
            stop: AtomicBool::new(false),
            wake: tokio::sync::Notify::new(),
            places: Places::new(places),
            live: AtomicUsize::new(0),
        });
        let work = Arc::new((receive, serve));
        let threads = ServiceThreads {
            served: Arc::clone(&served),
        };
        for _ in 0..=places {
            served.live.fetch_add(1, Ordering::AcqRel);
            // Counted out when the thread ends, however it ends (a panic too), and only after it
            // has let go of `receive` and `serve` (and what they hold, a server for one).
            let live = Live(Arc::clone(&served));
            let work = Arc::clone(&work);
            let spawned = std::thread::Builder::new().name(name.to_owned()).spawn(move || {
                // Locals drop in reverse order, unwinding too: `work` before `live`.
                let live = live;
                let work = work;
                serve_turns(&live.0, &work.0, &work.1);
            });
            spawned?; // on failure `threads` drops: the ones started stop
        }
        Ok(threads)
    }

    /// The places (how many requests are being computed).
    pub fn places(&self) -> &Places {
        &self.served.places
    }

    /// Threads not ended.
    pub fn threads(&self) -> usize {
        self.served.live.load(Ordering::Acquire)
    }

    /// Takes no more requests: a thread waiting for one ends, the others once they have
    /// answered theirs.
    pub fn stop(&self) {
        self.served.stop.store(true, Ordering::Release);
        // A permit if the leader is not waiting now: it finds the flag before it waits again.
        self.served.wake.notify_one();
    }

    /// Stops taking requests and waits until every thread has ended (a request being answered
    /// is answered first), at most `limit` (checking every millisecond): before a node leaves,
    /// so that no answer is sent by a server whose participant is gone. The threads not ended
    /// then, or 0.
    pub async fn shut_down(&self, limit: Duration) -> usize {
        self.stop();
        let until = tokio::time::Instant::now() + limit;
        loop {
            let left = self.served.live.load(Ordering::Acquire);
            if left == 0 || tokio::time::Instant::now() >= until {
                return left;
            }
            tokio::time::sleep(Duration::from_millis(1)).await;
        }
    }
}

/// A live thread of a [`ServiceThreads`], counted out when dropped.
struct Live(Arc<Served>);

impl Drop for Live {
    fn drop(&mut self) {
        if std::thread::panicking() {
            tracing::error!("a service thread ended with a panic (see above): one thread fewer takes requests");
        }
        self.0.live.fetch_sub(1, Ordering::AcqRel);
    }
}

impl Drop for ServiceThreads {
    /// The threads end as soon as they are free.
    fn drop(&mut self) {
        self.stop();
    }
}

/// One thread's turns: lead (wait for a request), then serve it, until the service stops.
fn serve_turns<R, F: Future<Output = R>>(served: &Served, receive: &impl Fn() -> F, serve: &impl Fn(R, &Places)) {
    loop {
        let request = {
            let _leader = served.leader.lock().unwrap_or_else(PoisonError::into_inner);
            if served.stop.load(Ordering::Acquire) {
                break;
            }
            let next = std::pin::pin!(receive());
            let stopped = std::pin::pin!(served.wake.notified());
            match futures::executor::block_on(futures::future::select(stopped, next)) {
                Either::Left(_) => break,
                Either::Right((request, _)) => request,
            }
        };
        if std::panic::catch_unwind(AssertUnwindSafe(|| serve(request, &served.places))).is_err() {
            tracing::error!("a service request was not answered: its handler panicked (see above)");
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

    /// A request source for [`ServiceThreads`]: a channel whose receiver the leader locks.
    type Source = Arc<tokio::sync::Mutex<mpsc::UnboundedReceiver<u32>>>;

    fn source() -> (mpsc::UnboundedSender<u32>, Source) {
        let (tx, rx) = mpsc::unbounded_channel();
        (tx, Arc::new(tokio::sync::Mutex::new(rx)))
    }

    fn receive(rx: &Source) -> impl Fn() -> std::pin::Pin<Box<dyn Future<Output = Option<u32>> + Send>> + use<> {
        let rx = Arc::clone(rx);
        move || {
            let rx = Arc::clone(&rx);
            Box::pin(async move { rx.lock().await.recv().await })
        }
    }

    /// What a test service answered: the request, whether it was computed (else BUSY), the
    /// places taken as it answered, and its thread's name.
    type Answer = (u32, bool, usize, Option<String>);

    #[tokio::test(flavor = "current_thread")]
    async fn requests_are_computed_up_to_the_places_and_beyond_them_turned_away_at_once() {
        let (requests, rx) = source();
        let (answers_tx, answers) = std::sync::mpsc::channel::<Answer>();
        let (release_tx, release_rx) = std::sync::mpsc::channel::<()>();
        let release = Arc::new(std::sync::Mutex::new(release_rx));
        let service = ServiceThreads::start(
            "test_service",
            2,
            receive(&rx),
            move |request: Option<u32>, places: &Places| {
                let Some(request) = request else { return };
                let name = std::thread::current().name().map(str::to_owned);
                let computed = match places.take() {
                    Ok(place) => {
                        // Held until released, so that both places are taken when the third comes.
                        let _ = release.lock().map(|r| r.recv());
                        drop(place);
                        true
                    }
                    Err(_) => false,
                };
                let _ = answers_tx.send((request, computed, places.taken(), name));
            },
        )
        .expect("threads start");
        assert_eq!(service.threads(), 3, "one thread more than places");
        requests.send(1).expect("open");
        requests.send(2).expect("open");
        // Both places taken before the third request comes.
        let deadline = std::time::Instant::now() + Duration::from_secs(5);
        while service.places().taken() < 2 && std::time::Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(1));
        }
        assert_eq!(service.places().taken(), 2);
        requests.send(3).expect("open");
        let busy = answers
            .recv_timeout(Duration::from_secs(5))
            .expect("the third is answered");
        assert_eq!(
            busy,
            (3, false, 2, Some("test_service".to_owned())),
            "turned away at once, on a service thread"
        );
        release_tx.send(()).expect("a job waits");
        let first = answers.recv_timeout(Duration::from_secs(5)).expect("an answer");
        assert!(first.1 && (first.0 == 1 || first.0 == 2));
        assert_eq!(first.2, 1, "its place was free before it answered");
        requests.send(4).expect("open");
        release_tx.send(()).expect("a job waits");
        release_tx.send(()).expect("a job waits");
        let mut rest: Vec<u32> = (0..2)
            .map(|_| answers.recv_timeout(Duration::from_secs(5)).expect("an answer"))
            .inspect(|a| assert!(a.1, "{a:?} computed"))
            .map(|a| a.0)
            .collect();
        rest.sort();
        assert_eq!(rest, if first.0 == 1 { vec![2, 4] } else { vec![1, 4] });
        assert_eq!(service.shut_down(Duration::from_secs(5)).await, 0);
        assert_eq!(service.places().taken(), 0);
    }

    #[tokio::test(flavor = "current_thread")]
    async fn shutting_down_wakes_the_waiting_thread_and_waits_for_the_request_under_way() {
        let (requests, rx) = source();
        let (answers_tx, answers) = std::sync::mpsc::channel::<u32>();
        let (release_tx, release_rx) = std::sync::mpsc::channel::<()>();
        let release = std::sync::Mutex::new(release_rx);
        let (taken_tx, taken) = std::sync::mpsc::channel::<()>();
        let service = ServiceThreads::start(
            "test_service",
            1,
            receive(&rx),
            move |request: Option<u32>, _: &Places| {
                let Some(request) = request else { return };
                let _ = taken_tx.send(());
                let _ = release.lock().map(|r| r.recv());
                let _ = answers_tx.send(request);
            },
        )
        .expect("threads start");
        requests.send(1).expect("open");
        taken.recv_timeout(Duration::from_secs(5)).expect("request 1 is taken");
        // The other thread now waits for a request; the first holds request 1. Stopped, the
        // waiting one ends; the other stays until it has answered.
        service.stop();
        let deadline = std::time::Instant::now() + Duration::from_secs(5);
        while service.threads() > 1 && std::time::Instant::now() < deadline {
            tokio::time::sleep(Duration::from_millis(1)).await;
        }
        assert_eq!(service.threads(), 1, "the waiting thread ended, request 1 is under way");
        assert_eq!(service.shut_down(Duration::from_millis(20)).await, 1, "still under way");
        requests.send(2).expect("open");
        release_tx.send(()).expect("the job waits");
        assert_eq!(
            service.shut_down(Duration::from_secs(5)).await,
            0,
            "every thread has ended"
        );
        assert_eq!(
            answers.recv_timeout(Duration::from_secs(5)).ok(),
            Some(1),
            "answered before the end"
        );
        assert!(answers.try_recv().is_err(), "no request is taken once stopped");
    }

    #[tokio::test(flavor = "current_thread")]
    async fn a_panicking_handler_loses_its_request_and_its_thread_serves_on() {
        let (requests, rx) = source();
        let (answers_tx, answers) = std::sync::mpsc::channel::<u32>();
        let service = ServiceThreads::start(
            "test_service",
            1,
            receive(&rx),
            move |request: Option<u32>, places: &Places| match request {
                Some(0) => {
                    // It panics holding a place: the place comes back.
                    let _place = places.take();
                    panic!("a failing handler")
                }
                Some(request) => {
                    let _ = answers_tx.send(request);
                }
                None => {}
            },
        )
        .expect("threads start");
        for request in [0, 1, 0, 2, 3] {
            requests.send(request).expect("open");
        }
        let mut got: Vec<u32> = (0..3)
            .map(|_| answers.recv_timeout(Duration::from_secs(5)).expect("an answer"))
            .collect();
        got.sort();
        assert_eq!(got, vec![1, 2, 3]);
        assert_eq!(service.threads(), 2, "both threads still serve");
        assert_eq!(service.shut_down(Duration::from_secs(5)).await, 0);
        assert_eq!(service.places().taken(), 0, "the panicking handler's place came back");
    }
}
