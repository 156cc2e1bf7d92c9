"""primm wire types as ctypes structures.

Mirrors the Rust types of the primm-wire crate (crates/primm-wire/src/) and
crates/primm-wire/include/primm_wire.h byte for byte (crates/primm-wire/tests/layout.rs compares
sizes, alignments and every field offset). Each payload type has a static ``type_name()``
returning the iceoryx2 type name the Rust side declares, so the iceoryx2 Python package opens
the same services. Units are part of the field names; ``_ns`` times are CLOCK_MONOTONIC
nanoseconds (``time.monotonic_ns()``), ``_s`` times are sensor seconds.
"""

import ctypes

WIRE_VERSION = 5  # layout version; TrackFrame.wire_version carries the writer's
MEASUREMENT_CAPACITY = 1024
TRACK_CAPACITY = 512
STAGE_CAPACITY = 12
STAGE_NAME_LEN = 24

FRAME_FLAG_STREAM_START = 1 << 0
FRAME_FLAG_EGO_VALID = 1 << 1
FRAME_FLAG_STREAM_END = 1 << 2

TRACK_FLAG_TRACKER_RESET = 1 << 0
TRACK_FLAG_SEQUENCE_GAP = 1 << 1
TRACK_FLAG_STREAM_END = 1 << 2
TRACK_FLAG_LATE_FRAME = 1 << 3  # late input tracked in its place; tracks at tracks_timestamp_s
TRACK_FLAG_PREDICTED = 1 << 4  # tracks predicted to tracks_timestamp_s (the publish time)

STATUS_NAMES = {
    0: "tracked",
    1: "non_finite_timestamp",
    2: "timestamp_not_increasing",
    3: "interval_too_long",
    4: "too_many_measurements",
    5: "association_failed",
    6: "invalid_ego_pose",
    7: "too_late",
}
CLASS_NAMES = {0: "car", 1: "pedestrian", 2: "two_wheeler"}

# Service names and the QoS every primm program opens them with (crates/primm-ipc/src/catalog.rs).
MEASUREMENTS = "primm/measurements"
TRACKS = "primm/tracks"
LATENCY = "primm/latency"
QOS = {
    MEASUREMENTS: dict(subscriber_buffer=64, history=0, max_publishers=4, max_subscribers=8, max_borrowed=2),
    TRACKS: dict(subscriber_buffer=16, history=0, max_publishers=2, max_subscribers=8, max_borrowed=2),
    LATENCY: dict(subscriber_buffer=4, history=1, max_publishers=2, max_subscribers=8, max_borrowed=2),
}


def service_name(base: str, prefix: str = "") -> str:
    """The full service name under an optional prefix (``PREFIX/primm/...``)."""
    prefix = prefix.strip("/")
    return f"{prefix}/{base}" if prefix else base


class WireMeasurement(ctypes.Structure):
    """One object-level measurement (64 bytes)."""

    _fields_ = [
        ("x_m", ctypes.c_double),
        ("y_m", ctypes.c_double),
        ("vr_mps", ctypes.c_double),
        ("rcs_dbsm", ctypes.c_double),
        ("true_x_m", ctypes.c_double),
        ("true_y_m", ctypes.c_double),
        ("gt_id", ctypes.c_int64),
        ("sensor_id", ctypes.c_uint16),
        ("class_code", ctypes.c_uint8),
        ("truth_valid", ctypes.c_uint8),
        ("_pad0", ctypes.c_uint8 * 4),
    ]

    @staticmethod
    def type_name() -> str:
        return "primm::WireMeasurement"


class MeasurementFrame(ctypes.Structure):
    """One radar frame (16456 bytes)."""

    _fields_ = [
        ("sequence", ctypes.c_uint64),
        ("source_frame", ctypes.c_uint64),
        ("sensor_timestamp_s", ctypes.c_double),
        ("publish_time_ns", ctypes.c_uint64),
        ("scheduled_time_ns", ctypes.c_uint64),
        ("ego_x_m", ctypes.c_double),
        ("ego_y_m", ctypes.c_double),
        ("ego_yaw_rad", ctypes.c_double),
        ("count", ctypes.c_uint32),
        ("flags", ctypes.c_uint32),
        ("measurements", WireMeasurement * MEASUREMENT_CAPACITY),
    ]

    @staticmethod
    def type_name() -> str:
        return "primm::MeasurementFrame"


class WireTrack(ctypes.Structure):
    """One track's fused state (424 bytes)."""

    _fields_ = [
        ("id", ctypes.c_uint64),
        ("x_m", ctypes.c_double),
        ("y_m", ctypes.c_double),
        ("vx_mps", ctypes.c_double),
        ("vy_mps", ctypes.c_double),
        ("state_covariance", ctypes.c_double * 16),  # row-major 4x4 of [x, y, vx, vy]
        ("prior_x_m", ctypes.c_double),
        ("prior_y_m", ctypes.c_double),
        ("mode_probabilities", ctypes.c_double * 4),
        ("world_x_m", ctypes.c_double),
        ("world_y_m", ctypes.c_double),
        ("world_vx_mps", ctypes.c_double),
        ("world_vy_mps", ctypes.c_double),
        ("world_state_covariance", ctypes.c_double * 16),
        ("existence_probability", ctypes.c_double),
        ("age_s", ctypes.c_double),
        ("gt_id", ctypes.c_int64),
        ("age_frames", ctypes.c_uint32),
        ("hits", ctypes.c_uint32),
        ("misses", ctypes.c_uint32),
        ("measurement_index", ctypes.c_int32),
        ("class_code", ctypes.c_uint8),
        ("status", ctypes.c_uint8),
        ("prior_valid", ctypes.c_uint8),
        ("world_valid", ctypes.c_uint8),
        ("_pad0", ctypes.c_uint8 * 4),
    ]

    @staticmethod
    def type_name() -> str:
        return "primm::WireTrack"


class TrackFrame(ctypes.Structure):
    """The tracker's answer to one measurement frame (217168 bytes)."""

    _fields_ = [
        ("input_sequence", ctypes.c_uint64),
        ("source_frame", ctypes.c_uint64),
        ("sensor_timestamp_s", ctypes.c_double),
        ("tracks_timestamp_s", ctypes.c_double),
        ("input_publish_time_ns", ctypes.c_uint64),
        ("input_scheduled_time_ns", ctypes.c_uint64),
        ("receive_time_ns", ctypes.c_uint64),
        ("publish_time_ns", ctypes.c_uint64),
        ("count", ctypes.c_uint32),
        ("status", ctypes.c_uint8),
        ("flags", ctypes.c_uint8),
        ("measurements_accepted", ctypes.c_uint16),
        ("measurements_rejected", ctypes.c_uint16),
        ("wire_version", ctypes.c_uint16),
        ("_pad0", ctypes.c_uint8 * 4),
        ("tracks", WireTrack * TRACK_CAPACITY),
    ]

    @staticmethod
    def type_name() -> str:
        return "primm::TrackFrame"

    def valid_tracks(self):
        """The tracks in use (count clamped to the capacity)."""
        return self.tracks[: min(self.count, TRACK_CAPACITY)]


class StageLatency(ctypes.Structure):
    """Percentiles of one stage's latency (80 bytes)."""

    _fields_ = [
        ("name", ctypes.c_char * STAGE_NAME_LEN),
        ("count", ctypes.c_uint64),
        ("p50_ns", ctypes.c_uint64),
        ("p90_ns", ctypes.c_uint64),
        ("p99_ns", ctypes.c_uint64),
        ("p999_ns", ctypes.c_uint64),
        ("max_ns", ctypes.c_uint64),
        ("mean_ns", ctypes.c_uint64),
    ]

    @staticmethod
    def type_name() -> str:
        return "primm::StageLatency"


class LatencyReport(ctypes.Structure):
    """The tracker's latency percentiles and counters (1032 bytes)."""

    _fields_ = [
        ("sequence", ctypes.c_uint64),
        ("publish_time_ns", ctypes.c_uint64),
        ("frames_received", ctypes.c_uint64),
        ("frames_tracked", ctypes.c_uint64),
        ("frames_rejected", ctypes.c_uint64),
        ("frames_lost", ctypes.c_uint64),
        ("measurements_rejected", ctypes.c_uint64),
        ("resets", ctypes.c_uint64),
        ("stage_count", ctypes.c_uint32),
        ("_pad0", ctypes.c_uint8 * 4),
        ("stages", StageLatency * STAGE_CAPACITY),
    ]

    @staticmethod
    def type_name() -> str:
        return "primm::LatencyReport"


ALL_TYPES = [WireMeasurement, MeasurementFrame, WireTrack, TrackFrame, StageLatency, LatencyReport]


def layout() -> dict:
    """Size, alignment and field offsets of every type, for the layout test."""
    result = {}
    for struct in ALL_TYPES:
        fields = {name: getattr(struct, name).offset for name, *_ in struct._fields_}
        result[struct.__name__] = {"size": ctypes.sizeof(struct), "align": ctypes.alignment(struct), "fields": fields}
    return result


if __name__ == "__main__":
    print(f"version {WIRE_VERSION}")
    for name, info in layout().items():
        print(f"{name} size {info['size']} align {info['align']}")
        for field, offset in info["fields"].items():
            print(f"{name}.{field} {offset}")
