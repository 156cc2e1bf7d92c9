/*
 * primm.hpp: a header-only C++17 wrapper over the primm C API (primm.h).
 *
 *   primm::Tracker tracker(primm::Options().method(PRIMM_METHOD_IMM));
 *   std::vector<PrimmTrack> buffer(PRIMM_MAX_TRACKS);
 *   tracker.step(timestamp_s, pose, primm::Span<const PrimmMeasurement>(measurements));
 *   for (const PrimmTrack &track : tracker.tracks(buffer)) { ... }
 *
 * - primm::Tracker owns one PrimmTracker handle: it is destroyed with the object, and the
 *   object can be moved but not copied (a handle has exactly one owner).
 * - Errors are exceptions: every failed C call throws primm::Error, which carries the
 *   PrimmStatus and the library's detailed message (the configuration key, the model problem,
 *   the frame fault). A rejected frame (PRIMM_STATUS_INVALID_FRAME) leaves the tracker as it
 *   was, so a caller may catch the exception and go on with the next frame. A header and a
 *   library of different ABI versions throw primm::AbiMismatch when the first tracker is built.
 *   Nothing throws on the success path, and the success path allocates nothing: step() and
 *   tracks() only write into the caller's buffers.
 * - Buffers stay the caller's: primm::Span<T> is a pointer and a count (C++17 has no
 *   std::span), built from a pointer and a size, a C array, a std::array or a std::vector.
 *
 * Threads: a Tracker may move between threads but must not be used by two at once; error
 * messages are kept per thread and per tracker, as in the C API. Build lines, CMake and
 * pkg-config: docs/integrating-c-cpp.md.
 */
#ifndef PRIMM_HPP
#define PRIMM_HPP

#include "primm.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace primm {

/* A view of `size` contiguous elements owned by someone else: a pointer and a count. */
template <typename T> class Span {
  public:
    using element_type = T;
    using value_type = std::remove_cv_t<T>;
    using iterator = T *;

    constexpr Span() noexcept = default;
    constexpr Span(T *data, std::size_t size) noexcept : data_(data), size_(size) {}
    template <std::size_t N> constexpr Span(T (&array)[N]) noexcept : data_(array), size_(N) {}
    template <typename U, std::size_t N,
              typename = std::enable_if_t<std::is_convertible_v<U (*)[], T (*)[]>>>
    constexpr Span(std::array<U, N> &array) noexcept : data_(array.data()), size_(N) {}
    template <typename U, std::size_t N,
              typename = std::enable_if_t<std::is_convertible_v<const U (*)[], T (*)[]>>>
    constexpr Span(const std::array<U, N> &array) noexcept : data_(array.data()), size_(N) {}
    template <typename U, typename A, typename = std::enable_if_t<std::is_convertible_v<U (*)[], T (*)[]>>>
    Span(std::vector<U, A> &vector) noexcept : data_(vector.data()), size_(vector.size()) {}
    template <typename U, typename A,
              typename = std::enable_if_t<std::is_convertible_v<const U (*)[], T (*)[]>>>
    Span(const std::vector<U, A> &vector) noexcept : data_(vector.data()), size_(vector.size()) {}
    /* A Span<T> converts to a Span<const T>. */
    template <typename U, typename = std::enable_if_t<std::is_convertible_v<U (*)[], T (*)[]>>>
    constexpr Span(const Span<U> &other) noexcept : data_(other.data()), size_(other.size()) {}

    constexpr T *data() const noexcept { return data_; }
    constexpr std::size_t size() const noexcept { return size_; }
    constexpr bool empty() const noexcept { return size_ == 0; }
    constexpr T *begin() const noexcept { return data_; }
    constexpr T *end() const noexcept { return data_ + size_; }
    /* Unchecked, like std::span. */
    constexpr T &operator[](std::size_t index) const noexcept { return data_[index]; }
    /* The first `count` elements (count <= size()). */
    constexpr Span first(std::size_t count) const noexcept { return Span(data_, count); }

  private:
    T *data_ = nullptr;
    std::size_t size_ = 0;
};

/* A failed call of the C API: its status and the library's message. */
class Error : public std::runtime_error {
  public:
    Error(PrimmStatus status, const std::string &message) : std::runtime_error(message), status_(status) {}
    /* The status code the C call returned. */
    PrimmStatus status() const noexcept { return status_; }

  private:
    PrimmStatus status_;
};

/* The header (PRIMM_ABI_VERSION) and the linked library (primm_abi_version()) differ. */
class AbiMismatch : public std::runtime_error {
  public:
    AbiMismatch(std::uint32_t header_abi_version, std::uint32_t library_abi_version)
        : std::runtime_error("primm.h has ABI version " + std::to_string(header_abi_version) +
                             " but the linked primm library has ABI version " +
                             std::to_string(library_abi_version) +
                             ": rebuild the program against the library's own headers"),
          header_abi_version_(header_abi_version), library_abi_version_(library_abi_version) {}
    std::uint32_t header_abi_version() const noexcept { return header_abi_version_; }
    std::uint32_t library_abi_version() const noexcept { return library_abi_version_; }

  private:
    std::uint32_t header_abi_version_;
    std::uint32_t library_abi_version_;
};

/* The release version of the linked library, e.g. "0.2.0". */
inline const char *version() noexcept { return primm_version(); }

/* The ABI version of the linked library (compare PRIMM_ABI_VERSION). */
inline std::uint32_t abi_version() noexcept { return primm_abi_version(); }

/* Throws AbiMismatch when the linked library does not have this header's ABI version. */
inline void check_abi_version() {
    if (primm_abi_version() != PRIMM_ABI_VERSION) {
        throw AbiMismatch(PRIMM_ABI_VERSION, primm_abi_version());
    }
}

namespace detail {

/* Reads a message through a C function with the snprintf contract (returns the full length). */
template <typename Read> std::string read_message(Read read) {
    char small[256];
    std::size_t length = read(small, sizeof small);
    if (length < sizeof small) {
        return std::string(small, length);
    }
    std::string text(length + 1, '\0');
    length = read(&text[0], text.size());
    text.resize(length < text.size() ? length : text.size() - 1);
    return text;
}

/* "what: status description: detail". */
inline std::string describe(const char *what, PrimmStatus status, const std::string &detail) {
    std::string message = what;
    message += ": ";
    message += primm_status_message(static_cast<std::int32_t>(status));
    if (!detail.empty()) {
        message += ": ";
        message += detail;
    }
    return message;
}

/* Throws Error for a failed call that is not on a tracker (the calling thread's message). */
inline void check(PrimmStatus status, const char *what) {
    if (status != PRIMM_STATUS_OK) {
        const std::string detail =
            read_message([](char *buf, std::size_t len) { return primm_last_error_message(buf, len); });
        throw Error(status, describe(what, status, detail));
    }
}

} // namespace detail

/* The text primm's CSV files write for a number (the shortest form that reads back exactly). */
inline std::string format_f64(double value) {
    char text[512];
    const std::size_t length = primm_format_f64(value, text, sizeof text);
    return std::string(text, length < sizeof text ? length : sizeof text - 1);
}

/* The CSV name of an object class code ("car", "pedestrian", "two_wheeler"), or nullptr. */
inline const char *object_class_name(PrimmObjectClass class_code) noexcept {
    return primm_object_class_name(class_code);
}

/* The class code of a CSV class name; throws Error (PRIMM_STATUS_INVALID_ARGUMENT) when unknown. */
inline PrimmObjectClass object_class_from_name(const std::string &name) {
    const std::int32_t code = primm_object_class_from_name(name.c_str());
    if (code < 0) {
        throw Error(PRIMM_STATUS_INVALID_ARGUMENT, "unknown object class `" + name + "`");
    }
    return static_cast<PrimmObjectClass>(code);
}

/* How a Tracker is built: primm_tracker_options_default() with setters. The configuration text
 * is copied; model bytes are borrowed and must stay alive until the Tracker is built. */
class Options {
  public:
    Options() noexcept : raw_(primm_tracker_options_default()) {}

    /* Configuration TOML text (the format of config/primm.toml); empty for the defaults. */
    Options &config_toml(std::string text) {
        config_toml_ = std::move(text);
        return *this;
    }
    /* One of the PRIMM_METHOD_* codes. */
    Options &method(PrimmMethod method) noexcept {
        raw_.method = method;
        return *this;
    }
    /* ONNX model bytes of a PR model (borrowed until the Tracker is built). */
    Options &model_onnx(Span<const std::uint8_t> bytes) noexcept {
        raw_.model_onnx = bytes.data();
        raw_.model_onnx_len = bytes.size();
        return *this;
    }
    /* Whether the built-in PR model is used when no model bytes are given. */
    Options &use_builtin_model(bool use) noexcept {
        raw_.use_builtin_model = use;
        return *this;
    }
    /* Whether the PR model runs on an inference thread instead of inside step(). */
    Options &inference_thread(bool use) noexcept {
        raw_.inference_thread = use;
        return *this;
    }

    /* The C options; valid while this object lives and is not changed. */
    PrimmTrackerOptions raw() const noexcept {
        PrimmTrackerOptions options = raw_;
        options.config_toml = config_toml_.empty() ? nullptr : config_toml_.c_str();
        return options;
    }

  private:
    PrimmTrackerOptions raw_;
    std::string config_toml_;
};

/* The owner of one primm tracker. Move-only; the handle is destroyed with the object. */
class Tracker {
  public:
    /* Builds a tracker; throws AbiMismatch, or Error with the library's message. */
    explicit Tracker(const Options &options = Options()) {
        check_abi_version();
        const PrimmTrackerOptions raw = options.raw();
        detail::check(primm_tracker_create(&raw, &handle_), "primm_tracker_create");
    }

    /* Takes ownership of a handle from primm_tracker_create (not NULL). */
    static Tracker adopt(PrimmTracker *handle) noexcept { return Tracker(handle); }

    ~Tracker() { primm_tracker_destroy(handle_); }

    Tracker(const Tracker &) = delete;
    Tracker &operator=(const Tracker &) = delete;
    Tracker(Tracker &&other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
    Tracker &operator=(Tracker &&other) noexcept {
        if (this != &other) {
            primm_tracker_destroy(handle_);
            handle_ = std::exchange(other.handle_, nullptr);
        }
        return *this;
    }

    /* Tracks one frame in the vehicle frame (no ego pose). Throws Error; a rejected frame leaves
     * the tracker as it was. */
    PrimmStepSummary step(double timestamp_s, Span<const PrimmMeasurement> measurements) {
        return step(timestamp_s, nullptr, measurements);
    }

    /* Tracks one frame with the ego pose at its time (see primm_tracker_step_with_pose). */
    PrimmStepSummary step(double timestamp_s, const PrimmEgoPose &pose, Span<const PrimmMeasurement> measurements) {
        return step(timestamp_s, &pose, measurements);
    }

    /* Tracks one frame with the ego pose `*pose`, or none when `pose` is nullptr. */
    PrimmStepSummary step(double timestamp_s, const PrimmEgoPose *pose, Span<const PrimmMeasurement> measurements) {
        PrimmStepSummary summary{};
        check(primm_tracker_step_with_pose(require(), timestamp_s, pose, measurements.data(), measurements.size(),
                                           &summary),
              "primm_tracker_step_with_pose");
        return summary;
    }

    /* Copies the last step's tracks into `out` and returns the filled part of it. Throws Error
     * (PRIMM_STATUS_BUFFER_TOO_SMALL) when `out` is too small; PRIMM_MAX_TRACKS entries always
     * fit. */
    Span<PrimmTrack> tracks(Span<PrimmTrack> out) {
        std::size_t count = 0;
        check(primm_tracker_tracks(require(), out.data(), out.size(), &count), "primm_tracker_tracks");
        return out.first(count);
    }

    /* The number of tracks of the last step (a query with no buffer: the C API answers
     * PRIMM_STATUS_BUFFER_TOO_SMALL with the count whenever there is a track). */
    std::size_t track_count() {
        std::size_t count = 0;
        const PrimmStatus status = primm_tracker_tracks(require(), nullptr, 0, &count);
        if (status != PRIMM_STATUS_BUFFER_TOO_SMALL) {
            check(status, "primm_tracker_tracks");
        }
        return count;
    }

    /* Writes every track's prediction to `timestamp_s` into `out` without changing the
     * tracker (see primm_tracker_predict_to) and returns the filled part of it; `pose` is the
     * ego pose at that time, or nullptr. Throws Error for a time out of range or too small a
     * buffer. */
    Span<PrimmTrack> predict_to(double timestamp_s, const PrimmEgoPose *pose, Span<PrimmTrack> out) {
        std::size_t count = 0;
        check(primm_tracker_predict_to(require(), timestamp_s, pose, out.data(), out.size(), &count),
              "primm_tracker_predict_to");
        return out.first(count);
    }

    /* The newest tracked frame's time: the time of the tracks (NaN before the first frame). */
    double newest_timestamp() {
        double timestamp_s = 0.0;
        check(primm_tracker_newest_timestamp(require(), &timestamp_s), "primm_tracker_newest_timestamp");
        return timestamp_s;
    }

    /* The counters since the tracker was built. */
    PrimmStats stats() {
        PrimmStats stats{};
        check(primm_tracker_stats(require(), &stats), "primm_tracker_stats");
        return stats;
    }

    /* Drops every track and forgets the last timestamp (counters are kept). */
    void reset() { check(primm_tracker_reset(require()), "primm_tracker_reset"); }

    /* The message of the last failed call on this tracker (empty when none failed). */
    std::string last_error() const {
        const PrimmTracker *handle = handle_;
        return detail::read_message(
            [handle](char *buf, std::size_t len) { return primm_tracker_last_error(handle, buf, len); });
    }

    /* The C handle (still owned by this object); nullptr after a move. */
    PrimmTracker *get() const noexcept { return handle_; }
    /* Gives up ownership: the caller destroys the returned handle. */
    PrimmTracker *release() noexcept { return std::exchange(handle_, nullptr); }
    /* Whether this object owns a handle (false after a move or release()). */
    explicit operator bool() const noexcept { return handle_ != nullptr; }

  private:
    explicit Tracker(PrimmTracker *handle) noexcept : handle_(handle) {}

    /* The handle; a moved-from Tracker throws Error (PRIMM_STATUS_NULL_ARGUMENT) instead of
     * passing NULL on. */
    PrimmTracker *require() const {
        if (handle_ == nullptr) {
            throw Error(PRIMM_STATUS_NULL_ARGUMENT, "primm::Tracker: the tracker was moved from or released");
        }
        return handle_;
    }

    /* Throws Error with this tracker's message for a failed call. */
    void check(PrimmStatus status, const char *what) const {
        if (status != PRIMM_STATUS_OK) {
            throw Error(status, detail::describe(what, status, last_error()));
        }
    }

    PrimmTracker *handle_ = nullptr;
};

} // namespace primm

#endif /* PRIMM_HPP */
