/*
 * track_csv: tracks a measurement CSV file through primm's C++ wrapper (primm.hpp) and writes
 * the track CSV file, exactly as `primm track --method imm --input INPUT.csv --output OUTPUT.csv`
 * does. The C++ form of examples/c/track_csv.c: same input rules, same output, same structure
 * (one function per step of the C example), so that a column added to one is added to the other
 * in the same place.
 *
 *   cargo build --release -p primm-ffi
 *   c++ -std=c++17 -O2 -Iinclude examples/cpp/track_csv.cpp target/release/libprimm_ffi.a \
 *       -lpthread -ldl -lm -o track_csv
 *   ./track_csv INPUT.csv OUTPUT.csv
 *
 * or through CMake against an installed primm (tools/install_c_api.sh PREFIX):
 *
 *   cmake -S examples/cpp -B build -DCMAKE_PREFIX_PATH=PREFIX && cmake --build build
 *
 * Input: the measurement CSV format of docs/scenario.md. Columns are found by their header
 * names (frame, t, gt_id, class, x, y, vr, rcs required; sensor_id and the ego pose ego_x,
 * ego_y, ego_yaw optional; others ignored), fields are trimmed, lines starting with '#' are
 * comments, and a row with an empty class is the one row of a frame without measurements. Rows
 * of one frame are consecutive.
 *
 * Output: the columns of examples/c/track_csv.c (see there), numbers written with
 * primm::format_f64, the shortest form that reads back exactly (as primm writes them).
 *
 * Errors: a fault in the input throws InputError, a failed primm call primm::Error; main
 * prints either and exits with a failure status.
 */
#include "primm.hpp"

#include <array>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

enum Column {
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

const std::array<const char *, COL_COUNT> COLUMN_NAMES = {"frame", "t",   "gt_id",     "class", "x",     "y",
                                                          "vr",    "rcs", "sensor_id", "ego_x", "ego_y", "ego_yaw"};

/* Required columns: all but sensor_id and the ego pose. */
constexpr int REQUIRED_COLUMNS = COL_SENSOR_ID;

/* The header of the track file; the world-frame columns follow when the input has a pose. */
constexpr const char *TRACK_COLUMNS =
    "frame,t,track_id,class,x,y,prior_x,prior_y,gt_id,mu_pr,mu_cv,mu_ca,mu_ct,status,existence_probability,"
    "vx,vy,age_s,cov_xx,cov_xy,cov_xvx,cov_xvy,cov_yy,cov_yvx,cov_yvy,cov_vxvx,cov_vxvy,cov_vyvy";
constexpr const char *WORLD_COLUMNS =
    ",world_x,world_y,world_vx,world_vy,world_cov_xx,world_cov_xy,world_cov_xvx,world_cov_xvy,world_cov_yy,"
    "world_cov_yvx,world_cov_yvy,world_cov_vxvx,world_cov_vxvy,world_cov_vyvy";

/* A fault in the input file, with its place. */
class InputError : public std::runtime_error {
  public:
    InputError(const std::string &path, unsigned long line, const std::string &detail)
        : std::runtime_error(path + ":" + std::to_string(line) + ": " + detail) {}
};

std::string trim(const std::string &text) {
    std::size_t start = 0;
    while (start < text.size() && (text[start] == ' ' || text[start] == '\t')) {
        start++;
    }
    std::size_t end = text.size();
    while (end > start && (text[end - 1] == ' ' || text[end - 1] == '\t' || text[end - 1] == '\r' ||
                           text[end - 1] == '\n')) {
        end--;
    }
    return text.substr(start, end - start);
}

/* The measurement file, read one record at a time. */
class Input {
  public:
    explicit Input(const std::string &path) : path_(path), file_(path) {
        if (!file_) {
            throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
        }
    }

    /* Reads the next non-comment, non-empty line into fields; false at the end of the file. */
    bool next_record() {
        std::string line;
        while (std::getline(file_, line)) {
            line_number_++;
            if (!line.empty() && line[0] == '#') {
                continue;
            }
            line = trim(line);
            if (line.empty()) {
                continue;
            }
            split_fields(line);
            return true;
        }
        if (file_.bad()) {
            fail("cannot read");
        }
        return false;
    }

    /* Finds the columns in the header record. */
    void read_header() {
        if (!next_record()) {
            throw InputError(path_, 1, "no header");
        }
        for (int column = 0; column < COL_COUNT; column++) {
            columns_[column] = -1;
            for (std::size_t i = 0; i < fields_.size(); i++) {
                if (fields_[i] == COLUMN_NAMES[column]) {
                    columns_[column] = static_cast<int>(i);
                }
            }
            if (column < REQUIRED_COLUMNS && columns_[column] < 0) {
                fail(std::string("missing header column `") + COLUMN_NAMES[column] + "`");
            }
        }
    }

    bool has_column(Column column) const { return columns_[column] >= 0; }
    void drop_column(Column column) { columns_[column] = -1; }

    const std::string &field(Column column) const {
        static const std::string empty;
        const int index = columns_[column];
        if (index < 0 || static_cast<std::size_t>(index) >= fields_.size()) {
            return empty;
        }
        return fields_[static_cast<std::size_t>(index)];
    }

    double parse_double(Column column) const {
        const std::string &text = field(column);
        char *end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (text.empty() || *end != '\0' || value != value || value - value != 0.0) {
            fail("invalid number `" + text + "`");
        }
        return value;
    }

    std::uint64_t parse_u64(Column column) const {
        const std::string &text = field(column);
        char *end = nullptr;
        errno = 0;
        const unsigned long long value = std::strtoull(text.c_str(), &end, 10);
        if (text.empty() || text[0] < '0' || text[0] > '9' || *end != '\0' || errno == ERANGE) {
            fail("invalid integer `" + text + "`");
        }
        return static_cast<std::uint64_t>(value);
    }

    /* The ego pose of the current row, if its ego columns are filled. */
    std::optional<PrimmEgoPose> read_pose() const {
        if (!has_column(COL_EGO_X) || field(COL_EGO_X).empty()) {
            return std::nullopt;
        }
        PrimmEgoPose pose{};
        pose.x_m = parse_double(COL_EGO_X);
        pose.y_m = parse_double(COL_EGO_Y);
        pose.yaw_rad = parse_double(COL_EGO_YAW);
        return pose;
    }

    [[noreturn]] void fail(const std::string &detail) const { throw InputError(path_, line_number_, detail); }

  private:
    /* Splits `line` into fields; handles double-quoted fields with "" escapes. */
    void split_fields(const std::string &line) {
        fields_.clear();
        std::size_t read = 0;
        for (;;) {
            while (read < line.size() && (line[read] == ' ' || line[read] == '\t')) {
                read++;
            }
            std::string value;
            if (read < line.size() && line[read] == '"') {
                read++;
                for (;;) {
                    if (read >= line.size()) {
                        fail("unterminated quoted field");
                    }
                    if (line[read] == '"') {
                        if (read + 1 < line.size() && line[read + 1] == '"') {
                            value += '"';
                            read += 2;
                            continue;
                        }
                        read++;
                        break;
                    }
                    value += line[read++];
                }
                while (read < line.size() && line[read] != ',') {
                    read++;
                }
            } else {
                while (read < line.size() && line[read] != ',') {
                    value += line[read++];
                }
            }
            fields_.push_back(trim(value));
            if (read >= line.size()) {
                break;
            }
            read++; /* the comma */
        }
    }

    std::string path_;
    std::ifstream file_;
    unsigned long line_number_ = 0;
    std::vector<std::string> fields_;
    std::array<int, COL_COUNT> columns_{};
};

void print_double(std::FILE *out, double value) { std::fputs(primm::format_f64(value).c_str(), out); }

/* The track file's name of a status code. */
const char *track_status_name(PrimmTrackStatus status) {
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

/* Writes the row of one track; with `world_columns`, the row ends with the world-frame estimate
 * (empty without one). */
/* Writes the upper triangle of a row-major 4x4 covariance, each value after a comma. */
void print_upper_triangle(std::FILE *out, const double (&covariance)[16]) {
    for (std::size_t row = 0; row < 4; row++) {
        for (std::size_t column = row; column < 4; column++) {
            std::fputc(',', out);
            print_double(out, covariance[4 * row + column]);
        }
    }
}

void write_track_row(std::FILE *out, std::uint64_t frame, double timestamp_s, const PrimmTrack &track,
                     bool world_columns) {
    std::fprintf(out, "%" PRIu64 ",", frame);
    print_double(out, timestamp_s);
    std::fprintf(out, ",%" PRIu64 ",%s,", track.id, primm::object_class_name(track.class_code));
    print_double(out, track.x_m);
    std::fputc(',', out);
    print_double(out, track.y_m);
    std::fputc(',', out);
    if (track.has_prior_position) {
        print_double(out, track.prior_x_m);
        std::fputc(',', out);
        print_double(out, track.prior_y_m);
    } else {
        std::fputc(',', out);
    }
    std::fprintf(out, ",%" PRId64, track.ground_truth_id);
    for (double probability : track.mode_probabilities) {
        std::fputc(',', out);
        print_double(out, probability);
    }
    std::fprintf(out, ",%s,", track_status_name(track.status));
    print_double(out, track.existence_probability);
    for (double value : {track.velocity_x_mps, track.velocity_y_mps, track.age_s}) {
        std::fputc(',', out);
        print_double(out, value);
    }
    print_upper_triangle(out, track.state_covariance);
    if (world_columns && track.has_world_estimate) {
        const double world[4] = {track.world_x_m, track.world_y_m, track.world_velocity_x_mps,
                                 track.world_velocity_y_mps};
        for (double value : world) {
            std::fputc(',', out);
            print_double(out, value);
        }
        print_upper_triangle(out, track.world_state_covariance);
    } else if (world_columns) {
        std::fputs(",,,,,,,,,,,,,,", out);
    }
    std::fputc('\n', out);
}

/* Tracks one frame (with its ego pose, or none) and writes the rows of the tracks a measurement
 * updated. Frames come in file order, which is arrival order: a late frame is tracked in its
 * place and writes no rows here (the C API hands out the tracks at the newest frame's time,
 * while `primm track` writes the late frame's own rows, so the two files differ for such input);
 * one older than the late-frame window is skipped, as `primm track` does. */
void track_frame(primm::Tracker &tracker, std::FILE *out, std::uint64_t frame, double timestamp_s,
                 const std::optional<PrimmEgoPose> &pose, primm::Span<const PrimmMeasurement> measurements,
                 primm::Span<PrimmTrack> buffer, bool world_columns) {
    const std::uint64_t too_late_before = tracker.stats().frames_rejected_too_late;
    PrimmStepSummary summary{};
    try {
        summary = tracker.step(timestamp_s, pose ? &*pose : nullptr, measurements);
    } catch (const primm::Error &) {
        if (tracker.stats().frames_rejected_too_late > too_late_before) {
            std::fprintf(stderr, "frame %" PRIu64 ": older than the late-frame window reaches; skipped\n", frame);
            return;
        }
        throw std::runtime_error("frame " + std::to_string(frame) + ": " + tracker.last_error());
    }
    if (summary.late_frame) {
        return;
    }
    for (const PrimmTrack &track : tracker.tracks(buffer)) {
        if (track.measurement_index == PRIMM_NO_MEASUREMENT_INDEX) {
            continue;
        }
        write_track_row(out, frame, timestamp_s, track, world_columns);
    }
}

/* Closes the output file when the run ends, whichever way. */
struct FileCloser {
    void operator()(std::FILE *file) const {
        if (file != nullptr) {
            std::fclose(file);
        }
    }
};

int run(const std::string &input_path, const std::string &output_path) {
    Input in(input_path);
    in.read_header();

    primm::Tracker tracker(primm::Options().method(PRIMM_METHOD_IMM));

    std::FILE *out = std::fopen(output_path.c_str(), "w");
    if (out == nullptr) {
        throw std::runtime_error("cannot create " + output_path + ": " + std::strerror(errno));
    }
    std::unique_ptr<std::FILE, FileCloser> out_guard(out);
    const bool world_columns = in.has_column(COL_EGO_X) && in.has_column(COL_EGO_Y) && in.has_column(COL_EGO_YAW);
    if (!world_columns) {
        in.drop_column(COL_EGO_X); /* an incomplete pose group is ignored */
    }
    std::fputs(TRACK_COLUMNS, out);
    std::fputs(world_columns ? WORLD_COLUMNS : "", out);
    std::fputc('\n', out);

    std::vector<PrimmMeasurement> measurements(PRIMM_MAX_MEASUREMENTS_PER_FRAME);
    std::vector<PrimmTrack> tracks(PRIMM_MAX_TRACKS);
    std::size_t count = 0;
    bool open = false;
    std::uint64_t frame = 0;
    double timestamp_s = 0.0;
    std::optional<PrimmEgoPose> pose;
    while (in.next_record()) {
        const std::uint64_t row_frame = in.parse_u64(COL_FRAME);
        const double row_t = in.parse_double(COL_T);
        if (!open || row_frame != frame) {
            if (open) {
                track_frame(tracker, out, frame, timestamp_s, pose, primm::Span<const PrimmMeasurement>(measurements.data(), count),
                            tracks, world_columns);
            }
            open = true;
            frame = row_frame;
            timestamp_s = row_t;
            count = 0;
            pose = in.read_pose();
        } else if (row_t != timestamp_s) {
            in.fail("timestamp `" + in.field(COL_T) + "` differs within a frame");
        }
        const std::string &class_name = in.field(COL_CLASS);
        if (class_name.empty()) {
            continue; /* the row of a frame without measurements */
        }
        if (count == PRIMM_MAX_MEASUREMENTS_PER_FRAME) {
            in.fail("frame `" + in.field(COL_FRAME) + "` has too many measurements");
        }
        const std::int32_t class_code = primm_object_class_from_name(class_name.c_str());
        if (class_code < 0) {
            in.fail("unknown object class `" + class_name + "`");
        }
        const std::string &gt = in.field(COL_GT_ID);
        const std::string &sensor = in.field(COL_SENSOR_ID);
        PrimmMeasurement &m = measurements[count++];
        m.x_m = in.parse_double(COL_X);
        m.y_m = in.parse_double(COL_Y);
        m.radial_velocity_mps = in.parse_double(COL_VR);
        m.rcs_dbsm = in.parse_double(COL_RCS);
        m.class_code = static_cast<PrimmObjectClass>(class_code);
        m.ground_truth_id = (gt.empty() || gt == "-1") ? PRIMM_NO_GROUND_TRUTH_ID
                                                       : static_cast<std::int64_t>(in.parse_u64(COL_GT_ID));
        m.sensor_id = sensor.empty() ? PRIMM_NO_SENSOR_ID : static_cast<std::int32_t>(in.parse_u64(COL_SENSOR_ID));
    }
    if (open) {
        track_frame(tracker, out, frame, timestamp_s, pose, primm::Span<const PrimmMeasurement>(measurements.data(), count),
                    tracks, world_columns);
    }

    const PrimmStats stats = tracker.stats();
    std::fprintf(stderr,
                 "imm: %" PRIu64 " frames, %" PRIu64 " measurements, %" PRIu64 " tracks started, %" PRIu64
                 " deleted -> %s\n",
                 stats.frames_tracked, stats.measurements_accepted, stats.tracks_initiated, stats.tracks_deleted,
                 output_path.c_str());
    if (std::fclose(out_guard.release()) != 0) {
        throw std::runtime_error("cannot write " + output_path);
    }
    return EXIT_SUCCESS;
}

} // namespace

int main(int argc, char **argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: %s INPUT.csv OUTPUT.csv\n", argv[0]);
        return EXIT_FAILURE;
    }
    try {
        return run(argv[1], argv[2]);
    } catch (const std::exception &error) { /* primm::Error, InputError and the rest */
        std::fprintf(stderr, "track_csv: %s\n", error.what());
    }
    return EXIT_FAILURE;
}
