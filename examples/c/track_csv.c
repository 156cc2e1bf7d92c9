/*
 * track_csv: tracks a measurement CSV file through the primm C API and writes the track CSV
 * file, exactly as `primm track --method imm --input INPUT.csv --output OUTPUT.csv` does.
 *
 *   cargo build --release -p primm-ffi
 *   cc -O2 -Iinclude examples/c/track_csv.c target/release/libprimm_ffi.a -lpthread -ldl -lm -o track_csv
 *   ./track_csv INPUT.csv OUTPUT.csv
 *
 * The program links without a warning and with a non-executable stack (docs/integrating-c-cpp.md);
 * examples/cpp/track_csv.cpp is the same program in C++ over include/primm.hpp.
 *
 * Input: the measurement CSV format of docs/scenario.md. Columns are found by their header
 * names (frame, t, gt_id, class, x, y, vr, rcs required; sensor_id and the ego pose ego_x,
 * ego_y, ego_yaw optional; others ignored),
 * fields are trimmed, lines starting with '#' are comments, and a row with an empty class is
 * the one row of a frame without measurements. Rows of one frame are consecutive. Classes are
 * read by primm_object_class_from_name, which accepts what `primm track` accepts (car, truck,
 * bus, person, Bicycle, ...: docs/scenario.md).
 *
 * Output: header frame,t,track_id,class,x,y,prior_x,prior_y,gt_id,mu_pr,mu_cv,mu_ca,mu_ct,status,
 * existence_probability and
 * one row per track updated by a measurement in that frame; a file with an ego pose adds the
 * world-frame columns world_x,world_y,world_vx,world_vy (the tracker then tracks in the world
 * frame, see primm_tracker_step_with_pose). Numbers are written with
 * primm_format_f64, the shortest form that reads back exactly (as primm writes them).
 */
#define _POSIX_C_SOURCE 200809L

#include "primm.h"

#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_FIELDS 64

enum column {
    COL_FRAME,
    COL_T,
    COL_GT_ID,
    COL_CLASS,
    COL_X,
    COL_Y,
    COL_VR,
    COL_RCS,
    COL_SENSOR_ID,
    COL_EGO_X,
    COL_EGO_Y,
    COL_EGO_YAW,
    COL_COUNT
};

static const char *const COLUMN_NAMES[COL_COUNT] = {"frame", "t",   "gt_id",     "class", "x",     "y",
                                                    "vr",    "rcs", "sensor_id", "ego_x", "ego_y", "ego_yaw"};

/* Required columns: all but sensor_id. */
#define REQUIRED_COLUMNS COL_SENSOR_ID

struct input {
    FILE *file;
    const char *path;
    char *line;
    size_t line_capacity;
    unsigned long line_number;
    char *fields[MAX_FIELDS];
    size_t field_count;
    int columns[COL_COUNT];
};

static void fail(const char *format, const char *path, unsigned long line, const char *detail) {
    fprintf(stderr, "track_csv: %s:%lu: ", path, line);
    fprintf(stderr, format, detail);
    fputc('\n', stderr);
    exit(EXIT_FAILURE);
}

static char *trim(char *text) {
    while (*text == ' ' || *text == '\t') {
        text++;
    }
    size_t len = strlen(text);
    while (len > 0 && (text[len - 1] == ' ' || text[len - 1] == '\t' || text[len - 1] == '\r' ||
                       text[len - 1] == '\n')) {
        text[--len] = '\0';
    }
    return text;
}

/* Splits the current line into fields in place; handles double-quoted fields with "" escapes. */
static void split_fields(struct input *in) {
    char *read = in->line;
    in->field_count = 0;
    for (;;) {
        if (in->field_count == MAX_FIELDS) {
            fail("%s", in->path, in->line_number, "too many fields");
        }
        while (*read == ' ' || *read == '\t') {
            read++;
        }
        char *start = read;
        char *write = read;
        if (*read == '"') {
            read++;
            for (;;) {
                if (*read == '\0') {
                    fail("%s", in->path, in->line_number, "unterminated quoted field");
                }
                if (*read == '"') {
                    if (read[1] == '"') {
                        *write++ = '"';
                        read += 2;
                        continue;
                    }
                    read++;
                    break;
                }
                *write++ = *read++;
            }
            while (*read != ',' && *read != '\0') {
                read++;
            }
        } else {
            while (*read != ',' && *read != '\0') {
                *write++ = *read++;
            }
        }
        char separator = *read;
        *write = '\0';
        in->fields[in->field_count++] = trim(start);
        if (separator != ',') {
            break;
        }
        read++;
    }
}

/* Reads the next non-comment, non-empty line into fields; returns 0 at the end of the file. */
static int next_record(struct input *in) {
    for (;;) {
        errno = 0;
        if (getline(&in->line, &in->line_capacity, in->file) < 0) {
            if (errno != 0) {
                fail("cannot read: %s", in->path, in->line_number + 1, strerror(errno));
            }
            return 0;
        }
        in->line_number++;
        if (in->line[0] == '#') {
            continue;
        }
        char *content = trim(in->line);
        if (*content == '\0') {
            continue;
        }
        memmove(in->line, content, strlen(content) + 1);
        split_fields(in);
        return 1;
    }
}

static const char *field(const struct input *in, enum column column) {
    int index = in->columns[column];
    if (index < 0 || (size_t)index >= in->field_count) {
        return "";
    }
    return in->fields[index];
}

static double parse_double(const struct input *in, enum column column) {
    const char *text = field(in, column);
    char *end = NULL;
    errno = 0;
    double value = strtod(text, &end);
    if (*text == '\0' || *end != '\0' || value != value || value - value != 0.0) {
        fail("invalid number `%s`", in->path, in->line_number, text);
    }
    return value;
}

static uint64_t parse_u64(const struct input *in, enum column column) {
    const char *text = field(in, column);
    char *end = NULL;
    errno = 0;
    unsigned long long value = strtoull(text, &end, 10);
    if (*text < '0' || *text > '9' || *end != '\0' || errno == ERANGE) {
        fail("invalid integer `%s`", in->path, in->line_number, text);
    }
    return (uint64_t)value;
}

static void print_double(FILE *out, double value) {
    char text[512];
    primm_format_f64(value, text, sizeof text);
    fputs(text, out);
}

static void check(PrimmStatus status, const char *what) {
    if (status != PRIMM_STATUS_OK) {
        char message[1024];
        primm_last_error_message(message, sizeof message);
        fprintf(stderr, "track_csv: %s: %s: %s\n", what, primm_status_message(status), message);
        exit(EXIT_FAILURE);
    }
}

/* The ego pose of the current row, if its ego columns are filled. */
static int read_pose(const struct input *in, PrimmEgoPose *pose) {
    if (in->columns[COL_EGO_X] < 0 || *field(in, COL_EGO_X) == '\0') {
        return 0;
    }
    pose->x_m = parse_double(in, COL_EGO_X);
    pose->y_m = parse_double(in, COL_EGO_Y);
    pose->yaw_rad = parse_double(in, COL_EGO_YAW);
    return 1;
}

/* The track file's name of a status code. */
static const char *track_status_name(PrimmTrackStatus status) {
    switch (status) {
    case PRIMM_TRACK_STATUS_TENTATIVE:
        return "tentative";
    case PRIMM_TRACK_STATUS_CONFIRMED:
        return "confirmed";
    case PRIMM_TRACK_STATUS_COASTING:
        return "coasting";
    default:
        return "unknown";
    }
}

/* Writes the upper triangle of a row-major 4x4 covariance, each value after a comma. */
static void print_upper_triangle(FILE *out, const double covariance[16]) {
    for (size_t row = 0; row < 4; row++) {
        for (size_t column = row; column < 4; column++) {
            fputc(',', out);
            print_double(out, covariance[4 * row + column]);
        }
    }
}

/* Tracks one frame (with its ego pose, or NULL) and writes the rows of the tracks a measurement
 * updated; with `world_columns`, each row ends with the world-frame estimate (empty without).
 * Frames come in file order, which is arrival order: a late frame is tracked in its place and
 * writes no rows here (the C API hands out the tracks at the newest frame's time, while
 * `primm track` writes the late frame's own rows, so the two files differ for such input); one
 * older than the late-frame window is skipped, as `primm track` does. */
static void track_frame(PrimmTracker *tracker, FILE *out, uint64_t frame, double timestamp_s,
                        const PrimmEgoPose *pose, const PrimmMeasurement *measurements, size_t count,
                        PrimmTrack *tracks, int world_columns) {
    PrimmStats before;
    check(primm_tracker_stats(tracker, &before), "reading the counters");
    PrimmStepSummary summary;
    PrimmStatus status = primm_tracker_step_with_pose(tracker, timestamp_s, pose, measurements, count, &summary);
    if (status != PRIMM_STATUS_OK) {
        char message[1024];
        primm_tracker_last_error(tracker, message, sizeof message);
        PrimmStats after;
        check(primm_tracker_stats(tracker, &after), "reading the counters");
        if (after.frames_rejected_too_late > before.frames_rejected_too_late) {
            fprintf(stderr, "frame %" PRIu64 ": older than the late-frame window reaches; skipped\n", frame);
            return;
        }
        fprintf(stderr, "track_csv: frame %" PRIu64 ": %s\n", frame, message);
        exit(EXIT_FAILURE);
    }
    if (summary.late_frame) {
        return;
    }
    size_t track_count = 0;
    check(primm_tracker_tracks(tracker, tracks, PRIMM_MAX_TRACKS, &track_count), "copying tracks");
    for (size_t i = 0; i < track_count; i++) {
        const PrimmTrack *track = &tracks[i];
        if (track->measurement_index == PRIMM_NO_MEASUREMENT_INDEX) {
            continue;
        }
        fprintf(out, "%" PRIu64 ",", frame);
        print_double(out, timestamp_s);
        fprintf(out, ",%" PRIu64 ",%s,", track->id, primm_object_class_name(track->class_code));
        print_double(out, track->x_m);
        fputc(',', out);
        print_double(out, track->y_m);
        fputc(',', out);
        if (track->has_prior_position) {
            print_double(out, track->prior_x_m);
            fputc(',', out);
            print_double(out, track->prior_y_m);
        } else {
            fputc(',', out);
        }
        fprintf(out, ",%" PRId64, track->ground_truth_id);
        for (size_t mode = 0; mode < PRIMM_MODE_COUNT; mode++) {
            fputc(',', out);
            print_double(out, track->mode_probabilities[mode]);
        }
        fprintf(out, ",%s,", track_status_name(track->status));
        print_double(out, track->existence_probability);
        const double velocity_and_age[3] = {track->velocity_x_mps, track->velocity_y_mps, track->age_s};
        for (size_t i = 0; i < 3; i++) {
            fputc(',', out);
            print_double(out, velocity_and_age[i]);
        }
        print_upper_triangle(out, track->state_covariance);
        if (world_columns && track->has_world_estimate) {
            const double world[4] = {track->world_x_m, track->world_y_m, track->world_velocity_x_mps,
                                     track->world_velocity_y_mps};
            for (size_t i = 0; i < 4; i++) {
                fputc(',', out);
                print_double(out, world[i]);
            }
            print_upper_triangle(out, track->world_state_covariance);
        } else if (world_columns) {
            fputs(",,,,,,,,,,,,,,", out);
        }
        fputc('\n', out);
    }
}

int main(int argc, char **argv) {
    if (argc != 3) {
        fprintf(stderr, "usage: %s INPUT.csv OUTPUT.csv\n", argv[0]);
        return EXIT_FAILURE;
    }
    struct input in = {.path = argv[1]};
    in.file = fopen(in.path, "r");
    if (in.file == NULL) {
        fprintf(stderr, "track_csv: cannot open %s: %s\n", in.path, strerror(errno));
        return EXIT_FAILURE;
    }
    if (!next_record(&in)) {
        fail("%s", in.path, 1, "no header");
    }
    for (int c = 0; c < COL_COUNT; c++) {
        in.columns[c] = -1;
        for (size_t i = 0; i < in.field_count; i++) {
            if (strcmp(in.fields[i], COLUMN_NAMES[c]) == 0) {
                in.columns[c] = (int)i;
            }
        }
        if (c < REQUIRED_COLUMNS && in.columns[c] < 0) {
            fail("missing header column `%s`", in.path, in.line_number, COLUMN_NAMES[c]);
        }
    }

    PrimmTrackerOptions options = primm_tracker_options_default();
    options.method = PRIMM_METHOD_IMM;
    PrimmTracker *tracker = NULL;
    check(primm_tracker_create(&options, &tracker), "creating the tracker");

    FILE *out = fopen(argv[2], "w");
    if (out == NULL) {
        fprintf(stderr, "track_csv: cannot create %s: %s\n", argv[2], strerror(errno));
        return EXIT_FAILURE;
    }
    int world_columns = in.columns[COL_EGO_X] >= 0 && in.columns[COL_EGO_Y] >= 0 && in.columns[COL_EGO_YAW] >= 0;
    if (!world_columns) {
        in.columns[COL_EGO_X] = -1; /* an incomplete pose group is ignored */
    }
    fputs("frame,t,track_id,class,x,y,prior_x,prior_y,gt_id,mu_pr,mu_cv,mu_ca,mu_ct,status,existence_probability,"
          "vx,vy,age_s,cov_xx,cov_xy,cov_xvx,cov_xvy,cov_yy,cov_yvx,cov_yvy,cov_vxvx,cov_vxvy,cov_vyvy",
          out);
    fputs(world_columns ? ",world_x,world_y,world_vx,world_vy,world_cov_xx,world_cov_xy,world_cov_xvx,world_cov_xvy,"
                          "world_cov_yy,world_cov_yvx,world_cov_yvy,world_cov_vxvx,world_cov_vxvy,world_cov_vyvy\n"
                        : "\n",
          out);

    static PrimmMeasurement measurements[PRIMM_MAX_MEASUREMENTS_PER_FRAME];
    static PrimmTrack tracks[PRIMM_MAX_TRACKS];
    size_t count = 0;
    int open = 0;
    uint64_t frame = 0;
    double timestamp_s = 0.0;
    PrimmEgoPose pose;
    int has_pose = 0;
    while (next_record(&in)) {
        uint64_t row_frame = parse_u64(&in, COL_FRAME);
        double row_t = parse_double(&in, COL_T);
        if (!open || row_frame != frame) {
            if (open) {
                track_frame(tracker, out, frame, timestamp_s, has_pose ? &pose : NULL, measurements, count, tracks,
                            world_columns);
            }
            open = 1;
            frame = row_frame;
            timestamp_s = row_t;
            count = 0;
            has_pose = read_pose(&in, &pose);
        } else if (row_t != timestamp_s) {
            fail("timestamp `%s` differs within a frame", in.path, in.line_number, field(&in, COL_T));
        }
        const char *class_name = field(&in, COL_CLASS);
        if (*class_name == '\0') {
            continue; /* the row of a frame without measurements */
        }
        if (count == PRIMM_MAX_MEASUREMENTS_PER_FRAME) {
            fail("frame `%s` has too many measurements", in.path, in.line_number, field(&in, COL_FRAME));
        }
        int32_t class_code = primm_object_class_from_name(class_name);
        if (class_code < 0) {
            fail("unknown object class `%s`", in.path, in.line_number, class_name);
        }
        const char *gt = field(&in, COL_GT_ID);
        const char *sensor = field(&in, COL_SENSOR_ID);
        PrimmMeasurement *m = &measurements[count++];
        m->x_m = parse_double(&in, COL_X);
        m->y_m = parse_double(&in, COL_Y);
        m->radial_velocity_mps = parse_double(&in, COL_VR);
        m->rcs_dbsm = parse_double(&in, COL_RCS);
        m->class_code = (PrimmObjectClass)class_code;
        m->ground_truth_id = (*gt == '\0' || strcmp(gt, "-1") == 0) ? PRIMM_NO_GROUND_TRUTH_ID
                                                                     : (int64_t)parse_u64(&in, COL_GT_ID);
        m->sensor_id = *sensor == '\0' ? PRIMM_NO_SENSOR_ID : (int32_t)parse_u64(&in, COL_SENSOR_ID);
    }
    if (open) {
        track_frame(tracker, out, frame, timestamp_s, has_pose ? &pose : NULL, measurements, count, tracks,
                    world_columns);
    }

    PrimmStats stats;
    check(primm_tracker_stats(tracker, &stats), "reading the counters");
    fprintf(stderr,
            "imm: %" PRIu64 " frames, %" PRIu64 " measurements, %" PRIu64 " tracks started, %" PRIu64
            " deleted -> %s\n",
            stats.frames_tracked, stats.measurements_accepted, stats.tracks_initiated, stats.tracks_deleted,
            argv[2]);
    primm_tracker_destroy(tracker);
    free(in.line);
    fclose(in.file);
    if (fclose(out) != 0) {
        fprintf(stderr, "track_csv: cannot write %s\n", argv[2]);
        return EXIT_FAILURE;
    }
    return EXIT_SUCCESS;
}
