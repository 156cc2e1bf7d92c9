/*
 * Checks of include/primm.hpp, compiled and run by tests/c_example.rs: ownership (move-only,
 * destroyed once), errors as exceptions with the library's status and message, a rejected
 * frame leaving the tracker as it was, buffers as spans, versions. Prints "all wrapper checks
 * passed" and exits 0, or names the failed check and exits 1.
 */
#include "primm.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

static_assert(!std::is_copy_constructible_v<primm::Tracker>, "a tracker has one owner");
static_assert(!std::is_copy_assignable_v<primm::Tracker>, "a tracker has one owner");
static_assert(std::is_nothrow_move_constructible_v<primm::Tracker>, "moving a tracker cannot fail");
static_assert(std::is_nothrow_move_assignable_v<primm::Tracker>, "moving a tracker cannot fail");
static_assert(std::is_convertible_v<primm::Span<PrimmTrack>, primm::Span<const PrimmTrack>>, "T to const T");
static_assert(!std::is_convertible_v<primm::Span<const PrimmTrack>, primm::Span<PrimmTrack>>, "no const loss");

static int failures = 0;

#define CHECK(condition)                                                                                     \
    do {                                                                                                     \
        if (!(condition)) {                                                                                  \
            std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #condition);                \
            failures++;                                                                                      \
        }                                                                                                    \
    } while (0)

/* Two objects moving along x, frame k. */
static std::array<PrimmMeasurement, 2> two_objects(int k) {
    std::array<PrimmMeasurement, 2> frame{};
    const double x = 0.5 * k;
    frame[0] = PrimmMeasurement{20.0 + x, 2.0, 5.0, 10.0, 11, 2, PRIMM_OBJECT_CLASS_CAR};
    frame[1] = PrimmMeasurement{8.0, -3.0 + 0.05 * x, 5.0, 10.0, 12, 2, PRIMM_OBJECT_CLASS_PEDESTRIAN};
    return frame;
}

static primm::Tracker imm_tracker() { return primm::Tracker(primm::Options().method(PRIMM_METHOD_IMM)); }

/* The tracks as bytes, to compare states exactly. */
static std::string snapshot(primm::Tracker &tracker) {
    std::vector<PrimmTrack> buffer(PRIMM_MAX_TRACKS);
    const primm::Span<PrimmTrack> tracks = tracker.tracks(buffer);
    return std::string(reinterpret_cast<const char *>(tracks.data()), tracks.size() * sizeof(PrimmTrack));
}

static void versions() {
    CHECK(primm::abi_version() == PRIMM_ABI_VERSION);
    const std::string version = primm::version();
    CHECK(!version.empty() && std::count(version.begin(), version.end(), '.') == 2);
    primm::check_abi_version();
    const primm::AbiMismatch mismatch(PRIMM_ABI_VERSION, PRIMM_ABI_VERSION + 1);
    CHECK(std::strstr(mismatch.what(), "ABI version") != nullptr);
    CHECK(mismatch.library_abi_version() == PRIMM_ABI_VERSION + 1);
}

static void ownership() {
    primm::Tracker first = imm_tracker();
    PrimmTracker *handle = first.get();
    CHECK(handle != nullptr && static_cast<bool>(first));
    primm::Tracker second(std::move(first));
    CHECK(second.get() == handle);
    CHECK(!first && first.get() == nullptr);
    primm::Tracker third = imm_tracker();
    third = std::move(second); /* destroys third's own handle, takes the first one */
    CHECK(third.get() == handle && !second);
    primm::Tracker &same = third; /* a self-move keeps the handle */
    third = std::move(same);
    CHECK(third.get() == handle);

    /* A moved-from tracker refuses calls instead of passing NULL on. */
    const auto frame = two_objects(0);
    try {
        first.step(0.0, frame);
        CHECK(false);
    } catch (const primm::Error &error) {
        CHECK(error.status() == PRIMM_STATUS_NULL_ARGUMENT);
    }

    /* release() hands the handle over; adopt() takes one. */
    PrimmTracker *raw = third.release();
    CHECK(!third && raw == handle);
    primm::Tracker adopted = primm::Tracker::adopt(raw);
    CHECK(adopted.get() == raw);
    adopted.step(0.0, frame);
    CHECK(adopted.track_count() == 2);
}

static void errors() {
    /* A configuration error names the key, through the thread's message. */
    try {
        primm::Tracker tracker(primm::Options().method(PRIMM_METHOD_IMM).config_toml("[tracker]\nfrobnicate = 1\n"));
        CHECK(false);
    } catch (const primm::Error &error) {
        CHECK(error.status() == PRIMM_STATUS_INVALID_CONFIG);
        CHECK(std::strstr(error.what(), "primm_tracker_create") != nullptr);
        CHECK(std::strstr(error.what(), "frobnicate") != nullptr);
    }
    try {
        primm::Tracker tracker(primm::Options().method(42));
        CHECK(false);
    } catch (const primm::Error &error) {
        CHECK(error.status() == PRIMM_STATUS_INVALID_ARGUMENT);
        CHECK(std::strstr(error.what(), "unknown method code 42") != nullptr);
    }
    const std::array<std::uint8_t, 8> not_a_model = {1, 2, 3, 4, 5, 6, 7, 8};
    try {
        primm::Tracker tracker(primm::Options().method(PRIMM_METHOD_PR_IMM).model_onnx(not_a_model));
        CHECK(false);
    } catch (const primm::Error &error) {
        CHECK(error.status() == PRIMM_STATUS_INVALID_MODEL);
    }

    /* A rejected frame throws with the tracker's message and leaves the tracks as they were. */
    primm::Tracker tracker = imm_tracker();
    for (int k = 0; k < 4; k++) {
        const PrimmStepSummary summary = tracker.step(0.05 * k, two_objects(k));
        CHECK(summary.track_count == 2);
    }
    const std::string before = snapshot(tracker);
    const PrimmStats stats_before = tracker.stats();
    /* Every accepted measurement updated or started one track; no speed needed bounding. */
    CHECK(stats_before.tracks_updated + stats_before.tracks_initiated == stats_before.measurements_accepted);
    CHECK(stats_before.speeds_bounded == 0);
    try {
        tracker.step(0.05, two_objects(9));
        CHECK(false);
    } catch (const primm::Error &error) {
        CHECK(error.status() == PRIMM_STATUS_INVALID_FRAME);
        CHECK(std::strstr(error.what(), "does not advance") != nullptr);
        CHECK(tracker.last_error().find("does not advance") != std::string::npos);
    }
    const PrimmEgoPose bad_pose{std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0};
    try {
        tracker.step(0.25, bad_pose, two_objects(5));
        CHECK(false);
    } catch (const primm::Error &error) {
        CHECK(error.status() == PRIMM_STATUS_INVALID_FRAME);
        CHECK(std::strstr(error.what(), "ego pose") != nullptr);
    }
    CHECK(snapshot(tracker) == before);
    const PrimmStats stats_after = tracker.stats();
    CHECK(stats_after.frames_tracked == stats_before.frames_tracked);
    CHECK(stats_after.frames_rejected_timestamp_not_increasing == 1);
    CHECK(stats_after.frames_rejected_invalid_ego_pose == 1);

    /* The tracker goes on with the next frame. */
    tracker.step(0.20, two_objects(4));
    CHECK(tracker.stats().frames_tracked == stats_before.frames_tracked + 1);

    /* A buffer too small throws, with the count in the message; nothing is copied. */
    std::array<PrimmTrack, 1> small{};
    small[0].id = 777;
    try {
        tracker.tracks(small);
        CHECK(false);
    } catch (const primm::Error &error) {
        CHECK(error.status() == PRIMM_STATUS_BUFFER_TOO_SMALL);
        CHECK(std::strstr(error.what(), "2 are needed") != nullptr);
    }
    CHECK(small[0].id == 777);

    try {
        primm::object_class_from_name("tram");
        CHECK(false);
    } catch (const primm::Error &error) {
        CHECK(error.status() == PRIMM_STATUS_INVALID_ARGUMENT);
    }
    CHECK(primm::object_class_from_name("pedestrian") == PRIMM_OBJECT_CLASS_PEDESTRIAN);
    CHECK(primm::object_class_from_name("bus") == PRIMM_OBJECT_CLASS_CAR);
}

static void spans_and_steps() {
    primm::Tracker tracker = imm_tracker();
    const auto frame = two_objects(0);
    /* From a std::array, a C array, a vector, and a pointer with a size. */
    tracker.step(0.00, frame);
    PrimmMeasurement c_array[2] = {frame[0], frame[1]};
    tracker.step(0.05, c_array);
    std::vector<PrimmMeasurement> vector(frame.begin(), frame.end());
    tracker.step(0.10, vector);
    const PrimmEgoPose pose{100.0, -20.0, 0.3};
    const PrimmStepSummary summary = tracker.step(0.15, pose, primm::Span<const PrimmMeasurement>(vector.data(), 1));
    CHECK(summary.measurements_accepted == 1);
    const PrimmStepSummary empty = tracker.step(0.20, &pose, primm::Span<const PrimmMeasurement>());
    CHECK(empty.measurements_accepted == 0);

    std::vector<PrimmTrack> buffer(PRIMM_MAX_TRACKS);
    const primm::Span<PrimmTrack> tracks = tracker.tracks(buffer);
    CHECK(tracks.data() == buffer.data());
    CHECK(tracks.size() == tracker.track_count() && !tracks.empty());
    for (const PrimmTrack &track : tracks) {
        CHECK(track.has_world_estimate);
        CHECK(std::isfinite(track.world_x_m));
    }
    CHECK(primm::format_f64(0.1) == "0.1");
    CHECK(primm::format_f64(-2.0) == "-2");
    CHECK(std::string(primm::object_class_name(PRIMM_OBJECT_CLASS_CAR)) == "car");

    tracker.reset();
    CHECK(tracker.track_count() == 0);
    CHECK(tracker.stats().resets == 1);
    tracker.step(0.0, frame); /* time starts over after a reset */
}

int main() {
    try {
        versions();
        ownership();
        errors();
        spans_and_steps();
    } catch (const std::exception &error) {
        std::fprintf(stderr, "unexpected exception: %s\n", error.what());
        return EXIT_FAILURE;
    }
    if (failures != 0) {
        std::fprintf(stderr, "%d wrapper checks failed\n", failures);
        return EXIT_FAILURE;
    }
    std::printf("all wrapper checks passed\n");
    return EXIT_SUCCESS;
}
