//! A displacement predictor that knows the truth: the ceiling of any learned predictor.
//!
//! [`DisplacementOracle`] answers each [`PredictionRequest`] with the true motion of the
//! request's object over the tracker step (`step_start_s` to `prediction_time_s`), read from a
//! simulated sequence's true centres. Put in place of the PR model (`primm eval
//! --displacement-oracle`), it shows how good PR and PR-IMM could get with a perfect
//! displacement and everything else unchanged.
//!
//! * The request's object is the one whose measurement the track's latest history row is: the
//!   measurement of that time whose position (in the tracking frame) is within
//!   [`MATCH_TOLERANCE_M`] of the request's anchor. A track whose latest measurement has no
//!   ground truth (clutter) gets no answer, and its PR mode sits the step out.
//! * True centres are known only at the object's measurements; in between they are
//!   interpolated linearly, after the last one extrapolated with the last two samples' velocity
//!   (with one sample the object is taken to stand).
//! * Positions are in the tracker's frame: the world frame (each frame's ego pose applied to
//!   the vehicle-frame true centre) where the frames carry poses and the tracker tracks in the
//!   world frame, else the vehicle frame, which only sequences without poses allow (the
//!   vehicle frame moves with the ego, and its histories are not in one frame).
//!
//! [`DisplacementOracle::with_noise`] adds Gaussian noise of a given standard deviation to each
//! answer (each axis, independently per request, seeded by the request so that runs repeat): a
//! predictor of that accuracy whose errors are uncorrelated from step to step, which a trained
//! model's are not.
//!
//! The oracle is a diagnostic: it reads the future of the sequence.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, PoisonError};

use glam::DVec2;
use primm_core::config::CoordinateFrame;
use primm_core::predictor::{Displacement, DisplacementPredictor, PredictionRequest};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::io::Sequence;

/// Largest distance between a request's anchor and the measurement it is matched with, m.
pub const MATCH_TOLERANCE_M: f64 = 1e-6;

/// Largest difference between a request's anchor time and the measurement's frame time, s.
const TIME_TOLERANCE_S: f64 = 1e-9;

/// Why a sequence's truth cannot be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OracleError {
    /// No measurement of the sequence carries both a ground-truth id and a true centre.
    #[error("sequence {sequence} has no true object centres (only simulated data has them)")]
    NoTruth {
        /// Name of the sequence.
        sequence: String,
    },
    /// The frames carry ego poses but the tracker tracks in the vehicle frame, where a track's
    /// history is not in one frame.
    #[error("sequence {sequence} has ego poses and the tracking frame is `vehicle`: the oracle needs the world frame")]
    VehicleFrameWithPoses {
        /// Name of the sequence.
        sequence: String,
    },
}

/// One frame's time and its measurements' positions (tracking frame) with their objects.
type MeasuredFrame = (f64, Vec<(DVec2, Option<u64>)>);

/// The true centres of one sequence's objects, in the tracker's frame.
#[derive(Debug, Clone, Default)]
pub struct SequenceTruth {
    /// Per frame, in time order.
    frames: Vec<MeasuredFrame>,
    /// Per object: (time, true centre), in time order, one sample per time.
    objects: HashMap<u64, Vec<(f64, DVec2)>>,
}

impl SequenceTruth {
    /// The truth of `sequence` for a tracker that tracks in `tracking_frame`.
    pub fn new(sequence: &Sequence, tracking_frame: CoordinateFrame) -> Result<Self, OracleError> {
        let world = tracking_frame == CoordinateFrame::World;
        if !world && sequence.has_ego_pose() {
            return Err(OracleError::VehicleFrameWithPoses { sequence: sequence.name.clone() });
        }
        let mut truth = SequenceTruth::default();
        for frame in &sequence.frames {
            let transform = frame.ego_pose.filter(|_| world).map(|pose| pose.vehicle_to_world());
            let to_frame = |p: DVec2| transform.map_or(p, |t| t.apply_point(p));
            let mut measured = Vec::with_capacity(frame.measurements.len());
            for recorded in &frame.measurements {
                let id = recorded.measurement.ground_truth_id;
                measured.push((to_frame(recorded.measurement.position()), id));
                if let (Some(id), Some(centre)) = (id, recorded.true_position) {
                    let samples = truth.objects.entry(id).or_default();
                    if samples.last().is_none_or(|&(t, _)| frame.timestamp_s > t) {
                        samples.push((frame.timestamp_s, to_frame(centre)));
                    }
                }
            }
            truth.frames.push((frame.timestamp_s, measured));
        }
        if truth.objects.is_empty() {
            return Err(OracleError::NoTruth { sequence: sequence.name.clone() });
        }
        Ok(truth)
    }

    /// The object whose measurement at `time_s` lies at `position` (tracking frame), if any.
    pub fn object_at(&self, time_s: f64, position: DVec2) -> Option<u64> {
        let first = self.frames.partition_point(|(t, _)| *t < time_s - TIME_TOLERANCE_S);
        self.frames[first..]
            .iter()
            .take_while(|(t, _)| *t <= time_s + TIME_TOLERANCE_S)
            .flat_map(|(_, measured)| measured.iter())
            .find(|(p, _)| p.distance(position) <= MATCH_TOLERANCE_M)
            .and_then(|&(_, id)| id)
    }

    /// The true centre of object `id` at `time_s` (interpolated or extrapolated, see the module
    /// documentation).
    pub fn centre(&self, id: u64, time_s: f64) -> Option<DVec2> {
        let samples = self.objects.get(&id)?;
        if !time_s.is_finite() {
            return None;
        }
        let segment = match samples.len() {
            0 => return None,
            1 => return Some(samples[0].1),
            n => {
                let after = samples.partition_point(|(t, _)| *t <= time_s).clamp(1, n - 1);
                (samples[after - 1], samples[after])
            }
        };
        let ((t0, p0), (t1, p1)) = segment;
        Some(p0 + (p1 - p0) * ((time_s - t0) / (t1 - t0)))
    }

    /// The true motion of the request's object over the tracker step, if the object is known.
    pub fn displacement(&self, request: &PredictionRequest) -> Option<DVec2> {
        self.object_displacement(request).map(|(_, motion)| motion)
    }

    fn object_displacement(&self, request: &PredictionRequest) -> Option<(u64, DVec2)> {
        let id = self.object_at(request.anchor_time_s, request.anchor_m)?;
        Some((id, self.centre(id, request.prediction_time_s)? - self.centre(id, request.step_start_s)?))
    }
}

/// What the oracle did, summed over every batch since it was made.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct OracleCounts {
    /// Requests received.
    pub requests: u64,
    /// Requests answered with a true displacement.
    pub answered: u64,
}

#[derive(Debug, Default)]
struct Shared {
    truth: SequenceTruth,
    counts: OracleCounts,
}

/// The displacement oracle; clones share the truth and the counts, so the evaluation can hand
/// one to the tracker and set the sequence through another.
#[derive(Debug, Clone, Default)]
pub struct DisplacementOracle {
    shared: Arc<Mutex<Shared>>,
    pending: Vec<Option<Displacement>>,
    noise_std_m: f64,
    seed: u64,
}

impl DisplacementOracle {
    /// An oracle that knows nothing yet: it answers nothing until [`set_truth`](Self::set_truth).
    pub fn new() -> Self {
        Self::default()
    }

    /// An oracle whose answers carry Gaussian noise of `std_m` per axis (see the module
    /// documentation), drawn from `seed` and the request.
    ///
    /// # Panics
    /// When `std_m` is negative or not finite.
    pub fn with_noise(std_m: f64, seed: u64) -> Self {
        assert!(std_m.is_finite() && std_m >= 0.0, "noise standard deviation {std_m} m");
        Self { noise_std_m: std_m, seed, ..Self::default() }
    }

    /// Makes `truth` the sequence the oracle answers for (call it before tracking that sequence).
    pub fn set_truth(&self, truth: SequenceTruth) {
        self.shared.lock().unwrap_or_else(PoisonError::into_inner).truth = truth;
    }

    /// The counts so far.
    pub fn counts(&self) -> OracleCounts {
        self.shared.lock().unwrap_or_else(PoisonError::into_inner).counts
    }
}

impl DisplacementPredictor for DisplacementOracle {
    fn submit(&mut self, requests: &[PredictionRequest]) {
        let mut shared = self.shared.lock().unwrap_or_else(PoisonError::into_inner);
        self.pending.clear();
        let (std_m, seed) = (self.noise_std_m, self.seed);
        self.pending.extend(requests.iter().map(|request| {
            let (id, motion) = shared.truth.object_displacement(request)?;
            Some(Displacement::new(motion + noise(std_m, seed, id, request)))
        }));
        shared.counts.requests += requests.len() as u64;
        shared.counts.answered += self.pending.iter().filter(|d| d.is_some()).count() as u64;
    }

    fn collect(&mut self, displacements: &mut [Option<Displacement>]) {
        for (slot, answer) in
            displacements.iter_mut().zip(self.pending.iter().copied().chain(std::iter::repeat(None)))
        {
            *slot = answer;
        }
    }

    fn report(&self) -> Option<String> {
        let counts = self.counts();
        Some(format!("displacement oracle: {} of {} requests answered", counts.answered, counts.requests))
    }
}

/// Gaussian noise of `std_m` per axis for object `id` and `request`, drawn from `seed` and both.
fn noise(std_m: f64, seed: u64, id: u64, request: &PredictionRequest) -> DVec2 {
    if std_m == 0.0 {
        return DVec2::ZERO;
    }
    let key = [
        id,
        request.anchor_time_s.to_bits(),
        request.step_start_s.to_bits(),
        request.prediction_time_s.to_bits(),
    ]
    .iter()
    .fold(seed, |hash, value| split_mix(hash ^ value));
    let mut rng = ChaCha8Rng::seed_from_u64(key);
    let (x, y): (f64, f64) = (StandardNormal.sample(&mut rng), StandardNormal.sample(&mut rng));
    DVec2::new(x, y) * std_m
}

/// SplitMix64's finaliser: spreads the request's fields over the seed.
fn split_mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{RecordedFrame, RecordedMeasurement};
    use primm_core::measurement::{Measurement, ObjectClass};
    use primm_core::pose::EgoPose;

    fn measurement(x: f64, y: f64, id: Option<u64>) -> Measurement {
        Measurement {
            x_m: x,
            y_m: y,
            radial_velocity_mps: 0.0,
            rcs_dbsm: 0.0,
            class: ObjectClass::Car,
            sensor_id: Some(0),
            ground_truth_id: id,
        }
    }

    /// Object 1 moves at (10, 0) m/s from (20, 5), measured 0.5 m off its centre in x, every
    /// 0.1 s; a clutter point at (40, 40) in every frame. The ego stands at (100, 0), turned by
    /// 90 degrees, when `posed`.
    fn sequence(posed: bool) -> Sequence {
        let mut sequence = Sequence::new("oracle");
        for k in 0..5u64 {
            let t = 0.1 * k as f64;
            let centre = DVec2::new(20.0 + 10.0 * t, 5.0);
            sequence.frames.push(RecordedFrame {
                index: k,
                timestamp_s: t,
                sensor_id: Some(0),
                ego_pose: posed.then_some(EgoPose {
                    x_m: 100.0,
                    y_m: 0.0,
                    yaw_rad: std::f64::consts::FRAC_PI_2,
                }),
                measurements: vec![
                    RecordedMeasurement {
                        measurement: measurement(centre.x + 0.5, centre.y, Some(1)),
                        true_position: Some(centre),
                        true_velocity: None,
                        origin: None,
                    },
                    RecordedMeasurement {
                        measurement: measurement(40.0, 40.0, None),
                        true_position: None,
                        true_velocity: None,
                        origin: None,
                    },
                ],
            });
        }
        sequence
    }

    fn request(
        anchor: DVec2,
        anchor_time_s: f64,
        step_start_s: f64,
        prediction_time_s: f64,
    ) -> PredictionRequest {
        PredictionRequest {
            len: 1,
            anchor_m: anchor,
            anchor_time_s,
            step_start_s,
            prediction_time_s,
            ..Default::default()
        }
    }

    #[test]
    fn the_true_motion_is_interpolated_between_and_extrapolated_after_the_samples() {
        let truth = SequenceTruth::new(&sequence(false), CoordinateFrame::World).unwrap();
        // Anchor: the measurement of frame 2 (t = 0.2), at (22.5, 5).
        let step = request(DVec2::new(22.5, 5.0), 0.2, 0.2, 0.25);
        assert!(truth.displacement(&step).unwrap().abs_diff_eq(DVec2::new(0.5, 0.0), 1e-12));
        // Beyond the last sample (t = 0.4): the last segment's velocity.
        let late = request(DVec2::new(22.5, 5.0), 0.2, 0.4, 0.7);
        assert!(truth.displacement(&late).unwrap().abs_diff_eq(DVec2::new(3.0, 0.0), 1e-12));
        assert!(truth.centre(1, 0.05).unwrap().abs_diff_eq(DVec2::new(20.5, 5.0), 1e-12));
        // Clutter, an unknown position or time: no answer.
        assert_eq!(truth.displacement(&request(DVec2::new(40.0, 40.0), 0.2, 0.2, 0.25)), None);
        assert_eq!(truth.displacement(&request(DVec2::new(22.6, 5.0), 0.2, 0.2, 0.25)), None);
        assert_eq!(truth.displacement(&request(DVec2::new(22.5, 5.0), 0.15, 0.2, 0.25)), None);
    }

    #[test]
    fn in_the_world_frame_positions_and_motion_follow_the_ego_pose() {
        let truth = SequenceTruth::new(&sequence(true), CoordinateFrame::World).unwrap();
        // The vehicle-frame measurement (22.5, 5) seen from (100, 0) turned by 90 degrees.
        let anchor = DVec2::new(100.0 - 5.0, 22.5);
        let motion = truth.displacement(&request(anchor, 0.2, 0.2, 0.3)).unwrap();
        assert!(motion.abs_diff_eq(DVec2::new(0.0, 1.0), 1e-9), "{motion}");
        assert_eq!(
            SequenceTruth::new(&sequence(true), CoordinateFrame::Vehicle).unwrap_err(),
            OracleError::VehicleFrameWithPoses { sequence: "oracle".into() }
        );
        let mut blind = sequence(false);
        blind.frames.iter_mut().flat_map(|f| f.measurements.iter_mut()).for_each(|m| m.true_position = None);
        assert_eq!(
            SequenceTruth::new(&blind, CoordinateFrame::World).unwrap_err(),
            OracleError::NoTruth { sequence: "oracle".into() }
        );
    }

    #[test]
    fn the_oracle_answers_known_objects_counts_and_shares_its_truth_with_clones() {
        let oracle = DisplacementOracle::new();
        let mut handed_over = oracle.clone();
        let requests =
            [request(DVec2::new(22.5, 5.0), 0.2, 0.2, 0.3), request(DVec2::new(40.0, 40.0), 0.2, 0.2, 0.3)];
        let mut answers = [Some(Displacement::new(DVec2::ONE)); 2];
        handed_over.predict(&requests, &mut answers);
        assert_eq!(answers, [None, None], "no truth set yet");
        oracle.set_truth(SequenceTruth::new(&sequence(false), CoordinateFrame::World).unwrap());
        handed_over.predict(&requests, &mut answers);
        assert!(answers[0].unwrap().mean_m.abs_diff_eq(DVec2::new(1.0, 0.0), 1e-12));
        assert_eq!(answers[0].unwrap().covariance_m2, None);
        assert_eq!(answers[1], None);
        assert_eq!(oracle.counts(), OracleCounts { requests: 4, answered: 1 });
        assert_eq!(handed_over.report().unwrap(), "displacement oracle: 1 of 4 requests answered");
    }

    #[test]
    fn a_noisy_oracle_repeats_itself_and_has_the_asked_spread() {
        let truth = SequenceTruth::new(&sequence(false), CoordinateFrame::World).unwrap();
        let mut noisy = DisplacementOracle::with_noise(0.2, 7);
        noisy.set_truth(truth.clone());
        let mut again = DisplacementOracle::with_noise(0.2, 7);
        again.set_truth(truth);
        // 2000 requests at different prediction times; the true motion is (10 m/s) x horizon.
        let requests: Vec<_> = (0..2000)
            .map(|k| request(DVec2::new(22.5, 5.0), 0.2, 0.2, 0.2 + 1e-4 * (k + 1) as f64))
            .collect();
        let (mut first, mut second) = (vec![None; requests.len()], vec![None; requests.len()]);
        noisy.predict(&requests, &mut first);
        again.predict(&requests, &mut second);
        assert_eq!(first, second);
        let errors: Vec<DVec2> = first
            .iter()
            .zip(&requests)
            .map(|(d, r)| d.unwrap().mean_m - DVec2::new(10.0 * (r.prediction_time_s - 0.2), 0.0))
            .collect();
        let n = errors.len() as f64;
        let mean = errors.iter().copied().sum::<DVec2>() / n;
        let rms = (errors.iter().map(|e| e.length_squared()).sum::<f64>() / (2.0 * n)).sqrt();
        assert!(mean.length() < 0.02, "{mean}");
        assert!((rms - 0.2).abs() < 0.01, "{rms}");
    }
}
