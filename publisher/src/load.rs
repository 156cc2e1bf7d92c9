//! Load for service benchmarks: a scene of `N` objects on lanes, sent at a fixed wall-clock
//! rate with every frame stamped with its scheduled send time, the tracker's answers read as
//! they come; and the search for the highest rate a tracker sustains without losing a frame.
//!
//! `primm bench-service` and `benches/max_rate.rs` run their trials with this module.

use crate::replay::{ReplayError, Replayer};
use hdrhistogram::Histogram;
use primm_core::measurement::{Measurement, ObjectClass};
use primm_ipc::clock::monotonic_ns;
use primm_ipc::latency::MAX_TRACKABLE_NS;
use primm_ipc::ShutdownFlag;
use primm_sim::io::{RecordedFrame, RecordedMeasurement, Sequence};
use primm_wire::{TrackFrame, FRAME_FLAG_STREAM_END, FRAME_FLAG_STREAM_START};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::time::{Duration, Instant};

/// Sensor time between the frames of [`lane_scene`], s.
pub const LANE_SCENE_FRAME_INTERVAL_S: f64 = 0.05;

/// Frames of [`lane_scene`] before it repeats (each repetition a new stream).
pub const LANE_SCENE_FRAMES: usize = 500;

/// `objects` objects on parallel lanes 4 m apart, alternating cars (8-12 m/s) and pedestrians
/// (1.2-1.5 m/s), every one measured in each of `frames` frames `interval_s` apart, with
/// Gaussian position noise of `noise_m` (and 0.1 m/s on the radial velocity).
pub fn lane_scene(objects: usize, frames: usize, interval_s: f64, noise_m: f64, seed: u64) -> Sequence {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let noise =
        Normal::new(0.0, noise_m.max(0.0)).unwrap_or_else(|_| Normal::new(0.0, 0.0).expect("zero noise"));
    let velocity_noise = Normal::new(0.0, 0.1).expect("valid noise");
    let frames = (0..frames)
        .map(|index| {
            let t = index as f64 * interval_s;
            let measurements = (0..objects)
                .map(|i| {
                    let class = if i % 2 == 0 { ObjectClass::Car } else { ObjectClass::Pedestrian };
                    let speed = if class == ObjectClass::Car {
                        8.0 + (i % 5) as f64
                    } else {
                        1.2 + 0.1 * (i % 4) as f64
                    };
                    let x = 5.0 + (i % 3) as f64 * 10.0 + speed * t;
                    let y = -128.0 + 4.0 * i as f64;
                    let range = (x * x + y * y).sqrt().max(1.0);
                    RecordedMeasurement {
                        measurement: Measurement {
                            x_m: x + noise.sample(&mut rng),
                            y_m: y + noise.sample(&mut rng),
                            radial_velocity_mps: speed * x / range + velocity_noise.sample(&mut rng),
                            rcs_dbsm: if class == ObjectClass::Car { 10.0 } else { -5.0 },
                            class,
                            sensor_id: Some(0),
                            ground_truth_id: Some(i as u64 + 1),
                        },
                        true_position: None,
                        true_velocity: None,
                        origin: None,
                    }
                })
                .collect();
            RecordedFrame {
                index: index as u64,
                timestamp_s: t,
                sensor_id: Some(0),
                ego_pose: None,
                measurements,
            }
        })
        .collect();
    Sequence { name: format!("lanes-{objects}"), frames }
}

/// The latencies a load client measures on the answers, in the order of [`RateTrial::latencies`]
/// (named as the subscriber names them, so that their files compare).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClientLatency {
    /// Publisher send of the frame to the client's receive of its answer.
    PublisherToSubscriber = 0,
    /// The same from the frame's scheduled send time: corrected for coordinated omission.
    PublisherToSubscriberCorrected = 1,
    /// Tracker send of the answer to the client's receive.
    TrackerToSubscriber = 2,
}

impl ClientLatency {
    /// Number of latencies.
    pub const COUNT: usize = 3;
    /// All, in order.
    pub const ALL: [ClientLatency; Self::COUNT] =
        [Self::PublisherToSubscriber, Self::PublisherToSubscriberCorrected, Self::TrackerToSubscriber];

    /// File and table name.
    pub fn name(self) -> &'static str {
        match self {
            Self::PublisherToSubscriber => "publisher_to_subscriber",
            Self::PublisherToSubscriberCorrected => "publisher_to_subscriber_corrected",
            Self::TrackerToSubscriber => "tracker_to_subscriber",
        }
    }

    /// What is measured, one line.
    pub fn description(self) -> &'static str {
        match self {
            Self::PublisherToSubscriber => "publisher send of the measurement frame to receive of its answer",
            Self::PublisherToSubscriberCorrected => {
                "corrected for coordinated omission: scheduled send time of the measurement frame to receive of its answer"
            }
            Self::TrackerToSubscriber => "tracker send of the track frame to its receive",
        }
    }
}

/// How a trial loads the tracker.
#[derive(Debug, Clone, PartialEq)]
pub struct RateTrialOptions {
    /// Frames per second of wall-clock time, > 0.
    pub rate_hz: f64,
    /// How long frames are sent.
    pub duration: Duration,
    /// Longest wait for the last answers after the last frame.
    pub drain: Duration,
}

/// What a trial saw.
#[derive(Debug, Clone)]
pub struct RateTrial {
    /// The rate asked for, Hz.
    pub rate_hz: f64,
    /// Frames sent.
    pub sent: u64,
    /// Frames that could not be sent (no shared-memory sample to loan, or the send failed).
    pub send_failures: u64,
    /// Answers received.
    pub answered: u64,
    /// Answers that reported a rejected frame.
    pub rejected: u64,
    /// Frames sent later than their schedule by more than one frame interval.
    pub late_sends: u64,
    /// Indexed by [`ClientLatency`], ns.
    pub latencies: [Histogram<u64>; ClientLatency::COUNT],
    /// Wall-clock time from the first scheduled send to the last answer read.
    pub elapsed: Duration,
}

impl RateTrial {
    /// Frames sent whose answer never arrived (dropped from the tracker's full input buffer, or
    /// not answered within the drain time).
    pub fn lost(&self) -> u64 {
        self.sent.saturating_sub(self.answered)
    }

    /// Whether every frame was sent and answered.
    pub fn lossless(&self) -> bool {
        self.send_failures == 0 && self.lost() == 0
    }
}

/// Why a trial could not run.
#[derive(Debug, thiserror::Error)]
pub enum RateTrialError {
    /// The rate is not a positive number or the scene is empty.
    #[error("a trial needs a positive rate and a scene with frames (rate {rate_hz} Hz, {frames} frames)")]
    Invalid {
        /// The rate asked for.
        rate_hz: f64,
        /// Frames in the scene.
        frames: usize,
    },
    /// Reading the answers failed.
    #[error(transparent)]
    Replay(#[from] ReplayError),
}

/// How often a trial looks for answers while it waits for the next send time. The iceoryx2
/// listener's timed wait rounds its timeout up to the kernel's tick (several ms here), far too
/// coarse to pace sends by; a short sleep is exact to tens of µs. The client's receive time of
/// an answer is therefore late by up to this much (the tracker's own stamps are not).
pub const ANSWER_POLL_INTERVAL: Duration = Duration::from_micros(100);

/// A histogram of latencies in ns, as the service keeps them.
pub fn latency_histogram() -> Histogram<u64> {
    Histogram::new_with_bounds(1, MAX_TRACKABLE_NS, 3).expect("valid histogram bounds")
}

impl RateTrial {
    /// A trial at `rate_hz` before its first frame.
    fn starting(rate_hz: f64) -> Self {
        RateTrial {
            rate_hz,
            sent: 0,
            send_failures: 0,
            answered: 0,
            rejected: 0,
            late_sends: 0,
            latencies: std::array::from_fn(|_| latency_histogram()),
            elapsed: Duration::ZERO,
        }
    }

    /// Counts one answer received at `now_ns` and records its latencies: from the input's
    /// publication, from its scheduled send time (coordinated-omission corrected; the
    /// publication time where the frame had no schedule) and from the tracker's publication.
    fn record_answer(&mut self, answer: &TrackFrame, now_ns: u64) {
        self.answered += 1;
        if answer.status != 0 {
            self.rejected += 1;
        }
        let mut record_since = |latency: ClientLatency, since_ns: u64| {
            if since_ns != 0 && since_ns <= now_ns {
                self.latencies[latency as usize].saturating_record((now_ns - since_ns).max(1));
            }
        };
        record_since(ClientLatency::PublisherToSubscriber, answer.input_publish_time_ns);
        let scheduled = if answer.input_scheduled_time_ns != 0 {
            answer.input_scheduled_time_ns
        } else {
            answer.input_publish_time_ns
        };
        record_since(ClientLatency::PublisherToSubscriberCorrected, scheduled);
        record_since(ClientLatency::TrackerToSubscriber, answer.publish_time_ns);
    }
}

/// Sends `scene` (repeated, each repetition a new stream) at `options.rate_hz` through
/// `replayer` (opened with flow control, so that it reads the answers) for
/// `options.duration`, each frame stamped with its scheduled send time, and reads the answers
/// as they come (every [`ANSWER_POLL_INTERVAL`] between sends). `on_answer` is called with the
/// receive time and the latencies after every answer, for interval logs. Stops early on
/// `shutdown`.
pub fn run_rate_trial(
    replayer: &mut Replayer,
    scene: &Sequence,
    options: &RateTrialOptions,
    shutdown: &ShutdownFlag,
    mut on_answer: impl FnMut(u64, &[Histogram<u64>; ClientLatency::COUNT]),
) -> Result<RateTrial, RateTrialError> {
    if !(options.rate_hz.is_finite() && options.rate_hz > 0.0) || scene.frames.is_empty() {
        return Err(RateTrialError::Invalid { rate_hz: options.rate_hz, frames: scene.frames.len() });
    }
    let interval = Duration::from_secs_f64(1.0 / options.rate_hz);
    let frames = (options.rate_hz * options.duration.as_secs_f64()).ceil().max(1.0) as u64;
    let mut trial = RateTrial::starting(options.rate_hz);
    let start = Instant::now();
    let start_ns = monotonic_ns();
    let mut record = |trial: &mut RateTrial, answer: &TrackFrame| {
        let now_ns = monotonic_ns();
        trial.record_answer(answer, now_ns);
        on_answer(now_ns, &trial.latencies);
    };
    let scene_frames = scene.frames.len();
    for k in 0..frames {
        if shutdown.is_requested() {
            break;
        }
        let offset = interval.mul_f64(k as f64);
        let due = start + offset;
        loop {
            replayer.receive_answers(|answer| record(&mut trial, answer))?;
            let now = Instant::now();
            if now >= due {
                break;
            }
            std::thread::sleep((due - now).min(ANSWER_POLL_INTERVAL));
        }
        if Instant::now().duration_since(due) > interval {
            trial.late_sends += 1;
        }
        let index = (k as usize) % scene_frames;
        let mut frame = scene.frames[index].clone();
        // Sensor time keeps increasing across repetitions; each repetition starts a new stream
        // so that the tracker resets instead of seeing every object jump back.
        frame.timestamp_s = k as f64 * LANE_SCENE_FRAME_INTERVAL_S;
        let mut flags = if index == 0 { FRAME_FLAG_STREAM_START } else { 0 };
        if k + 1 == frames {
            flags |= FRAME_FLAG_STREAM_END;
        }
        let scheduled_ns = start_ns.saturating_add(offset.as_nanos() as u64);
        match replayer.send_scheduled(&scene.name, &frame, flags, scheduled_ns) {
            Ok(_) => trial.sent += 1,
            Err(ReplayError::Loan(_) | ReplayError::Send(_)) => trial.send_failures += 1,
            Err(error) => return Err(error.into()),
        }
    }
    let drain_until = Instant::now() + options.drain;
    while trial.answered < trial.sent && !shutdown.is_requested() {
        replayer.receive_answers(|answer| record(&mut trial, answer))?;
        let now = Instant::now();
        if now >= drain_until || trial.answered >= trial.sent {
            break;
        }
        std::thread::sleep((drain_until - now).min(ANSWER_POLL_INTERVAL));
    }
    trial.elapsed = start.elapsed();
    Ok(trial)
}

/// The outcome of [`highest_sustained_rate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RateSearch {
    /// The highest rate tried without loss, Hz.
    pub highest_lossless_hz: Option<f64>,
    /// The lowest rate tried with loss, Hz.
    pub lowest_lossy_hz: Option<f64>,
    /// Trials run.
    pub trials: usize,
}

/// Finds the highest rate at which `lossless(rate)` holds: doubles the rate from `start_hz`
/// until a trial loses frames (or `max_hz` is passed), then bisects between the last good and
/// the first bad rate `steps` times.
pub fn highest_sustained_rate<E>(
    start_hz: f64,
    max_hz: f64,
    steps: usize,
    mut lossless: impl FnMut(f64) -> Result<bool, E>,
) -> Result<RateSearch, E> {
    let mut search = RateSearch { highest_lossless_hz: None, lowest_lossy_hz: None, trials: 0 };
    let mut rate = start_hz;
    while search.lowest_lossy_hz.is_none() && rate <= max_hz && rate > 0.0 {
        search.trials += 1;
        if lossless(rate)? {
            search.highest_lossless_hz = Some(rate);
            rate *= 2.0;
        } else {
            search.lowest_lossy_hz = Some(rate);
        }
    }
    for _ in 0..steps {
        let (Some(low), Some(high)) = (search.highest_lossless_hz, search.lowest_lossy_hz) else { break };
        let rate = (low + high) / 2.0;
        search.trials += 1;
        if lossless(rate)? {
            search.highest_lossless_hz = Some(rate);
        } else {
            search.lowest_lossy_hz = Some(rate);
        }
    }
    Ok(search)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_search_brackets_the_boundary_of_a_known_capacity() {
        let capacity = 1234.0;
        let mut tried = Vec::new();
        let search = highest_sustained_rate::<()>(50.0, 100_000.0, 6, |rate| {
            tried.push(rate);
            Ok(rate <= capacity)
        })
        .unwrap();
        let (low, high) = (search.highest_lossless_hz.unwrap(), search.lowest_lossy_hz.unwrap());
        assert!(low <= capacity && capacity < high, "{low} {high}");
        // Doubling 50 → 1600 (6 trials), then 6 bisection steps narrow 800..1600 to 12.5 Hz.
        assert_eq!(search.trials, 12);
        assert_eq!(tried.len(), 12);
        assert!(high - low <= 800.0 / 64.0 + 1e-9, "{low} {high}");
    }

    #[test]
    fn a_tracker_that_loses_at_the_first_rate_has_no_lossless_rate() {
        let search = highest_sustained_rate::<()>(50.0, 1000.0, 4, |_| Ok(false)).unwrap();
        assert_eq!(search.highest_lossless_hz, None);
        assert_eq!(search.lowest_lossy_hz, Some(50.0));
        assert_eq!(search.trials, 1);
        let search = highest_sustained_rate::<()>(50.0, 1000.0, 4, |_| Ok(true)).unwrap();
        assert_eq!(search.highest_lossless_hz, Some(800.0));
        assert_eq!(search.lowest_lossy_hz, None);
    }

    #[test]
    fn the_lane_scene_measures_every_object_in_every_frame() {
        let scene = lane_scene(64, 10, LANE_SCENE_FRAME_INTERVAL_S, 0.2, 11);
        assert_eq!(scene.frames.len(), 10);
        assert!(scene.frames.iter().all(|frame| frame.measurements.len() == 64));
        assert!(scene.frames.windows(2).all(|pair| pair[0].timestamp_s < pair[1].timestamp_s));
        let cars =
            scene.frames[0].measurements.iter().filter(|m| m.measurement.class == ObjectClass::Car).count();
        assert_eq!(cars, 32);
    }
}
