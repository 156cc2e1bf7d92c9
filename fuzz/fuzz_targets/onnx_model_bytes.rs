//! libFuzzer entry of the `onnx_model_bytes` target; the body is `primm_fuzz_targets::onnx_model_bytes::run`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| primm_fuzz_targets::onnx_model_bytes::run(data));
