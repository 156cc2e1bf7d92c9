/*
 * primm wire types: the payloads of the primm shared-memory services (iceoryx2).
 *
 * Mirrors the Rust types of the primm-wire crate (crates/primm-wire/src/) byte for byte; a test
 * (crates/primm-wire/tests/layout.rs) compares the size, alignment and every field offset of
 * this header, the Rust types and the Python module crates/primm-wire/python/primm_wire.py.
 * tools/install_c_api.sh installs it beside primm.h; it needs no library.
 * Every field is a plain integer or double, there is no implicit padding, and entries past
 * `count` in an array are unused. Units are part of the field names; `_ns` times are
 * CLOCK_MONOTONIC nanoseconds, `_s` times are sensor seconds.
 *
 * iceoryx2 type names (for the C/C++ bindings' type_name): "primm::MeasurementFrame",
 * "primm::TrackFrame", "primm::LatencyReport". Service names and QoS: docs/service.md;
 * examples/c/subscriber.c prints recorded track frames with this header alone.
 */
#ifndef PRIMM_WIRE_H
#define PRIMM_WIRE_H

#include <stdint.h>

#define PRIMM_WIRE_VERSION 5 /* layout version; primm_track_frame.wire_version carries the writer's */
#define PRIMM_MEASUREMENT_CAPACITY 1024
#define PRIMM_TRACK_CAPACITY 512
#define PRIMM_STAGE_CAPACITY 12
#define PRIMM_STAGE_NAME_LEN 24

#define PRIMM_GROUND_TRUTH_UNKNOWN (-1)
#define PRIMM_SENSOR_UNKNOWN 0xFFFFu
#define PRIMM_MEASUREMENT_INDEX_NONE (-1)

/* MeasurementFrame.flags */
#define PRIMM_FRAME_FLAG_STREAM_START (1u << 0)
#define PRIMM_FRAME_FLAG_EGO_VALID (1u << 1)
#define PRIMM_FRAME_FLAG_STREAM_END (1u << 2)

/* TrackFrame.flags */
#define PRIMM_TRACK_FLAG_TRACKER_RESET (1u << 0)
#define PRIMM_TRACK_FLAG_SEQUENCE_GAP (1u << 1)
#define PRIMM_TRACK_FLAG_STREAM_END (1u << 2)
#define PRIMM_TRACK_FLAG_LATE_FRAME (1u << 3) /* late input tracked in its place; tracks at tracks_timestamp_s */
#define PRIMM_TRACK_FLAG_PREDICTED (1u << 4)  /* tracks predicted to tracks_timestamp_s (publish time) */

/* TrackFrame.status */
#define PRIMM_STATUS_TRACKED 0
#define PRIMM_STATUS_REJECTED_NON_FINITE_TIMESTAMP 1
#define PRIMM_STATUS_REJECTED_TIMESTAMP_NOT_INCREASING 2
#define PRIMM_STATUS_REJECTED_INTERVAL_TOO_LONG 3
#define PRIMM_STATUS_REJECTED_TOO_MANY_MEASUREMENTS 4
#define PRIMM_STATUS_ASSOCIATION_FAILED 5
#define PRIMM_STATUS_REJECTED_INVALID_EGO_POSE 6
#define PRIMM_STATUS_REJECTED_TOO_LATE 7

/* Object class codes */
#define PRIMM_CLASS_CAR 0
#define PRIMM_CLASS_PEDESTRIAN 1
#define PRIMM_CLASS_TWO_WHEELER 2

/* One object-level measurement: 64 bytes. */
typedef struct primm_wire_measurement {
    double x_m;
    double y_m;
    double vr_mps;
    double rcs_dbsm;
    double true_x_m;      /* valid when truth_valid == 1 */
    double true_y_m;
    int64_t gt_id;        /* < 0: unknown */
    uint16_t sensor_id;   /* PRIMM_SENSOR_UNKNOWN: unknown */
    uint8_t class_code;
    uint8_t truth_valid;
    uint8_t _pad0[4];
} primm_wire_measurement;

/* "primm::MeasurementFrame": 16456 bytes. count is not trusted by the tracker. */
typedef struct primm_measurement_frame {
    uint64_t sequence;
    uint64_t source_frame;
    double sensor_timestamp_s;
    uint64_t publish_time_ns;
    uint64_t scheduled_time_ns; /* when the publisher was due to send it; 0: no schedule */
    double ego_x_m;
    double ego_y_m;
    double ego_yaw_rad;
    uint32_t count;
    uint32_t flags;
    primm_wire_measurement measurements[PRIMM_MEASUREMENT_CAPACITY];
} primm_measurement_frame;

/* One track: 424 bytes. With world_valid == 1 the frame was tracked in the world frame: x, y,
 * velocity, covariance and prior are in the vehicle frame of the input frame (velocity over
 * ground in the vehicle's axes), world_* in the world frame. */
typedef struct primm_wire_track {
    uint64_t id;
    double x_m;
    double y_m;
    double vx_mps;
    double vy_mps;
    double state_covariance[16];  /* row-major 4x4 of [x, y, vx, vy]: m^2, m^2/s, m^2/s^2 */
    double prior_x_m;             /* valid when prior_valid == 1 */
    double prior_y_m;
    double mode_probabilities[4]; /* PR, CV, CA, CT */
    double world_x_m;             /* valid when world_valid == 1 */
    double world_y_m;
    double world_vx_mps;
    double world_vy_mps;
    double world_state_covariance[16]; /* row-major 4x4 of the world [x, y, vx, vy] */
    double existence_probability; /* probability that the object exists, (0, 1) */
    double age_s;                 /* time since the track's first measurement */
    int64_t gt_id;                /* -1: none */
    uint32_t age_frames;
    uint32_t hits;
    uint32_t misses;
    int32_t measurement_index;    /* PRIMM_MEASUREMENT_INDEX_NONE: coasted */
    uint8_t class_code;
    uint8_t status;               /* 0 tentative, 1 confirmed, 2 coasting */
    uint8_t prior_valid;
    uint8_t world_valid;
    uint8_t _pad0[4];
} primm_wire_track;

/* "primm::TrackFrame": 217168 bytes. */
typedef struct primm_track_frame {
    uint64_t input_sequence;
    uint64_t source_frame;
    double sensor_timestamp_s;
    double tracks_timestamp_s; /* the time the tracks describe (see the flags) */
    uint64_t input_publish_time_ns;
    uint64_t input_scheduled_time_ns;
    uint64_t receive_time_ns;
    uint64_t publish_time_ns;
    uint32_t count;
    uint8_t status;
    uint8_t flags;
    uint16_t measurements_accepted;
    uint16_t measurements_rejected;
    uint16_t wire_version; /* PRIMM_WIRE_VERSION of the writer */
    uint8_t _pad0[4];
    primm_wire_track tracks[PRIMM_TRACK_CAPACITY];
} primm_track_frame;

/* Percentiles of one stage: 80 bytes. */
typedef struct primm_stage_latency {
    char name[PRIMM_STAGE_NAME_LEN]; /* ASCII, NUL-padded */
    uint64_t count;
    uint64_t p50_ns;
    uint64_t p90_ns;
    uint64_t p99_ns;
    uint64_t p999_ns;
    uint64_t max_ns;
    uint64_t mean_ns;
} primm_stage_latency;

/* "primm::LatencyReport": 1032 bytes. */
typedef struct primm_latency_report {
    uint64_t sequence;
    uint64_t publish_time_ns;
    uint64_t frames_received;
    uint64_t frames_tracked;
    uint64_t frames_rejected;
    uint64_t frames_lost;
    uint64_t measurements_rejected;
    uint64_t resets;
    uint32_t stage_count;
    uint8_t _pad0[4];
    primm_stage_latency stages[PRIMM_STAGE_CAPACITY];
} primm_latency_report;

#endif /* PRIMM_WIRE_H */
