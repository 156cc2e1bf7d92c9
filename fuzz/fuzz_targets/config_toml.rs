//! libFuzzer entry of the `config_toml` target; the body is `primm_fuzz_targets::config_toml::run`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| primm_fuzz_targets::config_toml::run(data));
