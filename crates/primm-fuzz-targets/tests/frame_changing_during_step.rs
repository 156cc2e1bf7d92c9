//! A frame read in place from shared memory may change while the tracker steps it: a hostile
//! publisher can keep writing into a sample after sending it. The tracker must read each field
//! once, so that what it validated is what it tracks.

use primm_core::config::Config;
use primm_core::invariants::check_tracker;
use primm_core::measurement::{Frame, FrameView, Measurement, ObjectClass, UnknownClass};
use primm_core::mode::Method;
use primm_core::tracker::Tracker;
use std::cell::Cell;

fn car(x_m: f64) -> Measurement {
    Measurement {
        x_m,
        y_m: 1.0,
        radial_velocity_mps: 5.0,
        rcs_dbsm: 3.0,
        class: ObjectClass::Car,
        sensor_id: Some(0),
        ground_truth_id: None,
    }
}

/// Answers its first read of every field honestly, then turns hostile: a count far beyond the
/// capacity, a NaN timestamp and NaN measurements.
struct ChangingFrame {
    timestamp_s: f64,
    honest: Vec<Measurement>,
    length_reads: Cell<usize>,
    timestamp_reads: Cell<usize>,
    measurement_reads: Vec<Cell<usize>>,
}

impl ChangingFrame {
    fn new(timestamp_s: f64, honest: Vec<Measurement>) -> Self {
        let measurement_reads = honest.iter().map(|_| Cell::new(0)).collect();
        Self {
            timestamp_s,
            honest,
            length_reads: Cell::new(0),
            timestamp_reads: Cell::new(0),
            measurement_reads,
        }
    }

    fn first_read(counter: &Cell<usize>) -> bool {
        counter.set(counter.get() + 1);
        counter.get() == 1
    }
}

impl FrameView for ChangingFrame {
    fn timestamp_s(&self) -> f64 {
        if Self::first_read(&self.timestamp_reads) {
            self.timestamp_s
        } else {
            f64::NAN
        }
    }

    fn len(&self) -> usize {
        if Self::first_read(&self.length_reads) {
            self.honest.len()
        } else {
            100_000
        }
    }

    fn measurement(&self, index: usize) -> Result<Measurement, UnknownClass> {
        let honest = *self.honest.get(index).ok_or(UnknownClass { code: 255 })?;
        if Self::first_read(&self.measurement_reads[index]) {
            Ok(honest)
        } else {
            Ok(Measurement { x_m: f64::NAN, y_m: f64::INFINITY, ..honest })
        }
    }
}

#[test]
fn a_frame_rewritten_after_validation_is_tracked_as_it_was_validated() {
    let mut tracker = Tracker::new(Config::default().with_modes(Method::Imm.modes())).unwrap();
    for k in 0..3 {
        let mut frame = Frame::new(0.05 * k as f64);
        frame.measurements.push(car(10.0 + 0.25 * k as f64));
        frame.measurements.push(car(30.0));
        tracker.step(&frame).unwrap();
    }
    let changing = ChangingFrame::new(0.15, vec![car(10.75), car(30.0), car(50.0)]);
    let summary = tracker.step_into(&changing, |_| {}).expect("the frame was valid when read");

    assert_eq!(summary.counts.measurements_accepted, 3);
    assert_eq!(changing.length_reads.get(), 1, "the count is read once");
    assert_eq!(changing.timestamp_reads.get(), 1, "the timestamp is read once");
    assert!(changing.measurement_reads.iter().all(|reads| reads.get() == 1), "each measurement is read once");
    assert_eq!(check_tracker(&tracker), Ok(()));
    let latest_update_s =
        tracker.tracks().iter().map(|track| track.last_update_s).fold(f64::NEG_INFINITY, f64::max);
    assert_eq!(latest_update_s, 0.15, "tracks updated at the time read during validation");
    assert_eq!(tracker.tracks().len(), 3, "two updated tracks and one new one");
}
