//! Counting the hard association situations the paper evaluates separately (Section IV,
//! `tab:scenario_mot`): close proximity and crossing motion.

use serde::{Deserialize, Serialize};

use super::kinematics::wrap_angle;
use super::GeneratedSequence;

/// Two objects closer than this (centre to centre) are in close proximity, metres.
pub const CLOSE_PROXIMITY_DISTANCE_M: f64 = 4.0;
/// Two objects closer than this can be crossing, metres.
pub const CROSSING_DISTANCE_M: f64 = 8.0;
/// Smallest heading difference of crossing objects, degrees.
pub const CROSSING_MIN_HEADING_DIFF_DEG: f64 = 45.0;
/// Largest heading difference of crossing objects, degrees.
pub const CROSSING_MAX_HEADING_DIFF_DEG: f64 = 135.0;
/// Objects slower than this have no meaningful heading for the crossing test, m/s.
pub const MOVING_SPEED_MPS: f64 = 0.5;

/// Number of frames with each kind of situation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EventCounts {
    /// Frames in which some measured object has another object within
    /// [`CLOSE_PROXIMITY_DISTANCE_M`].
    pub close_proximity_frames: usize,
    /// Frames in which some measured, moving object has another moving object within
    /// [`CROSSING_DISTANCE_M`] whose heading differs by 45°–135°.
    pub crossing_frames: usize,
}

impl std::ops::AddAssign for EventCounts {
    fn add_assign(&mut self, other: Self) {
        self.close_proximity_frames += other.close_proximity_frames;
        self.crossing_frames += other.crossing_frames;
    }
}

/// Counts close-proximity and crossing frames of a generated sequence. A frame counts when at
/// least one object measured in it is in such a situation with any other existing object
/// (measured in that frame or not), judged on ground truth.
pub fn count_events(generated: &GeneratedSequence) -> EventCounts {
    let mut counts = EventCounts::default();
    let (min_diff, max_diff) =
        (CROSSING_MIN_HEADING_DIFF_DEG.to_radians(), CROSSING_MAX_HEADING_DIFF_DEG.to_radians());
    for (frame, truth) in generated.sequence.frames.iter().zip(&generated.truth) {
        let mut close = false;
        let mut crossing = false;
        for recorded in &frame.measurements {
            let Some(id) = recorded.measurement.ground_truth_id else {
                continue;
            };
            let Some(me) = truth.object(id) else { continue };
            for other in truth.objects.iter().filter(|o| o.id != id) {
                let distance = me.position.distance(other.position);
                if distance < CLOSE_PROXIMITY_DISTANCE_M {
                    close = true;
                }
                if distance < CROSSING_DISTANCE_M
                    && me.speed_mps > MOVING_SPEED_MPS
                    && other.speed_mps > MOVING_SPEED_MPS
                {
                    let diff = wrap_angle(me.heading_rad - other.heading_rad).abs();
                    if (min_diff..=max_diff).contains(&diff) {
                        crossing = true;
                    }
                }
            }
            if close && crossing {
                break;
            }
        }
        counts.close_proximity_frames += usize::from(close);
        counts.crossing_frames += usize::from(crossing);
    }
    counts
}
