//! The service's only clock: `CLOCK_MONOTONIC` in nanoseconds, comparable between processes
//! on the same host (Python's `time.monotonic_ns()` and C's `clock_gettime(CLOCK_MONOTONIC)`
//! read the same clock).

/// `CLOCK_MONOTONIC` now, ns. Allocation-free (a vDSO call on Linux).
#[inline]
pub fn monotonic_ns() -> u64 {
    let mut now = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `now` is a valid, writable timespec; CLOCK_MONOTONIC always exists on the
    // platforms iceoryx2 supports, so the call cannot fail.
    unsafe {
        libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut now);
    }
    (now.tv_sec as u64).wrapping_mul(1_000_000_000).wrapping_add(now.tv_nsec as u64)
}
