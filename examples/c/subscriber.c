/*
 * subscriber: prints the track frames of a recording of primm/tracks, read with primm_wire.h
 * alone (no primm library, no iceoryx2).
 *
 *   python3 examples/python/subscriber.py --record tracks.frames --frames 200   # record
 *   cc -std=c11 -O2 -Icrates/primm-wire/include examples/c/subscriber.c -o subscriber
 *   ./subscriber tracks.frames          # a table of the confirmed tracks per frame
 *   ./subscriber --json tracks.frames   # one JSON object per frame, as subscriber.py --json
 *
 * A recording is the track frames one after the other, each exactly as it lies in shared
 * memory: sizeof(primm_track_frame) = 217168 bytes in the byte order of the host that recorded
 * it. `tools/install_c_api.sh PREFIX` installs the header as PREFIX/include/primm_wire.h.
 *
 * Why a recording and not the live service: a C program subscribes to primm/tracks through
 * iceoryx2's C binding, and the binding of the iceoryx2 release primm is built with (0.10) is
 * published neither on crates.io (whose iceoryx2-ffi stops at 0.4, a shared-memory layout that
 * 0.10 does not open) nor as a Debian package; it is built from iceoryx2's source tree with
 * CMake. With that binding the loop below stays the same: open the publish-subscribe service
 * "primm/tracks" with the type name "primm::TrackFrame", the size and alignment of
 * primm_track_frame and the QoS of docs/service.md, and hand each received payload to
 * print_frame instead of reading it from the file (docs/service.md, "Subscribing").
 *
 * Bad input never crashes it: a cut frame, a frame of another wire version or a count beyond
 * the capacity is reported with the frame's position and the program exits with status 1.
 */
#include "primm_wire.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One frame at a time; static, as it is too large for many threads' stacks. */
static primm_track_frame frame;

static const char *class_name(uint8_t code) {
    switch (code) {
    case PRIMM_CLASS_CAR:
        return "car";
    case PRIMM_CLASS_PEDESTRIAN:
        return "pedestrian";
    case PRIMM_CLASS_TWO_WHEELER:
        return "two_wheeler";
    default:
        return "unknown";
    }
}

static const char *status_name(uint8_t status) {
    static const char *const names[] = {"tracked",           "non_finite_timestamp", "timestamp_not_increasing",
                                        "interval_too_long", "too_many_measurements", "association_failed",
                                        "invalid_ego_pose",  "too_late"};
    return status < sizeof names / sizeof names[0] ? names[status] : "unknown";
}

/* A double as JSON: the shortest-enough form that reads back to the same value, null if not
 * finite (JSON has no NaN or infinity). */
static void print_json_number(double value) {
    if (isfinite(value)) {
        printf("%.17g", value);
    } else {
        fputs("null", stdout);
    }
}

/* Confirmed or coasting (confirmed, but missed the last time a sensor had it in view). */
static int is_confirmed(const primm_wire_track *track) {
    return track->status == 1 || track->status == 2;
}

/* The frame as one JSON object: the fields and track fields subscriber.py --json prints. */
static void print_json(const primm_track_frame *f) {
    printf("{\"input_sequence\": %" PRIu64 ", \"source_frame\": %" PRIu64 ", \"sensor_timestamp_s\": ",
           f->input_sequence, f->source_frame);
    print_json_number(f->sensor_timestamp_s);
    printf(", \"status\": \"%s\", \"flags\": %u, \"tracks\": [", status_name(f->status), (unsigned)f->flags);
    for (uint32_t i = 0; i < f->count; i++) {
        const primm_wire_track *t = &f->tracks[i];
        printf("%s{\"id\": %" PRIu64 ", \"class\": \"%s\", \"confirmed\": %s, \"x_m\": ", i ? ", " : "", t->id,
               class_name(t->class_code), is_confirmed(t) ? "true" : "false");
        print_json_number(t->x_m);
        fputs(", \"y_m\": ", stdout);
        print_json_number(t->y_m);
        fputs(", \"vx_mps\": ", stdout);
        print_json_number(t->vx_mps);
        fputs(", \"vy_mps\": ", stdout);
        print_json_number(t->vy_mps);
        fputs(", \"mode_probabilities\": [", stdout);
        for (int mode = 0; mode < 4; mode++) {
            if (mode) {
                fputs(", ", stdout);
            }
            print_json_number(t->mode_probabilities[mode]);
        }
        printf("], \"measurement_index\": %" PRId32 ", \"gt_id\": %" PRId64 "}", t->measurement_index, t->gt_id);
    }
    fputs("]}\n", stdout);
}

/* The frame as a line and one line per confirmed track (the table of subscriber.py). */
static void print_table(const primm_track_frame *f) {
    printf("frame %" PRIu64 " seq %" PRIu64 " t %.3f s %s: %" PRIu32 " tracks\n", f->source_frame, f->input_sequence,
           f->sensor_timestamp_s, status_name(f->status), f->count);
    for (uint32_t i = 0; i < f->count; i++) {
        const primm_wire_track *t = &f->tracks[i];
        if (is_confirmed(t)) {
            printf("  %5" PRIu64 " %-10s x %8.2f y %8.2f v (%6.2f, %6.2f)  mu PR %.2f CV %.2f CA %.2f CT %.2f\n", t->id,
                   class_name(t->class_code), t->x_m, t->y_m, t->vx_mps, t->vy_mps, t->mode_probabilities[0],
                   t->mode_probabilities[1], t->mode_probabilities[2], t->mode_probabilities[3]);
        }
    }
}

int main(int argc, char **argv) {
    int json = 0;
    const char *path = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--json") == 0) {
            json = 1;
        } else if (path == NULL && argv[i][0] != '-') {
            path = argv[i];
        } else {
            path = NULL;
            break;
        }
    }
    if (path == NULL) {
        fprintf(stderr, "usage: %s [--json] RECORDING\n", argv[0]);
        return EXIT_FAILURE;
    }
    FILE *file = fopen(path, "rb");
    if (file == NULL) {
        fprintf(stderr, "subscriber: cannot open %s: %s\n", path, strerror(errno));
        return EXIT_FAILURE;
    }
    uint64_t index = 0;
    for (;; index++) {
        size_t got = fread(&frame, 1, sizeof frame, file);
        if (got == 0 && feof(file)) {
            break;
        }
        if (got != sizeof frame) {
            fprintf(stderr, "subscriber: %s: frame %" PRIu64 " is cut after %zu of %zu bytes\n", path, index, got,
                    sizeof frame);
            return EXIT_FAILURE;
        }
        if (frame.wire_version != PRIMM_WIRE_VERSION) {
            fprintf(stderr, "subscriber: %s: frame %" PRIu64 " has wire version %u, this header %u\n", path, index,
                    (unsigned)frame.wire_version, (unsigned)PRIMM_WIRE_VERSION);
            return EXIT_FAILURE;
        }
        if (frame.count > PRIMM_TRACK_CAPACITY) {
            fprintf(stderr, "subscriber: %s: frame %" PRIu64 " claims %" PRIu32 " tracks, at most %d fit\n", path,
                    index, frame.count, PRIMM_TRACK_CAPACITY);
            return EXIT_FAILURE;
        }
        if (json) {
            print_json(&frame);
        } else {
            print_table(&frame);
        }
    }
    if (ferror(file)) {
        fprintf(stderr, "subscriber: cannot read %s\n", path);
        return EXIT_FAILURE;
    }
    fclose(file);
    return EXIT_SUCCESS;
}
