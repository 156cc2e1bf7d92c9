//! libFuzzer entry of the `ego_pose_frames` target; the body is `primm_fuzz_targets::ego_pose_frames::run`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| primm_fuzz_targets::ego_pose_frames::run(data));
