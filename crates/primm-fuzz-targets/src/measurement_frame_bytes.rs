//! Target `measurement_frame_bytes`: raw `MeasurementFrame`s as a hostile local publisher could
//! write them into shared memory, put through the service's own frame path
//! ([`primm_service::frame_step`]).

use crate::extrapolating_predictor::ExtrapolatingPredictor;
use crate::invariant_check::assert_tracker_invariants;
use primm_core::config::Config;
use primm_core::mode::Method;
use primm_core::predictor::DisplacementPredictor;
use primm_core::stage_timing::NoObserver;
use primm_core::tracker::Tracker;
use primm_service::frame_step::{starts_stream, step_received_frame};
use primm_wire::{MeasurementFrame, TrackFrame, TrackFrameWriter};
use std::mem::{size_of, MaybeUninit};

/// Most frames one input is turned into.
pub const MAX_FRAMES: usize = 64;

/// Reads `data` as a sequence of writes into one shared-memory frame: each record is a
/// little-endian `u16` length `n` followed by `n` bytes (fewer at the end of the input) that
/// overwrite the frame from its first byte; the bytes beyond stay as the previous write left
/// them, as in a reused shared-memory chunk. Every field can so take any bit pattern: a count
/// beyond the capacity, unknown class codes and flags, NaN or infinite values and times.
///
/// After each write the frame goes through the service's path — a stream-start flag resets the
/// tracker ([`starts_stream`]), then [`step_received_frame`] steps it (resetting after a gap)
/// and writes the answer into a track frame — for an IMM tracker and for a PR-IMM tracker whose
/// predictor extrapolates the frames' own positions. The invariants are checked after each.
pub fn run(data: &[u8]) {
    let mut frame = MeasurementFrame::boxed_zeroed();
    let mut answer = Box::<TrackFrame>::new_uninit();
    let mut imm = Tracker::new(Config::default().with_modes(Method::Imm.modes()))
        .expect("the default configuration is valid");
    let mut pr_imm = Tracker::with_predictor(
        Config::default().with_modes(Method::PrImm.modes()),
        ExtrapolatingPredictor::default(),
    )
    .expect("the default configuration is valid");

    let mut rest = data;
    for _ in 0..MAX_FRAMES {
        let Some((length, tail)) = rest.split_first_chunk::<2>() else { break };
        let length =
            usize::from(u16::from_le_bytes(*length)).min(tail.len()).min(size_of::<MeasurementFrame>());
        let (bytes, tail) = tail.split_at(length);
        overwrite_frame(&mut frame, bytes);
        rest = tail;
        receive(&mut imm, &frame, &mut answer, "IMM");
        receive(&mut pr_imm, &frame, &mut answer, "PR-IMM");
    }
}

/// Copies `bytes` over the start of `frame`'s memory.
fn overwrite_frame(frame: &mut MeasurementFrame, bytes: &[u8]) {
    assert!(bytes.len() <= size_of::<MeasurementFrame>());
    // SAFETY: `bytes` fits in the frame, the two do not overlap (`frame` is borrowed mutably),
    // and every field of `MeasurementFrame` is an integer, a float or an array of them, for which
    // any bit pattern is a valid value.
    unsafe {
        std::ptr::copy_nonoverlapping(
            bytes.as_ptr(),
            (frame as *mut MeasurementFrame).cast::<u8>(),
            bytes.len(),
        );
    }
}

fn receive<P: DisplacementPredictor>(
    tracker: &mut Tracker<P>,
    frame: &MeasurementFrame,
    answer: &mut MaybeUninit<TrackFrame>,
    name: &str,
) {
    if starts_stream(frame) {
        tracker.reset();
    }
    let mut writer = Some(TrackFrameWriter::new(answer));
    let stepped = step_received_frame(tracker, frame, &mut NoObserver, &mut writer);
    let written = writer.map_or(0, |writer| writer.len());
    if let Ok(summary) = stepped.result {
        assert_eq!(written, summary.live_tracks.min(primm_wire::TRACK_CAPACITY), "{name}: tracks written");
    }
    assert_tracker_invariants(tracker, name);
}
