//! libFuzzer entry of the `measurement_csv` target; the body is `primm_fuzz_targets::measurement_csv::run`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| primm_fuzz_targets::measurement_csv::run(data));
