//! libFuzzer entry of the `tracker_steps` target; the body is `primm_fuzz_targets::tracker_steps::run`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| primm_fuzz_targets::tracker_steps::run(data));
