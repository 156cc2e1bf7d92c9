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
//! * A missed deadline, a failed or panicking inference, more requests than a buffer holds, or
//!   no free buffer (both still with a slow inference thread) give `None` for every track of
//!   that frame only: the PR mode sits the frame out and the next frame starts afresh.
//!
//! This is the one part of primm that reads a clock (for the deadline): with it, whether a
//! frame gets its learned displacements depends on timing. Offline tracking and evaluation use
//! the synchronous predictor instead.

use glam::DVec2;
use primm_core::limits::MAX_TRACKS;
use primm_core::predictor::{DisplacementPredictor, PredictionRequest};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::mpsc::{sync_channel, Receiver, RecvTimeoutError, SyncSender, TryRecvError, TrySendError};
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

/// One batch in flight: requests in, displacements out.
struct Batch {
    sequence: u64,
    len: usize,
    requests: Box<[PredictionRequest]>,
    displacements: Box<[Option<DVec2>]>,
    /// Whether the inference completed (a panic leaves every displacement `None`).
    completed: bool,
}

impl Batch {
    fn new(capacity: usize) -> Box<Self> {
        Box::new(Batch {
            sequence: 0,
            len: 0,
            requests: vec![PredictionRequest::default(); capacity].into_boxed_slice(),
            displacements: vec![None; capacity].into_boxed_slice(),
            completed: false,
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
    /// Batches in which the wrapped predictor panicked.
    pub inference_panics: u64,
    /// Frames not submitted because the inference thread is gone.
    pub frames_without_inference_thread: u64,
}

/// Runs a [`DisplacementPredictor`] on a dedicated inference thread, with a deadline per frame.
pub struct ThreadedPredictor {
    to_worker: Option<SyncSender<Box<Batch>>>,
    from_worker: Receiver<Box<Batch>>,
    free: [Option<Box<Batch>>; BUFFERS],
    worker: Option<JoinHandle<()>>,
    deadline: Duration,
    capacity: usize,
    next_sequence: u64,
    /// The batch of the current frame: its sequence number and deadline.
    awaited: Option<(u64, Instant)>,
    stats: ThreadedPredictorStats,
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
        let (to_worker, work) = sync_channel::<Box<Batch>>(BUFFERS);
        let (done, from_worker) = sync_channel::<Box<Batch>>(BUFFERS);
        let worker = std::thread::Builder::new()
            .name(INFERENCE_THREAD_NAME.to_string())
            .spawn(move || inference_loop(predictor, work, done))?;
        let mut threaded = ThreadedPredictor {
            to_worker: Some(to_worker),
            from_worker,
            free: std::array::from_fn(|_| Some(Batch::new(capacity))),
            worker: Some(worker),
            deadline,
            capacity,
            next_sequence: 0,
            awaited: None,
            stats: ThreadedPredictorStats::default(),
        };
        threaded.warm_up();
        Ok(threaded)
    }

    /// One empty round trip (not counted in the statistics), waiting as long as it takes; then
    /// one wait on the empty return channel.
    ///
    /// The first time a thread blocks on a channel, std allocates (the thread's wait context
    /// and the channel's list of waiters). The round trip blocks only if the answer is not back
    /// yet, which depends on scheduling, so a wait on the empty channel makes sure those
    /// allocations happen here, on the thread that builds the predictor, instead of in the
    /// first `collect` that has to wait.
    fn warm_up(&mut self) {
        self.round_trip();
        let _ = self.from_worker.recv_timeout(WAIT_PRIMING);
    }

    /// See [`warm_up`](Self::warm_up).
    fn round_trip(&mut self) {
        let Some(mut batch) = self.free[0].take() else { return };
        batch.len = 0;
        batch.sequence = u64::MAX;
        let sent = self.to_worker.as_ref().map(|tx| tx.send(batch));
        match sent {
            Some(Ok(())) => {
                if let Ok(batch) = self.from_worker.recv_timeout(Duration::from_secs(3600)) {
                    self.free[0] = Some(batch);
                }
            }
            Some(Err(returned)) => self.free[0] = Some(returned.0),
            None => {}
        }
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

    /// Puts a returned buffer back into the free pool; counts it stale if nobody awaits it.
    fn reclaim(&mut self, batch: Box<Batch>) {
        let awaited = self.awaited.map(|(sequence, _)| sequence);
        if awaited != Some(batch.sequence) && batch.sequence != u64::MAX {
            self.stats.stale_batches_discarded += 1;
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
        let Some(to_worker) = self.to_worker.as_ref() else { return };
        match to_worker.try_send(batch) {
            Ok(()) => {
                self.stats.batches_submitted += 1;
                self.awaited = Some((self.next_sequence, Instant::now() + self.deadline));
            }
            Err(TrySendError::Full(batch)) => {
                // Cannot happen with one channel slot per buffer; keep the buffer regardless.
                self.reclaim(batch);
                self.stats.frames_without_free_buffer += 1;
            }
            Err(TrySendError::Disconnected(batch)) => {
                self.reclaim(batch);
                self.stats.frames_without_inference_thread += 1;
            }
        }
    }

    fn collect(&mut self, displacements: &mut [Option<DVec2>]) {
        displacements.fill(None);
        let Some((sequence, deadline)) = self.awaited else { return };
        loop {
            let now = Instant::now();
            let received = if now >= deadline {
                // Past the deadline: only what has already arrived counts.
                self.from_worker.try_recv().map_err(|error| match error {
                    TryRecvError::Empty => RecvTimeoutError::Timeout,
                    TryRecvError::Disconnected => RecvTimeoutError::Disconnected,
                })
            } else {
                self.from_worker.recv_timeout(deadline - now)
            };
            match received {
                Ok(batch) if batch.sequence == sequence => {
                    if batch.completed {
                        let n = batch.len.min(displacements.len());
                        displacements[..n].copy_from_slice(&batch.displacements[..n]);
                        self.stats.batches_on_time += 1;
                    } else {
                        self.stats.inference_panics += 1;
                    }
                    self.reclaim(batch);
                    self.awaited = None;
                    return;
                }
                Ok(stale) => self.reclaim(stale),
                Err(RecvTimeoutError::Timeout) => {
                    self.stats.deadline_misses += 1;
                    self.awaited = None;
                    return;
                }
                Err(RecvTimeoutError::Disconnected) => {
                    self.stats.frames_without_inference_thread += 1;
                    self.awaited = None;
                    return;
                }
            }
        }
    }

    fn report(&self) -> Option<String> {
        let s = &self.stats;
        Some(format!(
            "learned predictor (inference thread, deadline {:.1} ms): {} batches, {} on time, {} deadline misses, \
             {} stale discarded, {} without a free buffer, {} too large, {} inference panics",
            self.deadline.as_secs_f64() * 1000.0,
            s.batches_submitted,
            s.batches_on_time,
            s.deadline_misses,
            s.stale_batches_discarded,
            s.frames_without_free_buffer,
            s.frames_too_large,
            s.inference_panics
        ))
    }
}

impl Drop for ThreadedPredictor {
    fn drop(&mut self) {
        // Closing the work channel ends the inference loop once its current batch is done.
        self.to_worker = None;
        if let Some(worker) = self.worker.take() {
            let _ = worker.join();
        }
    }
}

/// The inference thread: predicts every batch it receives and sends it back.
fn inference_loop<P: DisplacementPredictor>(
    mut predictor: P,
    work: Receiver<Box<Batch>>,
    done: SyncSender<Box<Batch>>,
) {
    while let Ok(mut batch) = work.recv() {
        let len = batch.len;
        let Batch { requests, displacements, .. } = &mut *batch;
        let outcome =
            catch_unwind(AssertUnwindSafe(|| predictor.predict(&requests[..len], &mut displacements[..len])));
        batch.completed = outcome.is_ok();
        if !batch.completed {
            batch.displacements[..len].fill(None);
        }
        if done.send(batch).is_err() {
            return;
        }
    }
}
