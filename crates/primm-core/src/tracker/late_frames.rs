//! Frames in order and late frames: every frame is recorded once, tracked, and kept in the
//! replay ring with the state before it, so that a late frame can be tracked in its place
//! (`crate::replay`).

use super::{StepError, StepSummary, Tracker};
use crate::measurement::FrameView;
use crate::predictor::DisplacementPredictor;
use crate::replay::Placement;
use crate::stage_timing::StageObserver;
use crate::validation::FrameError;

impl<P: DisplacementPredictor> Tracker<P> {
    /// Everything but the report; counts what the step did into
    /// [`last_step`](Self::last_step) and the statistics, also when it fails. Reads `frame`
    /// once, into the tracker's own copy; a late frame is tracked in its place
    /// (`crate::replay`).
    pub(super) fn advance<F: FrameView + ?Sized, O: StageObserver>(
        &mut self,
        frame: &F,
        observer: &mut O,
    ) -> Result<(), StepError> {
        self.recorded.read_from(frame);
        match self.ring.place(self.recorded.timestamp_s(), self.last_timestamp_s) {
            Placement::InOrder | Placement::Duplicate => self.track_in_order(observer),
            Placement::Before(position) => self.track_late(position, observer),
            Placement::TooLate => {
                self.last_step = StepSummary::default();
                self.count_live_tracks();
                self.last_step.counts.frames_rejected_too_late = 1;
                self.stats.add(&self.last_step.counts);
                Err(StepError::InvalidFrame(FrameError::TooLate {
                    timestamp_s: self.recorded.timestamp_s(),
                    newest_s: self.last_timestamp_s.unwrap_or(f64::NAN),
                }))
            }
        }
    }

    /// Tracks the recorded frame after the newest one, first saving the state before it in the
    /// ring (and recording the frame there once tracked).
    pub(super) fn track_in_order<O: StageObserver>(&mut self, observer: &mut O) -> Result<(), StepError> {
        if !self.ring.is_enabled() {
            return self.track_recorded(observer);
        }
        let slot = self.ring.spare();
        self.save_state(slot);
        let result = self.track_recorded(observer);
        if result.is_ok() {
            core::mem::swap(&mut self.recorded, &mut self.ring.slot_mut(slot).frame);
            self.ring.insert(slot, self.ring.len());
            self.ring.trim(self.recorded_newest_s());
        }
        result
    }

    /// Tracks a late recorded frame in its place, before the recorded frame at `position`:
    /// back to the state before that frame, the late frame, then every newer recorded frame
    /// again. The frame is checked against its place first, so that a frame refused there
    /// changes nothing.
    pub(super) fn track_late<O: StageObserver>(
        &mut self,
        position: usize,
        observer: &mut O,
    ) -> Result<(), StepError> {
        let newer = self.ring.slot_at(position);
        let newest_s = self.last_timestamp_s;
        self.last_step = StepSummary::default();
        self.last_timestamp_s = self.ring.slot(newer).before.last_timestamp_s;
        let check = self.validate();
        self.last_timestamp_s = newest_s;
        if let Err(error) = check {
            self.count_live_tracks();
            self.stats.add(&self.last_step.counts);
            return Err(error);
        }
        self.restore_state(newer);
        let late = self.ring.spare();
        self.ring.copy_snapshot(newer, late);
        let result = self.track_recorded(observer);
        let mut summary = self.last_step;
        let mut next = position;
        self.late_outputs.clear();
        if result.is_ok() {
            self.keep_late_outputs();
            core::mem::swap(&mut self.recorded, &mut self.ring.slot_mut(late).frame);
            self.ring.insert(late, position);
            summary.counts.late_frames_tracked = 1;
            next += 1;
        }
        while next < self.ring.len() {
            let slot = self.ring.slot_at(next);
            self.save_state(slot);
            core::mem::swap(&mut self.recorded, &mut self.ring.slot_mut(slot).frame);
            let replayed = self.track_recorded(observer);
            core::mem::swap(&mut self.recorded, &mut self.ring.slot_mut(slot).frame);
            if replayed.is_ok() {
                summary.counts.frames_replayed += 1;
                next += 1;
            } else {
                // Cannot happen for a frame tracked before (its interval only shrank); it is
                // dropped from the ring rather than tracked half.
                self.ring.remove(next);
            }
        }
        self.ring.trim(self.recorded_newest_s());
        self.stats.late_frames_tracked += summary.counts.late_frames_tracked;
        self.stats.frames_replayed += summary.counts.frames_replayed;
        self.last_step = summary;
        self.count_live_tracks();
        result
    }

    /// The report of the late frame just tracked, into `late_outputs` (whose room was reserved
    /// when the tracker was built).
    fn keep_late_outputs(&mut self) {
        let outputs = &mut self.late_outputs;
        let to_vehicle = self.step_pose.map(|pose| pose.world_to_vehicle());
        let t = self.last_timestamp_s.unwrap_or(0.0);
        super::report(&self.table, &self.rows[..], &self.imms, to_vehicle, t, |output| outputs.push(*output));
    }

    /// The newest tracked frame's time, s (0 before the first).
    pub(super) fn recorded_newest_s(&self) -> f64 {
        self.last_timestamp_s.unwrap_or(0.0)
    }

    /// Saves the state before the next frame into ring slot `slot`.
    pub(super) fn save_state(&mut self, slot: usize) {
        let before = &mut self.ring.slot_mut(slot).before;
        before.next_id = self.table.save(&mut before.tracks);
        before.last_timestamp_s = self.last_timestamp_s;
        before.tracks_frame = self.tracks_frame;
        before.last_pose = self.last_pose;
        before.ego_motion = self.ego_motion;
        before.stats = self.stats;
        before.sensors = Some(*self.sensors);
    }

    /// Puts the tracker back into the state saved in ring slot `slot`.
    pub(super) fn restore_state(&mut self, slot: usize) {
        let before = &self.ring.slot(slot).before;
        self.table.restore(&before.tracks, before.next_id);
        self.last_timestamp_s = before.last_timestamp_s;
        self.tracks_frame = before.tracks_frame;
        self.last_pose = before.last_pose;
        self.ego_motion = before.ego_motion;
        self.stats.restore_tracked_counts(&before.stats);
        if let Some(sensors) = &before.sensors {
            *self.sensors = *sensors;
        }
    }

    /// Tracks the recorded frame; counts what it did into [`last_step`](Self::last_step) and
    /// the statistics, also when it fails.
    pub(super) fn track_recorded<O: StageObserver>(&mut self, observer: &mut O) -> Result<(), StepError> {
        self.last_step = StepSummary::default();
        let result = self.run_stages(observer);
        self.count_live_tracks();
        self.stats.add(&self.last_step.counts);
        result
    }

    /// The live and confirmed tracks into [`last_step`](Self::last_step).
    pub(super) fn count_live_tracks(&mut self) {
        self.last_step.live_tracks = self.table.len();
        self.last_step.confirmed_tracks =
            self.table.tracks().iter().filter(|track| track.status.is_confirmed()).count();
    }
}
