//! libFuzzer entry of the `c_api_calls` target; the body is `primm_fuzz_targets::c_api_calls::run`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| primm_fuzz_targets::c_api_calls::run(data));
