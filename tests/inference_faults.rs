//! The tracker under a faulty learned predictor: wrong answers (NaN, ±∞, absurd
//! displacements), late answers, a hung and a panicking inference thread — for all tracks or
//! only some tracks and frames.
//!
//! In every case the PR mode sits out exactly the affected tracks and frames, each dropout is
//! counted, the physics modes carry on (the same tracks as a tracker without PR), the tracker's
//! invariants hold after every step, and no step waits for a predictor that does not answer.
//! Nothing here asserts a duration: a late or hung predictor is held until the test releases it
//! (or forever), so a missed deadline is certain whatever the machine's speed.

use crate::common;

use glam::DVec2;
use primm_core::config::Config;
use primm_core::invariants::check_tracker;
use primm_core::measurement::Frame;
use primm_core::mode::Method;
use primm_core::predictor::{Displacement, DisplacementPredictor, PredictionRequest};
use primm_core::tracker::{StepSummary, Tracker};
use primm_predictor::threaded::{ShutdownOutcome, ThreadedPredictor};
use std::sync::mpsc::{channel, Receiver};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// A deadline no healthy answer misses, however loaded the machine.
const GENEROUS_DEADLINE: Duration = Duration::from_secs(30);
/// The deadline of frames whose answer is held back: it is certainly missed.
const SHORT_DEADLINE: Duration = Duration::from_millis(5);

/// Six objects on parallel lanes, 80 frames 50 ms apart.
fn frames() -> Vec<Frame> {
    common::scene_frames(&common::lanes(6), 80, 0.05, 0.2, 17)
}

/// The lane (0..6) of the object a request's track follows (lanes are 4 m apart from −128 m).
fn lane(request: &PredictionRequest) -> i64 {
    ((request.anchor_m.y + 128.0) / 4.0).round() as i64
}

/// A plausible displacement: the track's history extrapolated at constant velocity over the
/// request's step.
fn plausible(request: &PredictionRequest) -> DVec2 {
    if request.len < 2 {
        return DVec2::ZERO;
    }
    let oldest = request.features[0];
    let latest = request.features[request.len - 1];
    let span_s = f64::from(latest[4] - oldest[4]);
    if span_s <= 0.0 {
        return DVec2::ZERO;
    }
    let velocity = DVec2::new(f64::from(latest[0] - oldest[0]), f64::from(latest[1] - oldest[1])) / span_s;
    velocity * (request.prediction_time_s - request.step_start_s)
}

/// A wrong answer.
#[derive(Debug, Clone, Copy)]
enum WrongAnswer {
    Nan,
    PositiveInfinity,
    NegativeInfinity,
    /// A displacement of this many metres along x.
    Absurd(f64),
}

impl WrongAnswer {
    fn displacement(self) -> DVec2 {
        match self {
            WrongAnswer::Nan => DVec2::new(f64::NAN, 0.0),
            WrongAnswer::PositiveInfinity => DVec2::new(0.0, f64::INFINITY),
            WrongAnswer::NegativeInfinity => DVec2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
            WrongAnswer::Absurd(metres) => DVec2::new(metres, 0.0),
        }
    }

    fn is_non_finite(self) -> bool {
        !matches!(self, WrongAnswer::Absurd(_))
    }
}

/// Which tracks and frames a fault hits.
#[derive(Debug, Clone)]
struct Selection {
    /// Lanes hit; `None`: every track.
    lanes: Option<Vec<i64>>,
    /// Prediction times hit, s: `[from, to)`.
    times_s: (f64, f64),
}

impl Selection {
    fn everything() -> Self {
        Selection { lanes: None, times_s: (f64::NEG_INFINITY, f64::INFINITY) }
    }

    fn hits_frame(&self, time_s: f64) -> bool {
        (self.times_s.0..self.times_s.1).contains(&time_s)
    }

    fn hits(&self, request: &PredictionRequest) -> bool {
        self.hits_frame(request.prediction_time_s)
            && self.lanes.as_ref().is_none_or(|lanes| lanes.contains(&lane(request)))
    }
}

/// What a predictor does in the frames its selection hits.
enum Behaviour {
    /// Answers wrongly for the selected tracks.
    Wrong(WrongAnswer),
    /// Holds the whole batch until the test sends on the channel (one release per batch).
    Late(Mutex<Receiver<()>>),
    /// Never returns.
    Hang,
    /// Panics.
    Panic,
}

/// A predictor that answers plausibly except where its selection says otherwise; remembers how
/// many answers of its latest batch it got wrong.
struct FaultyPredictor {
    behaviour: Behaviour,
    selection: Selection,
    answers: Vec<Option<Displacement>>,
    wrong_in_latest_batch: Arc<Mutex<usize>>,
}

impl FaultyPredictor {
    fn new(behaviour: Behaviour, selection: Selection) -> Self {
        FaultyPredictor { behaviour, selection, answers: Vec::new(), wrong_in_latest_batch: Arc::default() }
    }
}

impl DisplacementPredictor for FaultyPredictor {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        self.answers.clear();
        let mut wrong = 0;
        let frame_hit =
            requests.first().is_some_and(|request| self.selection.hits_frame(request.prediction_time_s));
        match &self.behaviour {
            Behaviour::Late(release) if frame_hit => {
                release.lock().unwrap().recv().expect("the test releases every late batch");
            }
            Behaviour::Hang if frame_hit => loop {
                std::thread::park();
            },
            Behaviour::Panic if frame_hit => panic!("the learned predictor fails (deliberately)"),
            _ => {}
        }
        for request in requests {
            let answer = match &self.behaviour {
                Behaviour::Wrong(answer) if self.selection.hits(request) => {
                    wrong += 1;
                    answer.displacement()
                }
                _ => plausible(request),
            };
            self.answers.push(Some(answer.into()));
        }
        *self.wrong_in_latest_batch.lock().unwrap() = wrong;
    }

    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        displacements.copy_from_slice(&self.answers[..displacements.len()]);
    }
}

/// PR-IMM with every class predicted (the faults are counted per requested track).
fn pr_imm() -> Config {
    let mut config = Config::default().with_modes(Method::PrImm.modes());
    config.predictor.classes = primm_core::measurement::ClassSet::ALL;
    config
}

/// (live tracks, confirmed tracks, assigned) of every frame of a tracker without PR: the
/// physics-only baseline.
fn physics_baseline(frames: &[Frame]) -> Vec<(usize, usize, usize)> {
    let mut tracker = Tracker::new(Config::default().with_modes(Method::Imm.modes())).unwrap();
    frames
        .iter()
        .map(|frame| {
            tracker.step(frame).unwrap();
            let s = tracker.last_step();
            (s.live_tracks, s.confirmed_tracks, s.counts.tracks_updated as usize)
        })
        .collect()
}

/// Steps `tracker` over `frames`, checking the invariants and the physics modes after each
/// step; returns each step's summary. `before_step(k, tracker)` runs before frame `k`,
/// `after_step(k, tracker)` after it.
fn run<P: DisplacementPredictor>(
    tracker: &mut Tracker<P>,
    frames: &[Frame],
    mut before_step: impl FnMut(usize, &mut Tracker<P>),
    mut after_step: impl FnMut(usize, &mut Tracker<P>),
) -> Vec<StepSummary> {
    let baseline = physics_baseline(frames);
    let mut summaries = Vec::new();
    for (k, frame) in frames.iter().enumerate() {
        before_step(k, tracker);
        tracker.step(frame).unwrap();
        let summary = *tracker.last_step();
        check_tracker(tracker).unwrap_or_else(|violation| panic!("frame {k}: {violation}"));
        assert_eq!(
            (summary.live_tracks, summary.confirmed_tracks, summary.counts.tracks_updated as usize),
            baseline[k],
            "frame {k}: the physics modes track as without PR"
        );
        after_step(k, tracker);
        summaries.push(summary);
    }
    summaries
}

/// Runs a synchronous predictor answering `answer` for `selection`; checks that exactly the
/// wrong answers are rejected, under the right reason, and nothing else is missing.
fn wrong_answers_are_rejected(answer: WrongAnswer, selection: Selection) {
    let frames = frames();
    let predictor = FaultyPredictor::new(Behaviour::Wrong(answer), selection.clone());
    let wrong = predictor.wrong_in_latest_batch.clone();
    let mut tracker = Tracker::with_predictor(pr_imm(), predictor).unwrap();
    let mut wrong_per_frame = Vec::new();
    let summaries = run(
        &mut tracker,
        &frames,
        |_, _| *wrong.lock().unwrap() = 0,
        |_, _| wrong_per_frame.push(*wrong.lock().unwrap()),
    );
    let mut total_wrong = 0;
    for (k, (summary, &wrong)) in summaries.iter().zip(&wrong_per_frame).enumerate() {
        let (non_finite, implausible) = if answer.is_non_finite() { (wrong, 0) } else { (0, wrong) };
        assert_eq!(summary.counts.learned_predictions_rejected_non_finite as usize, non_finite, "frame {k}");
        assert_eq!(
            summary.counts.learned_predictions_rejected_implausible as usize, implausible,
            "frame {k}"
        );
        assert_eq!(
            summary.counts.learned_predictions_missing as usize, wrong,
            "frame {k}: only the wrong answers are missing"
        );
        if !selection.hits_frame(frames[k].timestamp_s) {
            assert_eq!(wrong, 0, "frame {k} is outside the selection");
        }
        total_wrong += wrong;
    }
    assert!(total_wrong > 0, "the fault struck");
    let stats = tracker.stats();
    assert_eq!(stats.learned_predictions_missing as usize, total_wrong);
    let rejected =
        stats.learned_predictions_rejected_non_finite + stats.learned_predictions_rejected_implausible;
    assert_eq!(rejected as usize, total_wrong);
}

/// Lanes 1 and 4 from 1 s to 2.5 s.
fn some_tracks_and_frames() -> Selection {
    Selection { lanes: Some(vec![1, 4]), times_s: (1.0, 2.5) }
}

#[test]
fn nan_displacements_for_every_track_are_rejected_as_non_finite_and_the_physics_modes_carry_on() {
    wrong_answers_are_rejected(WrongAnswer::Nan, Selection::everything());
}

#[test]
fn nan_displacements_for_some_tracks_and_frames_cost_exactly_those_predictions() {
    wrong_answers_are_rejected(WrongAnswer::Nan, some_tracks_and_frames());
}

#[test]
fn infinite_displacements_are_rejected_as_non_finite_for_every_track_or_some() {
    wrong_answers_are_rejected(WrongAnswer::PositiveInfinity, Selection::everything());
    wrong_answers_are_rejected(WrongAnswer::NegativeInfinity, some_tracks_and_frames());
}

#[test]
fn absurd_displacements_are_rejected_as_implausible_for_every_track_or_some() {
    wrong_answers_are_rejected(WrongAnswer::Absurd(1e6), Selection::everything());
    wrong_answers_are_rejected(WrongAnswer::Absurd(1e300), some_tracks_and_frames());
    wrong_answers_are_rejected(WrongAnswer::Absurd(-1e6), some_tracks_and_frames());
}

#[test]
fn a_displacement_just_above_the_configured_speed_bound_is_implausible_and_one_below_is_used() {
    // Every answer moves 30 m/s over its step; a bound of 29 m/s rejects all, 31 m/s none.
    #[derive(Default)]
    struct Speed(Vec<Option<Displacement>>);
    impl DisplacementPredictor for Speed {
        fn submit(&mut self, requests: &[PredictionRequest]) {
            self.0.clear();
            for request in requests {
                self.0.push(Some(
                    DVec2::new(30.0 * (request.prediction_time_s - request.step_start_s), 0.0).into(),
                ));
            }
        }
        fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
            displacements.copy_from_slice(&self.0);
        }
    }
    for (bound_mps, expect_rejected) in [(29.0, true), (31.0, false)] {
        let mut config = pr_imm();
        config.predictor.max_displacement_speed_mps = bound_mps;
        let mut tracker = Tracker::with_predictor(config, Speed::default()).unwrap();
        let mut requested = 0;
        for frame in frames().iter().take(20) {
            tracker.step(frame).unwrap();
            check_tracker(&tracker).unwrap();
            requested += tracker.last_step().live_tracks
                + (tracker.last_step().counts.tracks_deleted as usize)
                - (tracker.last_step().counts.tracks_initiated as usize);
        }
        let rejected = tracker.stats().learned_predictions_rejected_implausible as usize;
        assert!(requested > 0);
        assert_eq!(rejected, if expect_rejected { requested } else { 0 }, "bound {bound_mps} m/s");
    }
}

#[test]
fn non_finite_answers_through_the_inference_thread_are_rejected_for_the_selected_tracks_only() {
    let frames = frames();
    let predictor = FaultyPredictor::new(Behaviour::Wrong(WrongAnswer::Nan), some_tracks_and_frames());
    let wrong = predictor.wrong_in_latest_batch.clone();
    let threaded = ThreadedPredictor::new(predictor, GENEROUS_DEADLINE).unwrap();
    let mut tracker = Tracker::with_predictor(pr_imm(), threaded).unwrap();
    let mut wrong_per_frame = Vec::new();
    let summaries = run(
        &mut tracker,
        &frames,
        |_, _| *wrong.lock().unwrap() = 0,
        |_, _| wrong_per_frame.push(*wrong.lock().unwrap()),
    );
    for (k, (summary, &wrong)) in summaries.iter().zip(&wrong_per_frame).enumerate() {
        assert_eq!(summary.counts.learned_predictions_rejected_non_finite as usize, wrong, "frame {k}");
        assert_eq!(summary.counts.learned_predictions_missing as usize, wrong, "frame {k}");
    }
    assert!(wrong_per_frame.iter().sum::<usize>() > 0);
    assert_eq!(tracker.predictor().stats().deadline_misses, 0);
}

#[test]
fn late_answers_cost_exactly_the_late_frames_and_are_counted_as_deadline_misses() {
    let frames = frames();
    let (release, released) = channel::<()>();
    let late = Selection { lanes: None, times_s: (1.0, 1.2) };
    let predictor = FaultyPredictor::new(Behaviour::Late(Mutex::new(released)), late.clone());
    let threaded = ThreadedPredictor::new(predictor, GENEROUS_DEADLINE).unwrap();
    let mut tracker = Tracker::with_predictor(pr_imm(), threaded).unwrap();
    let is_late = |k: usize| late.hits_frame(frames[k].timestamp_s);
    let summaries = run(
        &mut tracker,
        &frames,
        |k, tracker| {
            let deadline = if is_late(k) { SHORT_DEADLINE } else { GENEROUS_DEADLINE };
            tracker.predictor_mut().set_deadline(deadline);
        },
        |k, _| {
            if is_late(k) {
                // The step returned without the held batch; now let it finish (too late).
                release.send(()).unwrap();
            }
        },
    );
    let late_frames: Vec<usize> = (0..frames.len()).filter(|&k| is_late(k)).collect();
    assert!(!late_frames.is_empty());
    for (k, summary) in summaries.iter().enumerate() {
        let requested = summary.live_tracks + (summary.counts.tracks_deleted as usize)
            - (summary.counts.tracks_initiated as usize);
        let expected_missing = if is_late(k) { requested } else { 0 };
        assert_eq!(summary.counts.learned_predictions_missing as usize, expected_missing, "frame {k}");
        assert_eq!(
            (summary.counts.learned_predictions_rejected_non_finite as usize)
                + (summary.counts.learned_predictions_rejected_implausible as usize),
            0
        );
    }
    let stats = *tracker.predictor().stats();
    assert_eq!(stats.deadline_misses as usize, late_frames.len());
    assert_eq!(
        stats.stale_batches_discarded as usize,
        late_frames.len(),
        "every late batch came back and was discarded"
    );
    assert_eq!(stats.inference_hangs_detected, 0, "late, not hung");
    assert_eq!(stats.inference_panics, 0);
}

#[test]
fn a_hung_inference_thread_is_detected_and_counted_frames_go_on_without_pr_and_drop_does_not_wait_for_it() {
    let frames = frames();
    let hang = Selection { lanes: None, times_s: (1.5, f64::INFINITY) };
    let hang_from = frames.iter().position(|frame| hang.hits_frame(frame.timestamp_s)).unwrap();
    let mut threaded =
        ThreadedPredictor::new(FaultyPredictor::new(Behaviour::Hang, hang), GENEROUS_DEADLINE).unwrap();
    threaded.set_hang_threshold(Duration::from_millis(20));
    threaded.set_shutdown_wait(Duration::from_millis(50));
    let mut tracker = Tracker::with_predictor(pr_imm(), threaded).unwrap();
    let mut hung_seen_at = None;
    let summaries = run(
        &mut tracker,
        &frames,
        |k, tracker| {
            if k >= hang_from {
                tracker.predictor_mut().set_deadline(SHORT_DEADLINE);
                // Let the held batch age past the hang threshold between frames.
                std::thread::sleep(Duration::from_millis(25));
            }
        },
        |k, tracker| {
            if hung_seen_at.is_none() && tracker.predictor().is_inference_thread_hung() {
                hung_seen_at = Some(k);
            }
        },
    );
    for (k, summary) in summaries.iter().enumerate() {
        let requested = summary.live_tracks + (summary.counts.tracks_deleted as usize)
            - (summary.counts.tracks_initiated as usize);
        let expected_missing = if k >= hang_from { requested } else { 0 };
        assert_eq!(summary.counts.learned_predictions_missing as usize, expected_missing, "frame {k}");
    }
    let hung_seen_at = hung_seen_at.expect("the hang is detected");
    assert!(hung_seen_at > hang_from, "a hang is a batch held past the threshold, not a single miss");
    let stats = *tracker.predictor().stats();
    assert_eq!(stats.inference_hangs_detected, 1, "one episode, counted once");
    assert_eq!(stats.inference_hang_recoveries, 0);
    // The first two frames miss their deadline (both buffers go to the stuck thread), the rest
    // find no free buffer: none of them waited for the thread.
    assert_eq!(stats.deadline_misses, 2);
    assert_eq!(stats.frames_without_free_buffer as usize, frames.len() - hang_from - 2);
    let report = tracker.predictor().report().unwrap();
    assert!(report.contains("1 hangs detected") && report.contains("hung now"), "{report}");
    assert_eq!(tracker.stats().frames_with_learned_predictions_missing as usize, frames.len() - hang_from);

    // Dropping the tracker neither waits for the hung thread forever nor fails.
    let (dropped, was_dropped) = channel();
    std::thread::spawn(move || {
        drop(tracker);
        dropped.send(()).unwrap();
    });
    was_dropped.recv_timeout(Duration::from_secs(120)).expect("drop returns, detaching the hung thread");
}

#[test]
fn shutdown_joins_a_healthy_inference_thread_and_detaches_a_hung_one() {
    let healthy = ThreadedPredictor::new(
        FaultyPredictor::new(Behaviour::Hang, Selection { lanes: None, times_s: (1e9, 1e9) }),
        GENEROUS_DEADLINE,
    )
    .unwrap();
    assert_eq!(healthy.shutdown(), ShutdownOutcome::Joined);

    let mut hung = ThreadedPredictor::new(
        FaultyPredictor::new(Behaviour::Hang, Selection::everything()),
        GENEROUS_DEADLINE,
    )
    .unwrap();
    hung.set_shutdown_wait(Duration::from_millis(50));
    hung.set_deadline(SHORT_DEADLINE);
    let request = PredictionRequest { len: 1, prediction_time_s: 1.0, ..Default::default() };
    let mut out = [Some(Displacement::new(DVec2::ZERO))];
    hung.predict(&[request], &mut out);
    assert_eq!(out, [None]);
    assert_eq!(hung.stats().deadline_misses, 1);
    assert_eq!(hung.shutdown(), ShutdownOutcome::Detached);
}

#[test]
fn a_predictor_that_hangs_from_its_first_call_does_not_block_construction_and_is_reported_hung() {
    // Hangs even on the empty warm-up batch: construction gives up waiting after the default
    // hang threshold and reports the thread hung.
    struct HangsAlways;
    impl DisplacementPredictor for HangsAlways {
        fn submit(&mut self, _requests: &[PredictionRequest]) {
            loop {
                std::thread::park();
            }
        }
        fn collect(&mut self, _displacements: &mut [Option<Displacement>]) {}
    }
    let mut threaded = ThreadedPredictor::new(HangsAlways, SHORT_DEADLINE).unwrap();
    assert!(threaded.is_inference_thread_hung());
    assert_eq!(threaded.stats().inference_hangs_detected, 1);
    let request = PredictionRequest { len: 1, prediction_time_s: 1.0, ..Default::default() };
    let mut out = [Some(Displacement::new(DVec2::ZERO))];
    threaded.predict(&[request], &mut out);
    assert_eq!(out, [None], "the frame goes without and does not wait for the hung thread");
    assert_eq!(threaded.stats().inference_hangs_detected, 1, "still the same episode");
    threaded.set_shutdown_wait(Duration::from_millis(10));
    assert_eq!(threaded.shutdown(), ShutdownOutcome::Detached);
}

#[test]
fn a_panicking_inference_thread_retires_the_predictor_and_later_frames_go_without_pr_counted() {
    let frames = frames();
    let panic_at = Selection { lanes: None, times_s: (1.0, 1.05) };
    let panic_frame = frames.iter().position(|frame| panic_at.hits_frame(frame.timestamp_s)).unwrap();
    let threaded =
        ThreadedPredictor::new(FaultyPredictor::new(Behaviour::Panic, panic_at), GENEROUS_DEADLINE).unwrap();
    let mut tracker = Tracker::with_predictor(pr_imm(), threaded).unwrap();
    let summaries = run(&mut tracker, &frames, |_, _| {}, |_, _| {});
    for (k, summary) in summaries.iter().enumerate() {
        let requested = summary.live_tracks + (summary.counts.tracks_deleted as usize)
            - (summary.counts.tracks_initiated as usize);
        let expected_missing = if k >= panic_frame { requested } else { 0 };
        assert_eq!(summary.counts.learned_predictions_missing as usize, expected_missing, "frame {k}");
    }
    let stats = *tracker.predictor().stats();
    assert_eq!(stats.inference_panics, 1);
    assert_eq!(stats.frames_without_inference_thread as usize, frames.len() - panic_frame - 1);
    assert_eq!(stats.deadline_misses, 0, "the panic is reported at once, not by waiting");
    let report = tracker.predictor().report().unwrap();
    assert!(report.contains("1 inference panics"), "{report}");
    // The thread has ended: dropping joins it.
    assert_eq!(stats.inference_hangs_detected, 0);
}

#[test]
fn the_service_answers_every_frame_while_its_inference_thread_hangs_and_reports_the_hang() {
    use crate::common::service::{unique_prefix, TestClient};
    use primm_service::{ServiceNames, TrackingOptions, TrackingService, WaitMode};

    const FRAMES: u64 = 60;
    let names = ServiceNames::new(&unique_prefix("inference-hang"));
    let frames = frames();
    let client = TestClient::new(&names);
    let (ready, is_ready) = channel();
    let tracker_names = names.clone();
    let tracking = std::thread::spawn(move || {
        // Hangs from 1 s of frame time on; built on the tracking thread, as `primm serve` does.
        let hang = Selection { lanes: None, times_s: (1.0, f64::INFINITY) };
        let mut predictor =
            ThreadedPredictor::new(FaultyPredictor::new(Behaviour::Hang, hang), Duration::from_millis(50))
                .unwrap();
        predictor.set_hang_threshold(Duration::from_millis(20));
        predictor.set_shutdown_wait(Duration::from_millis(50));
        let tracker = Tracker::with_predictor(pr_imm(), predictor).unwrap();
        let options = TrackingOptions {
            names: tracker_names,
            wait: WaitMode::Event,
            latency_report_interval_frames: 0,
            poll_timeout: Duration::from_millis(20),
            ..TrackingOptions::default()
        };
        let mut service = TrackingService::new(tracker, options).unwrap();
        ready.send(()).unwrap();
        while service.counters().frames_received < FRAMES {
            service.poll(Duration::from_millis(20)).unwrap();
            check_tracker(service.tracker()).unwrap();
        }
        let predictor_stats = *service.tracker().predictor().stats();
        let tracker_stats = *service.tracker().stats();
        (*service.counters(), predictor_stats, tracker_stats, service.summary())
        // The service, its tracker and the hung thread's handle are dropped here.
    });
    is_ready.recv().unwrap();
    client.wait_for_tracker(Duration::from_secs(10));
    for k in 0..FRAMES {
        client.send(&frames[k as usize], k, 0);
        let sequence = client
            .next_answer(Duration::from_secs(30), |answer| answer.input_sequence)
            .expect("the tracker answers every frame");
        assert_eq!(sequence, k);
    }
    let (counters, predictor_stats, tracker_stats, summary) = tracking.join().expect("no panic, no abort");
    assert_eq!(counters.frames_tracked, FRAMES);
    assert_eq!(predictor_stats.inference_hangs_detected, 1, "{predictor_stats:?}");
    let hung_frames = frames.iter().take(FRAMES as usize).filter(|f| f.timestamp_s >= 1.0).count() as u64;
    assert!(tracker_stats.frames_with_learned_predictions_missing >= hung_frames, "{tracker_stats:?}");
    assert!(summary.contains("1 hangs detected"), "{summary}");
}
