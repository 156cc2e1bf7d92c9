//! libFuzzer entry of the `measurement_frame_bytes` target; the body is `primm_fuzz_targets::measurement_frame_bytes::run`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| primm_fuzz_targets::measurement_frame_bytes::run(data));
