//! Target `tracker_steps`: IMM and PR-IMM trackers stepped on frame sequences built from the
//! fuzzer's bytes with `arbitrary`, the invariants checked after every step.

use crate::invariant_check::assert_tracker_invariants;
use crate::scripted_predictor::ScriptedPredictor;
use arbitrary::{Arbitrary, Unstructured};
use glam::{DMat2, DVec2};
use primm_core::config::Config;
use primm_core::measurement::{
    FrameView, Measurement, ObjectClass, UnknownClass, MAX_MEASUREMENTS_PER_FRAME,
};
use primm_core::mode::Method;
use primm_core::pose::EgoPose;
use primm_core::predictor::Displacement;
use primm_core::predictor::DisplacementPredictor;
use primm_core::tracker::Tracker;

/// Most frames one input is turned into.
pub const MAX_FRAMES: usize = 64;

/// A value of a measurement field: typical radar values and every kind of hostile float.
#[derive(Debug, Clone, Copy, Arbitrary)]
pub enum FuzzValue {
    /// A typical value: `raw / 64`, within ±512.
    Typical(i16),
    /// NaN.
    NotANumber,
    /// +∞.
    PositiveInfinity,
    /// −∞.
    NegativeInfinity,
    /// The smallest positive subnormal times `multiple`, with the given sign.
    Subnormal {
        /// Multiple of the smallest subnormal.
        multiple: u16,
        /// Whether the value is negative.
        negative: bool,
    },
    /// Near the largest finite value: `±1e308 × (1 + fraction / 2^16)` (can overflow to ∞).
    NearLargest {
        /// Fractional excess over 1e308, in 1/65536.
        fraction: u16,
        /// Whether the value is negative.
        negative: bool,
    },
    /// Any bit pattern.
    Bits(u64),
}

impl FuzzValue {
    /// The value.
    pub fn value(self) -> f64 {
        match self {
            FuzzValue::Typical(raw) => f64::from(raw) / 64.0,
            FuzzValue::NotANumber => f64::NAN,
            FuzzValue::PositiveInfinity => f64::INFINITY,
            FuzzValue::NegativeInfinity => f64::NEG_INFINITY,
            FuzzValue::Subnormal { multiple, negative } => {
                signed(f64::from_bits(1) * f64::from(multiple), negative)
            }
            FuzzValue::NearLargest { fraction, negative } => {
                signed(1e308 * (1.0 + f64::from(fraction) / 65536.0), negative)
            }
            FuzzValue::Bits(bits) => f64::from_bits(bits),
        }
    }
}

fn signed(value: f64, negative: bool) -> f64 {
    if negative {
        -value
    } else {
        value
    }
}

/// The time from one frame to the next.
#[derive(Debug, Clone, Copy, Arbitrary)]
pub enum FuzzTimeStep {
    /// A typical radar interval: `(1 + raw) ms`, 1 ms to 256 ms.
    Typical(u8),
    /// 1 ns.
    Nanosecond,
    /// Exactly the configured `tracker.max_frame_interval_s`.
    AtLimit,
    /// `(1 + raw)` times the configured limit, just beyond it and far beyond it.
    BeyondLimit(u8),
    /// The same time as the previous frame.
    Zero,
    /// Back in time by `(1 + raw) ms`.
    Backwards(u8),
    /// An arbitrary step (any float, non-finite included).
    Raw(FuzzValue),
}

/// One measurement as the fuzzer describes it.
#[derive(Debug, Clone, Copy, Arbitrary)]
pub struct FuzzMeasurement {
    /// x position, m.
    pub x: FuzzValue,
    /// y position, m.
    pub y: FuzzValue,
    /// Radial velocity, m/s.
    pub radial_velocity: FuzzValue,
    /// RCS, dBsm.
    pub rcs: FuzzValue,
    /// Class code; codes beyond the known classes are rejected by the tracker.
    pub class_code: u8,
    /// Sensor id, any value.
    pub sensor_id: Option<u16>,
    /// Repeat the frame's previous measurement exactly instead (duplicate positions).
    pub duplicate_previous: bool,
}

/// One frame as the fuzzer describes it.
#[derive(Debug, Clone, Arbitrary)]
pub struct FuzzFrame {
    /// Time since the previous frame (the first frame's time is `start`).
    pub time_step: FuzzTimeStep,
    /// The measurements; only the first [`MAX_MEASUREMENTS_PER_FRAME`] are used.
    pub measurements: Vec<FuzzMeasurement>,
    /// Copy the frame's first measurement until the frame holds this many (`× 2`, up to 510),
    /// so that full frames, and frames over the capacity the tracker must reject, are cheap to
    /// reach.
    pub repeat_first_to: u8,
    /// Reset both trackers before the frame.
    pub reset_before: bool,
    /// The ego pose `(x, y, yaw)` the frame carries, if any: the trackers run in the world
    /// frame, so a pose that comes, goes or is hostile moves or rejects the tracks.
    pub ego_pose: Option<(FuzzValue, FuzzValue, FuzzValue)>,
}

/// One answer of the scripted predictor.
#[derive(Debug, Clone, Copy, Arbitrary)]
pub struct FuzzDisplacement {
    /// x component, m.
    pub dx: FuzzValue,
    /// y component, m.
    pub dy: FuzzValue,
    /// The covariance's entries `[xx, yx, xy, yy]`, m², if the answer has one: any values,
    /// asymmetric and indefinite included.
    pub covariance: Option<[FuzzValue; 4]>,
}

impl FuzzDisplacement {
    /// The predictor's answer.
    pub fn displacement(self) -> Displacement {
        Displacement {
            mean_m: DVec2::new(self.dx.value(), self.dy.value()),
            covariance_m2: self.covariance.map(|[xx, yx, xy, yy]| {
                DMat2::from_cols(DVec2::new(xx.value(), yx.value()), DVec2::new(xy.value(), yy.value()))
            }),
            from_latest_m: None,
        }
    }
}

/// A whole input: the predictor's script, the start time and the frames.
#[derive(Debug, Clone, Arbitrary)]
pub struct FuzzScenario {
    /// The PR-IMM tracker's predictor answers, cycled; `None` entries mean "no prediction".
    pub displacements: Vec<Option<FuzzDisplacement>>,
    /// The first frame's time, s.
    pub start: FuzzValue,
    /// The frames, at most [`MAX_FRAMES`] used.
    pub frames: Vec<FuzzFrame>,
}

/// A frame whose class codes are raw bytes, read by the tracker through [`FrameView`].
#[derive(Debug, Clone, Default)]
pub struct CodedFrame {
    /// Frame time, s.
    pub timestamp_s: f64,
    /// Measurements with the class code each carries on the wire.
    pub measurements: Vec<(Measurement, u8)>,
    /// The ego pose, if the frame carries one.
    pub ego_pose: Option<EgoPose>,
}

impl FrameView for CodedFrame {
    fn timestamp_s(&self) -> f64 {
        self.timestamp_s
    }
    fn len(&self) -> usize {
        self.measurements.len()
    }
    fn measurement(&self, index: usize) -> Result<Measurement, UnknownClass> {
        let (measurement, code) = self.measurements[index];
        let class = ObjectClass::from_code(code).ok_or(UnknownClass { code })?;
        Ok(Measurement { class, ..measurement })
    }
    fn ego_pose(&self) -> Option<EgoPose> {
        self.ego_pose
    }
}

/// Builds the scenario from `data` and steps an IMM tracker and a PR-IMM tracker (its
/// predictor scripted by the input) through every frame, checking the invariants after each
/// step, rejected or not.
pub fn run(data: &[u8]) {
    let Ok(scenario) = FuzzScenario::arbitrary_take_rest(Unstructured::new(data)) else { return };
    let script =
        scenario.displacements.iter().map(|answer| answer.map(FuzzDisplacement::displacement)).collect();
    let imm_config = Config::default().with_modes(Method::Imm.modes());
    let pr_imm_config = Config::default().with_modes(Method::PrImm.modes());
    let limit_s = imm_config.tracker.max_frame_interval_s;
    let mut imm = Tracker::new(imm_config).expect("the default configuration is valid");
    let mut pr_imm = Tracker::with_predictor(pr_imm_config, ScriptedPredictor::new(script))
        .expect("the default configuration is valid");

    let mut timestamp_s = scenario.start.value();
    for (index, fuzz_frame) in scenario.frames.iter().take(MAX_FRAMES).enumerate() {
        if index > 0 {
            timestamp_s += time_step_s(fuzz_frame.time_step, limit_s);
        }
        let frame = coded_frame(fuzz_frame, timestamp_s);
        if fuzz_frame.reset_before {
            imm.reset();
            pr_imm.reset();
        }
        step_and_check(&mut imm, &frame, "IMM");
        step_and_check(&mut pr_imm, &frame, "PR-IMM");
    }
}

fn step_and_check<P: DisplacementPredictor>(tracker: &mut Tracker<P>, frame: &CodedFrame, name: &str) {
    // A rejected frame is a valid outcome; the invariants must hold either way.
    let _ = tracker.step(frame);
    assert_tracker_invariants(tracker, name);
}

fn time_step_s(step: FuzzTimeStep, limit_s: f64) -> f64 {
    match step {
        FuzzTimeStep::Typical(raw) => (1.0 + f64::from(raw)) * 1e-3,
        FuzzTimeStep::Nanosecond => 1e-9,
        FuzzTimeStep::AtLimit => limit_s,
        FuzzTimeStep::BeyondLimit(raw) => limit_s * (1.0 + f64::from(raw)) + 1e-9,
        FuzzTimeStep::Zero => 0.0,
        FuzzTimeStep::Backwards(raw) => -(1.0 + f64::from(raw)) * 1e-3,
        FuzzTimeStep::Raw(value) => value.value(),
    }
}

fn coded_frame(fuzz_frame: &FuzzFrame, timestamp_s: f64) -> CodedFrame {
    let ego_pose = fuzz_frame.ego_pose.map(|(x, y, yaw)| EgoPose {
        x_m: x.value(),
        y_m: y.value(),
        yaw_rad: yaw.value(),
    });
    let mut frame = CodedFrame { timestamp_s, measurements: Vec::new(), ego_pose };
    for fuzz in fuzz_frame.measurements.iter().take(MAX_MEASUREMENTS_PER_FRAME) {
        let entry = match frame.measurements.last() {
            Some(previous) if fuzz.duplicate_previous => *previous,
            _ => (
                Measurement {
                    x_m: fuzz.x.value(),
                    y_m: fuzz.y.value(),
                    radial_velocity_mps: fuzz.radial_velocity.value(),
                    rcs_dbsm: fuzz.rcs.value(),
                    class: ObjectClass::Car,
                    sensor_id: fuzz.sensor_id,
                    ground_truth_id: None,
                },
                fuzz.class_code,
            ),
        };
        frame.measurements.push(entry);
    }
    let wanted = usize::from(fuzz_frame.repeat_first_to) * 2;
    if let Some(&first) = frame.measurements.first() {
        while frame.measurements.len() < wanted {
            frame.measurements.push(first);
        }
    }
    frame
}
