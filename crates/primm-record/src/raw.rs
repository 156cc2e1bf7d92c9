//! The wire payloads as message bytes, and back.
//!
//! A payload is the `#[repr(C)]` bytes of the wire type (little-endian, as on the host that
//! recorded it), cut after the last valid entry: a `TrackFrame` with 3 tracks takes its header
//! and 3 × 424 bytes instead of 217 168. Every primm wire type has its array of entries last and
//! no implicit padding, so the bytes are fully defined and a reader restores the frame by
//! copying them into a zeroed frame.

use core::mem::{offset_of, size_of};
use primm_wire::{
    LatencyReport, MeasurementFrame, TrackFrame, WireMeasurement, WireTrack, MEASUREMENT_CAPACITY,
    TRACK_CAPACITY,
};

mod sealed {
    pub trait Sealed {}
}

/// A primm wire type recorded as bytes.
///
/// # Safety
///
/// Implementors are `#[repr(C)]` types made only of integers, floats and arrays of them, without
/// implicit padding (every byte is defined, every bit pattern is a valid value), whose entries
/// (if any) form the type's last field and start at [`HEADER_BYTES`](Self::HEADER_BYTES).
pub unsafe trait WirePayload: sealed::Sealed + Sized {
    /// The iceoryx2 type name.
    const TYPE_NAME: &'static str;
    /// Bytes before the first entry (the whole type for a type without entries).
    const HEADER_BYTES: usize;
    /// Bytes of one entry (0: no entries).
    const ENTRY_BYTES: usize;
    /// Entry slots.
    const CAPACITY: usize;
    /// Entries the header claims (untrusted).
    fn claimed_entries(&self) -> usize;
}

impl sealed::Sealed for MeasurementFrame {}
impl sealed::Sealed for TrackFrame {}
impl sealed::Sealed for LatencyReport {}

// SAFETY: see the wire crate: `#[repr(C)]`, explicit padding, plain fields; `measurements` last.
unsafe impl WirePayload for MeasurementFrame {
    const TYPE_NAME: &'static str = "primm::MeasurementFrame";
    const HEADER_BYTES: usize = offset_of!(MeasurementFrame, measurements);
    const ENTRY_BYTES: usize = size_of::<WireMeasurement>();
    const CAPACITY: usize = MEASUREMENT_CAPACITY;
    fn claimed_entries(&self) -> usize {
        self.count as usize
    }
}

// SAFETY: as above; `tracks` last.
unsafe impl WirePayload for TrackFrame {
    const TYPE_NAME: &'static str = "primm::TrackFrame";
    const HEADER_BYTES: usize = offset_of!(TrackFrame, tracks);
    const ENTRY_BYTES: usize = size_of::<WireTrack>();
    const CAPACITY: usize = TRACK_CAPACITY;
    fn claimed_entries(&self) -> usize {
        self.count as usize
    }
}

// SAFETY: as above; recorded whole (its stage array is small).
unsafe impl WirePayload for LatencyReport {
    const TYPE_NAME: &'static str = "primm::LatencyReport";
    const HEADER_BYTES: usize = size_of::<LatencyReport>();
    const ENTRY_BYTES: usize = 0;
    const CAPACITY: usize = 0;
    fn claimed_entries(&self) -> usize {
        0
    }
}

const _: () = assert!(
    MeasurementFrame::HEADER_BYTES + MEASUREMENT_CAPACITY * size_of::<WireMeasurement>()
        == size_of::<MeasurementFrame>()
);
const _: () =
    assert!(TrackFrame::HEADER_BYTES + TRACK_CAPACITY * size_of::<WireTrack>() == size_of::<TrackFrame>());

/// The payload bytes of `value`: its header and its valid entries (at most the capacity).
pub fn payload_bytes<T: WirePayload>(value: &T) -> &[u8] {
    let entries = value.claimed_entries().min(T::CAPACITY);
    let length = T::HEADER_BYTES + entries * T::ENTRY_BYTES;
    // SAFETY: `length` is at most `size_of::<T>()` (header plus at most every slot), and every
    // byte of `T` is defined (the trait's contract).
    unsafe { core::slice::from_raw_parts((value as *const T).cast::<u8>(), length) }
}

/// Why payload bytes are not a frame of the expected type.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RawPayloadError {
    /// Fewer bytes than the type's header.
    #[error("a {type_name} payload of {length} bytes is shorter than its {header} byte header")]
    TooShort {
        /// The wire type.
        type_name: &'static str,
        /// The payload's length.
        length: usize,
        /// The header's length.
        header: usize,
    },
    /// The bytes after the header are not a whole number of entries within the capacity.
    #[error("a {type_name} payload of {length} bytes is not a {header} byte header plus at most {capacity} entries of {entry} bytes")]
    BadLength {
        /// The wire type.
        type_name: &'static str,
        /// The payload's length.
        length: usize,
        /// The header's length.
        header: usize,
        /// One entry's length.
        entry: usize,
        /// The entry slots.
        capacity: usize,
    },
    /// The header's count disagrees with the entries present.
    #[error("a {type_name} payload claims {claimed} entries but carries {present}")]
    CountMismatch {
        /// The wire type.
        type_name: &'static str,
        /// The header's count.
        claimed: usize,
        /// Entries in the payload.
        present: usize,
    },
}

/// Copies payload `bytes` into `frame` (its header and entries; slots past them keep their
/// bytes), after checking that they are a header and whole entries that the header counts.
pub fn read_payload<T: WirePayload>(bytes: &[u8], frame: &mut T) -> Result<(), RawPayloadError> {
    let (type_name, header, entry, capacity) = (T::TYPE_NAME, T::HEADER_BYTES, T::ENTRY_BYTES, T::CAPACITY);
    let length = bytes.len();
    if length < header {
        return Err(RawPayloadError::TooShort { type_name, length, header });
    }
    let rest = length - header;
    let (present, whole) = match rest.checked_div(entry) {
        Some(present) => (present, rest.is_multiple_of(entry)),
        None => (0, rest == 0),
    };
    if !whole || present > capacity {
        return Err(RawPayloadError::BadLength { type_name, length, header, entry, capacity });
    }
    // SAFETY: `length` ≤ header + capacity × entry = size_of::<T>() (checked above and by the
    // constant assertions), and every bit pattern is a valid `T` (the trait's contract).
    unsafe {
        core::ptr::copy_nonoverlapping(bytes.as_ptr(), (frame as *mut T).cast::<u8>(), length);
    }
    // A frame claiming more than its capacity was recorded with every slot (the tracker rejects
    // it; a replay sends it as it was).
    if frame.claimed_entries().min(capacity) != present {
        return Err(RawPayloadError::CountMismatch { type_name, claimed: frame.claimed_entries(), present });
    }
    Ok(())
}

/// A boxed value of `T` with every byte zero.
pub fn zeroed_box<T: WirePayload>() -> Box<T> {
    let boxed = Box::<T>::new_zeroed();
    // SAFETY: the all-zero bit pattern is a valid `T` (the trait's contract).
    unsafe { boxed.assume_init() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_track_frame_comes_back_from_its_payload_with_only_the_valid_tracks_written() {
        let mut frame = zeroed_box::<TrackFrame>();
        frame.input_sequence = 7;
        frame.count = 2;
        frame.tracks[0].id = 11;
        frame.tracks[1].id = 12;
        frame.tracks[2].id = 99;
        let bytes = payload_bytes(&*frame).to_vec();
        assert_eq!(bytes.len(), TrackFrame::HEADER_BYTES + 2 * size_of::<WireTrack>());
        let mut back = zeroed_box::<TrackFrame>();
        read_payload(&bytes, &mut *back).unwrap();
        assert_eq!((back.input_sequence, back.count), (7, 2));
        assert_eq!(back.valid_tracks().iter().map(|t| t.id).collect::<Vec<_>>(), [11, 12]);
        assert_eq!(back.tracks[2].id, 0);
    }

    #[test]
    fn cut_or_miscounted_payloads_are_refused() {
        let mut frame = MeasurementFrame::boxed_zeroed();
        frame.count = 3;
        let bytes = payload_bytes(&*frame).to_vec();
        let mut back = MeasurementFrame::boxed_zeroed();
        assert!(matches!(read_payload(&bytes[..10], &mut *back), Err(RawPayloadError::TooShort { .. })));
        assert!(matches!(
            read_payload(&bytes[..bytes.len() - 1], &mut *back),
            Err(RawPayloadError::BadLength { .. })
        ));
        let two = &bytes[..bytes.len() - size_of::<WireMeasurement>()];
        assert!(matches!(
            read_payload(two, &mut *back),
            Err(RawPayloadError::CountMismatch { claimed: 3, present: 2, .. })
        ));
    }

    #[test]
    fn a_latency_report_is_recorded_whole() {
        let mut report = zeroed_box::<LatencyReport>();
        report.frames_tracked = 5;
        let bytes = payload_bytes(&*report).to_vec();
        assert_eq!(bytes.len(), size_of::<LatencyReport>());
        let mut back = zeroed_box::<LatencyReport>();
        read_payload(&bytes, &mut *back).unwrap();
        assert_eq!(back.frames_tracked, 5);
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(read_payload(&longer, &mut *back).is_err());
    }
}
