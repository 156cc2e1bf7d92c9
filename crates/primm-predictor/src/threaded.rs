//! A [`DisplacementPredictor`] that runs another predictor on a dedicated inference thread.
//!
//! The tracker calls [`submit`](DisplacementPredictor::submit) before its CV/CA/CT predictions
//! and [`collect`](DisplacementPredictor::collect) after them, so the learned prediction runs
//! while the tracking thread does its own work. The inference thread (named
//! [`INFERENCE_THREAD_NAME`]) owns the wrapped predictor, e.g. an
//! [`OnnxPredictor`](crate::onnx::OnnxPredictor) with its tract state; every allocation tract makes
//! per run happens there.
//!
//! # Hand-over
//!
//! Two batch buffers, each holding [`MAX_TRACKS`] requests and displacements, are allocated
//! when the predictor is built. They travel between the threads through two bounded channels of
//! capacity 2 (one per direction), so the tracking thread never allocates: `submit` copies the
//! requests into a free buffer, stamps it with a new sequence number and sends it; `collect`
//! waits for that buffer to come back, at most until the deadline (measured from `submit`).
//!
//! * A buffer that comes back with an older sequence number (a batch that missed its deadline)
//!   is stale: its results are discarded and the buffer is reused.
//! * A missed deadline, more requests than a buffer holds, or no free buffer (both still with a
//!   slow inference thread) give `None` for every track of that frame only: the PR mode sits the
//!   frame out and the next frame starts afresh.
//!
//! # Faults of the wrapped predictor
//!
//! * **Panic.** The inference thread catches it, returns the batch without results and stops:
//!   after an unwinding panic the predictor's state is unknown, and a predictor that answers
//!   wrongly is worse than none. Every later frame goes without learned displacements, counted
//!   in [`ThreadedPredictorStats::frames_without_inference_thread`]; the panic is counted in
//!   [`ThreadedPredictorStats::inference_panics`] and logged. The process carries on.
//! * **Hang.** A batch that stays with the inference thread for the hang threshold or longer
//!   ([`DEFAULT_HANG_THRESHOLD`], [`set_hang_threshold`](ThreadedPredictor::set_hang_threshold))
//!   marks the thread hung: counted once per episode in
//!   [`ThreadedPredictorStats::inference_hangs_detected`], logged, and visible in
//!   [`is_inference_thread_hung`](ThreadedPredictor::is_inference_thread_hung). Meanwhile frames
//!   go without learned displacements (deadline misses, then no free buffer) and never wait
//!   longer than the deadline. Should the batch come back after all, the episode ends
//!   ([`ThreadedPredictorStats::inference_hang_recoveries`]) and the next frames use the model
//!   again.
//! * **Shutdown.** Dropping the predictor (or [`shutdown`](ThreadedPredictor::shutdown)) closes
//!   the work channel and waits at most the shutdown wait ([`DEFAULT_SHUTDOWN_WAIT`],
//!   [`set_shutdown_wait`](ThreadedPredictor::set_shutdown_wait)) for the thread to finish. A
//!   thread still busy then is detached and logged: it ends by itself if its batch ever
//!   finishes, and with the process otherwise; the wrapped predictor is then never dropped.
//! * Wrong answers (NaN, infinite, absurd displacements) pass through unchanged: the tracker
//!   checks every displacement (`primm_core::displacement_check`).
//!
//! This is the one part of primm that reads a clock (for the deadline): with it, whether a
//! frame gets its learned displacements depends on timing. Offline tracking and evaluation use
//! the synchronous predictor instead.

use primm_core::limits::MAX_TRACKS;
use primm_core::predictor::{AnswerDependence, Displacement, DisplacementPredictor, PredictionRequest};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{
    sync_channel, Receiver, RecvError, RecvTimeoutError, SyncSender, TryRecvError, TrySendError,
};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Name of the inference thread.
pub const INFERENCE_THREAD_NAME: &str = "primm-pr-inference";

/// Batch buffers shared by the two threads.
const BUFFERS: usize = 2;

/// How long [`ThreadedPredictor::warm_up`] waits on the empty return channel: long enough
/// that the wait really blocks (it returns at once only if the thread was descheduled for
/// longer than this between starting the wait and checking its deadline).
const WAIT_PRIMING: Duration = Duration::from_millis(50);

/// Sequence number of the warm-up batch.
const WARM_UP_SEQUENCE: u64 = u64::MAX;

/// How long a batch may stay with the inference thread before the thread is reported hung,
/// unless [`ThreadedPredictor::set_hang_threshold`] says otherwise. Also the longest wait for
/// the warm-up round trip in [`ThreadedPredictor::new`].
pub const DEFAULT_HANG_THRESHOLD: Duration = Duration::from_secs(1);

/// How long dropping a [`ThreadedPredictor`] waits for its inference thread to finish before
/// detaching it, unless [`ThreadedPredictor::set_shutdown_wait`] says otherwise.
pub const DEFAULT_SHUTDOWN_WAIT: Duration = Duration::from_secs(1);

/// One batch in flight: requests in, displacements out.
struct Batch {
    sequence: u64,
    len: usize,
    requests: Box<[PredictionRequest]>,
    displacements: Box<[Option<Displacement>]>,
    /// Whether the inference completed (a panic leaves every displacement `None`).
    completed: bool,
    /// When the tracking thread handed the batch over, and when the inference thread began and
    /// finished it.
    submitted: Option<Instant>,
    started: Option<Instant>,
    finished: Option<Instant>,
}

/// When one batch passed each point of its round trip ([`ThreadedPredictor::last_timeline`]):
/// for a time line of a frame across the tracking and inference threads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BatchTimeline {
    /// The tracking thread handed the batch over (`submit`).
    pub submitted: Instant,
    /// The inference thread took it up (woken, or already awake).
    pub started: Instant,
    /// The inference thread finished it and sent it back.
    pub finished: Instant,
    /// The tracking thread had it back (`collect`).
    pub collected: Instant,
    /// Requests in the batch.
    pub requests: usize,
}

impl Batch {
    fn new(capacity: usize) -> Box<Self> {
        Box::new(Batch {
            sequence: 0,
            len: 0,
            requests: vec![PredictionRequest::default(); capacity].into_boxed_slice(),
            displacements: vec![None; capacity].into_boxed_slice(),
            completed: false,
            submitted: None,
            started: None,
            finished: None,
        })
    }
}

/// Counters of a [`ThreadedPredictor`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct ThreadedPredictorStats {
    /// Batches handed to the inference thread.
    pub batches_submitted: u64,
    /// Batches whose results arrived before their deadline.
    pub batches_on_time: u64,
    /// Frames whose batch missed its deadline.
    pub deadline_misses: u64,
    /// Late batches whose results were thrown away when they came back.
    pub stale_batches_discarded: u64,
    /// Frames not submitted because both buffers were still with the inference thread.
    pub frames_without_free_buffer: u64,
    /// Frames not submitted because they had more requests than a buffer holds.
    pub frames_too_large: u64,
    /// Batches in which the wrapped predictor panicked (the thread stops after the first).
    pub inference_panics: u64,
    /// Frames not submitted because the inference thread is gone (after a panic).
    pub frames_without_inference_thread: u64,
    /// Times the inference thread was found hung: a batch with it for at least the hang
    /// threshold (one count per episode).
    pub inference_hangs_detected: u64,
    /// Hang episodes that ended because the batch came back after all.
    pub inference_hang_recoveries: u64,
}

/// How [`ThreadedPredictor::shutdown`] ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShutdownOutcome {
    /// The inference thread finished within the shutdown wait and was joined.
    Joined,
    /// The inference thread was still busy after the shutdown wait and was detached.
    Detached,
    /// There was no inference thread left to stop (already shut down).
    AlreadyStopped,
}

/// Runs a [`DisplacementPredictor`] on a dedicated inference thread, with a deadline per frame.
pub struct ThreadedPredictor {
    to_worker: Option<SyncSender<Box<Batch>>>,
    from_worker: Receiver<Box<Batch>>,
    free: [Option<Box<Batch>>; BUFFERS],
    worker: Option<JoinHandle<()>>,
    deadline: Duration,
    capacity: usize,
    /// What the wrapped predictor's answers depend on, asked before it moved to its thread.
    dependence: AnswerDependence,
    /// How long each thread spins on its channel before it parks, ns ([`set_spin`]).
    ///
    /// [`set_spin`]: ThreadedPredictor::set_spin
    spin: Arc<AtomicU64>,
    next_sequence: u64,
    /// The batch of the current frame: its sequence number and deadline.
    awaited: Option<(u64, Instant)>,
    /// Batches with the inference thread: sequence number and when each was handed over.
    in_flight: [Option<(u64, Instant)>; BUFFERS],
    hang_threshold: Duration,
    shutdown_wait: Duration,
    /// Whether a hang episode is going on.
    hung: bool,
    /// Whether the inference thread has stopped (after a panic) or is unreachable.
    thread_gone: bool,
    stats: ThreadedPredictorStats,
    /// The round trip of the latest batch collected on time.
    last_timeline: Option<BatchTimeline>,
}

impl std::fmt::Debug for ThreadedPredictor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ThreadedPredictor")
            .field("deadline", &self.deadline)
            .field("capacity", &self.capacity)
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

impl ThreadedPredictor {
    /// Moves `predictor` onto a new inference thread; `collect` waits at most `deadline` after
    /// `submit`. Buffers hold [`MAX_TRACKS`] requests (the tracker's largest batch).
    ///
    /// One empty batch makes a round trip before this returns, so the channels' per-thread
    /// bookkeeping is set up for the calling thread: a tracker stepped on the thread that built
    /// its predictor allocates nothing from its first frame on.
    pub fn new<P>(predictor: P, deadline: Duration) -> std::io::Result<Self>
    where
        P: DisplacementPredictor + Send + 'static,
    {
        Self::with_capacity(predictor, deadline, MAX_TRACKS)
    }

    /// As [`new`](Self::new) with buffers of `capacity` requests.
    pub fn with_capacity<P>(predictor: P, deadline: Duration, capacity: usize) -> std::io::Result<Self>
    where
        P: DisplacementPredictor + Send + 'static,
    {
        let dependence = predictor.answer_dependence();
        let spin = Arc::new(AtomicU64::new(0));
        let (to_worker, work) = sync_channel::<Box<Batch>>(BUFFERS);
        let (done, from_worker) = sync_channel::<Box<Batch>>(BUFFERS);
        let worker = std::thread::Builder::new().name(INFERENCE_THREAD_NAME.to_string()).spawn({
            let spin = spin.clone();
            move || inference_loop(predictor, work, done, &spin)
        })?;
        let mut threaded = ThreadedPredictor {
            to_worker: Some(to_worker),
            from_worker,
            free: std::array::from_fn(|_| Some(Batch::new(capacity))),
            worker: Some(worker),
            deadline,
            capacity,
            dependence,
            spin,
            next_sequence: 0,
            awaited: None,
            in_flight: [None; BUFFERS],
            hang_threshold: DEFAULT_HANG_THRESHOLD,
            shutdown_wait: DEFAULT_SHUTDOWN_WAIT,
            hung: false,
            thread_gone: false,
            stats: ThreadedPredictorStats::default(),
            last_timeline: None,
        };
        threaded.warm_up();
        Ok(threaded)
    }

    /// One empty round trip (not counted in the statistics), waiting at most
    /// [`DEFAULT_HANG_THRESHOLD`] (a predictor that does not answer even an empty batch leaves
    /// the buffer with its thread, which is then reported hung); then one wait on the empty
    /// return channel.
    ///
    /// The first time a thread blocks on a channel, std allocates (the thread's wait context
    /// and the channel's list of waiters). The round trip blocks only if the answer is not back
    /// yet, which depends on scheduling, so a wait on the empty channel makes sure those
    /// allocations happen here, on the thread that builds the predictor, instead of in the
    /// first `collect` that has to wait. A late warm-up answer arriving meanwhile is reclaimed.
    fn warm_up(&mut self) {
        self.round_trip();
        if let Ok(batch) = self.from_worker.recv_timeout(WAIT_PRIMING) {
            self.reclaim(batch);
        }
    }

    /// See [`warm_up`](Self::warm_up).
    fn round_trip(&mut self) {
        let Some(mut batch) = self.free[0].take() else { return };
        batch.len = 0;
        batch.sequence = WARM_UP_SEQUENCE;
        let started = Instant::now();
        let sent = self.to_worker.as_ref().map(|tx| tx.send(batch));
        match sent {
            Some(Ok(())) => {
                self.in_flight[0] = Some((WARM_UP_SEQUENCE, started));
                match self.from_worker.recv_timeout(DEFAULT_HANG_THRESHOLD) {
                    Ok(batch) => self.reclaim(batch),
                    Err(RecvTimeoutError::Timeout) => self.check_hang(Instant::now()),
                    Err(RecvTimeoutError::Disconnected) => self.thread_gone = true,
                }
            }
            Some(Err(returned)) => {
                self.free[0] = Some(returned.0);
                self.thread_gone = true;
            }
            None => {}
        }
    }

    /// The inference thread's POSIX handle, for settings made from outside (CPU affinity,
    /// scheduling policy); `None` once the thread has been joined or detached. The handle stays
    /// valid while this predictor keeps the thread's join handle, even after the thread ended.
    #[cfg(unix)]
    pub fn inference_thread(&self) -> Option<std::os::unix::thread::RawPthread> {
        use std::os::unix::thread::JoinHandleExt;
        self.worker.as_ref().map(JoinHandleExt::as_pthread_t)
    }

    /// Whether a batch has been with the inference thread for at least the hang threshold
    /// (as of the latest `submit` or `collect`).
    pub fn is_inference_thread_hung(&self) -> bool {
        self.hung
    }

    /// How long a batch may stay with the inference thread before the thread is reported hung.
    pub fn hang_threshold(&self) -> Duration {
        self.hang_threshold
    }

    /// Changes the hang threshold (applies from the next `submit` or `collect`).
    pub fn set_hang_threshold(&mut self, threshold: Duration) {
        self.hang_threshold = threshold;
    }

    /// Changes how long dropping the predictor waits for the inference thread before detaching
    /// it.
    pub fn set_shutdown_wait(&mut self, wait: Duration) {
        self.shutdown_wait = wait;
    }

    /// Stops the inference thread: closes its work channel and waits at most the shutdown wait
    /// for it to finish; a thread still busy then is detached (and logged). Dropping the
    /// predictor does the same.
    pub fn shutdown(mut self) -> ShutdownOutcome {
        self.stop()
    }

    /// The work of [`shutdown`](Self::shutdown) and `drop`.
    fn stop(&mut self) -> ShutdownOutcome {
        // Closing the work channel ends the inference loop once its current batch is done; its
        // end drops the result channel's sender, which `recv_timeout` reports as disconnected.
        self.to_worker = None;
        let Some(worker) = self.worker.take() else { return ShutdownOutcome::AlreadyStopped };
        let until = Instant::now() + self.shutdown_wait;
        loop {
            let now = Instant::now();
            let received = if now >= until {
                self.from_worker.try_recv().map_err(|error| match error {
                    TryRecvError::Empty => RecvTimeoutError::Timeout,
                    TryRecvError::Disconnected => RecvTimeoutError::Disconnected,
                })
            } else {
                self.from_worker.recv_timeout(until - now)
            };
            match received {
                Ok(_returned) => {}
                Err(RecvTimeoutError::Disconnected) => {
                    let _ = worker.join();
                    return ShutdownOutcome::Joined;
                }
                Err(RecvTimeoutError::Timeout) => {
                    tracing::error!(
                        thread = INFERENCE_THREAD_NAME,
                        waited_ms = self.shutdown_wait.as_secs_f64() * 1000.0,
                        "inference thread still busy at shutdown; detached"
                    );
                    drop(worker);
                    return ShutdownOutcome::Detached;
                }
            }
        }
    }

    /// Starts a hang episode when a batch has been with the inference thread for at least
    /// the hang threshold at `now`.
    fn check_hang(&mut self, now: Instant) {
        if self.hung {
            return;
        }
        let oldest = self.in_flight.iter().flatten().map(|&(_, handed_over)| handed_over).min();
        let Some(oldest) = oldest else { return };
        let held = now.saturating_duration_since(oldest);
        if held >= self.hang_threshold {
            self.hung = true;
            self.stats.inference_hangs_detected += 1;
            tracing::error!(
                thread = INFERENCE_THREAD_NAME,
                held_ms = held.as_secs_f64() * 1000.0,
                threshold_ms = self.hang_threshold.as_secs_f64() * 1000.0,
                "inference thread hung: a batch is overdue; frames go without learned displacements"
            );
        }
    }

    /// How long both threads spin on their channel before parking: the inference thread after
    /// sending a batch back, waiting for the next; the tracking thread in `collect`, waiting for
    /// its batch (never past the deadline). A batch that arrives meanwhile is taken up without a
    /// wake-up (tens of µs each way, `benches/pr_frame_timeline.rs`), at the price of a core
    /// kept busy for that long: for hosts with cores to spare, or back-to-back frames (`primm
    /// track --inference-threads`). Zero (the default) parks at once. Applies from the next
    /// batch.
    pub fn set_spin(&mut self, spin: Duration) {
        self.spin.store(u64::try_from(spin.as_nanos()).unwrap_or(u64::MAX), Ordering::Relaxed);
    }

    /// The round trip of the latest batch collected on time; `None` before the first.
    pub fn last_timeline(&self) -> Option<BatchTimeline> {
        self.last_timeline
    }

    /// The counters.
    pub fn stats(&self) -> &ThreadedPredictorStats {
        &self.stats
    }

    /// The deadline of `collect`, measured from `submit`.
    pub fn deadline(&self) -> Duration {
        self.deadline
    }

    /// Changes the deadline (applies from the next `submit`).
    pub fn set_deadline(&mut self, deadline: Duration) {
        self.deadline = deadline;
    }

    /// Takes back every buffer the inference thread has returned so far, without waiting.
    fn reclaim_returned(&mut self) {
        loop {
            match self.from_worker.try_recv() {
                Ok(batch) => self.reclaim(batch),
                Err(TryRecvError::Empty | TryRecvError::Disconnected) => return,
            }
        }
    }

    /// Puts a returned buffer back into the free pool; counts it stale if nobody awaits it,
    /// and a panic if the inference did not complete; ends a hang episode once no batch is
    /// overdue any more.
    fn reclaim(&mut self, batch: Box<Batch>) {
        let awaited = self.awaited.map(|(sequence, _)| sequence);
        if awaited != Some(batch.sequence) && batch.sequence != WARM_UP_SEQUENCE {
            self.stats.stale_batches_discarded += 1;
        }
        if !batch.completed {
            self.stats.inference_panics += 1;
            self.thread_gone = true;
            tracing::error!(
                thread = INFERENCE_THREAD_NAME,
                "learned predictor panicked; it is retired and later frames go without learned displacements"
            );
        }
        if let Some(entry) =
            self.in_flight.iter_mut().find(|entry| entry.is_some_and(|(s, _)| s == batch.sequence))
        {
            *entry = None;
        }
        if self.hung && self.in_flight.iter().all(Option::is_none) {
            self.hung = false;
            self.stats.inference_hang_recoveries += 1;
            tracing::warn!(thread = INFERENCE_THREAD_NAME, "inference thread answered again after a hang");
        }
        if let Some(slot) = self.free.iter_mut().find(|slot| slot.is_none()) {
            *slot = Some(batch);
        }
    }
}

impl DisplacementPredictor for ThreadedPredictor {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        self.awaited = None;
        self.reclaim_returned();
        if requests.is_empty() {
            return;
        }
        let now = Instant::now();
        self.check_hang(now);
        if self.thread_gone {
            self.stats.frames_without_inference_thread += 1;
            return;
        }
        if requests.len() > self.capacity {
            self.stats.frames_too_large += 1;
            return;
        }
        let Some(slot) = self.free.iter_mut().find(|slot| slot.is_some()) else {
            self.stats.frames_without_free_buffer += 1;
            return;
        };
        let Some(mut batch) = slot.take() else { return };
        self.next_sequence += 1;
        batch.sequence = self.next_sequence;
        batch.len = requests.len();
        batch.requests[..requests.len()].copy_from_slice(requests);
        batch.completed = false;
        batch.submitted = Some(now);
        let Some(to_worker) = self.to_worker.as_ref() else { return };
        match to_worker.try_send(batch) {
            Ok(()) => {
                self.stats.batches_submitted += 1;
                self.awaited = Some((self.next_sequence, now + self.deadline));
                if let Some(entry) = self.in_flight.iter_mut().find(|entry| entry.is_none()) {
                    *entry = Some((self.next_sequence, now));
                }
            }
            Err(TrySendError::Full(batch)) => {
                // Cannot happen with one channel slot per buffer; keep the buffer regardless.
                self.reclaim(batch);
                self.stats.frames_without_free_buffer += 1;
            }
            Err(TrySendError::Disconnected(batch)) => {
                self.reclaim(batch);
                self.thread_gone = true;
                self.stats.frames_without_inference_thread += 1;
            }
        }
    }

    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        displacements.fill(None);
        let Some((sequence, deadline)) = self.awaited else { return };
        let spin = Duration::from_nanos(self.spin.load(Ordering::Relaxed));
        let spin_until = Instant::now() + spin;
        loop {
            let now = Instant::now();
            let received = if now >= deadline || now < spin_until {
                // Past the deadline only what has already arrived counts; before it, while
                // spinning, the channel is polled.
                self.from_worker.try_recv().map_err(|error| match error {
                    TryRecvError::Empty => RecvTimeoutError::Timeout,
                    TryRecvError::Disconnected => RecvTimeoutError::Disconnected,
                })
            } else {
                self.from_worker.recv_timeout(deadline - now)
            };
            if now < deadline && now < spin_until && matches!(received, Err(RecvTimeoutError::Timeout)) {
                std::hint::spin_loop();
                continue;
            }
            match received {
                Ok(batch) if batch.sequence == sequence => {
                    if batch.completed {
                        let n = batch.len.min(displacements.len());
                        displacements[..n].copy_from_slice(&batch.displacements[..n]);
                        self.stats.batches_on_time += 1;
                        if let (Some(submitted), Some(started), Some(finished)) =
                            (batch.submitted, batch.started, batch.finished)
                        {
                            let collected = Instant::now();
                            let requests = batch.len;
                            self.last_timeline =
                                Some(BatchTimeline { submitted, started, finished, collected, requests });
                        }
                    }
                    self.reclaim(batch);
                    self.awaited = None;
                    return;
                }
                Ok(stale) => self.reclaim(stale),
                Err(RecvTimeoutError::Timeout) => {
                    self.stats.deadline_misses += 1;
                    self.awaited = None;
                    self.check_hang(Instant::now());
                    return;
                }
                Err(RecvTimeoutError::Disconnected) => {
                    self.stats.frames_without_inference_thread += 1;
                    self.thread_gone = true;
                    self.awaited = None;
                    return;
                }
            }
        }
    }

    /// The wrapped predictor's (a missed deadline aside, which leaves an answer out whatever
    /// it depends on).
    fn answer_dependence(&self) -> AnswerDependence {
        self.dependence
    }

    fn report(&self) -> Option<String> {
        let s = &self.stats;
        Some(format!(
            "learned predictor (inference thread, deadline {:.1} ms): {} batches, {} on time, {} deadline misses, \
             {} stale discarded, {} without a free buffer, {} too large, {} inference panics, \
             {} without inference thread, {} hangs detected, {} hang recoveries{}",
            self.deadline.as_secs_f64() * 1000.0,
            s.batches_submitted,
            s.batches_on_time,
            s.deadline_misses,
            s.stale_batches_discarded,
            s.frames_without_free_buffer,
            s.frames_too_large,
            s.inference_panics,
            s.frames_without_inference_thread,
            s.inference_hangs_detected,
            s.inference_hang_recoveries,
            if self.hung { " (hung now)" } else { "" }
        ))
    }
}

impl Drop for ThreadedPredictor {
    /// Stops the inference thread, waiting at most the shutdown wait (see
    /// [`shutdown`](ThreadedPredictor::shutdown)).
    fn drop(&mut self) {
        self.stop();
    }
}

/// The inference thread: predicts every batch it receives and sends it back; after a panic of
/// the predictor it returns that batch without results and stops.
fn inference_loop<P: DisplacementPredictor>(
    mut predictor: P,
    work: Receiver<Box<Batch>>,
    done: SyncSender<Box<Batch>>,
    spin: &AtomicU64,
) {
    let mut next = work.recv();
    while let Ok(mut batch) = next {
        batch.started = Some(Instant::now());
        let len = batch.len;
        let Batch { requests, displacements, .. } = &mut *batch;
        let outcome =
            catch_unwind(AssertUnwindSafe(|| predictor.predict(&requests[..len], &mut displacements[..len])));
        batch.completed = outcome.is_ok();
        batch.finished = Some(Instant::now());
        if !batch.completed {
            batch.displacements[..len].fill(None);
            let _ = done.send(batch);
            // The predictor's state is unknown after the panic; dropping it may panic as well.
            let _ = catch_unwind(AssertUnwindSafe(move || drop(predictor)));
            return;
        }
        if done.send(batch).is_err() {
            return;
        }
        next = receive(&work, Duration::from_nanos(spin.load(Ordering::Relaxed)));
    }
}

/// The next batch: polled for up to `spin`, then waited for parked.
fn receive(work: &Receiver<Box<Batch>>, spin: Duration) -> Result<Box<Batch>, RecvError> {
    if !spin.is_zero() {
        let until = Instant::now() + spin;
        loop {
            match work.try_recv() {
                Ok(batch) => return Ok(batch),
                Err(TryRecvError::Disconnected) => return Err(RecvError),
                Err(TryRecvError::Empty) if Instant::now() >= until => break,
                Err(TryRecvError::Empty) => std::hint::spin_loop(),
            }
        }
    }
    work.recv()
}
