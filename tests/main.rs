//! primm's integration tests, linked into one test binary.
//!
//! Each file beside this one is a module named after what it tests (`cargo test --test
//! integration tracker_allocation::` runs one of them). One binary instead of one per file keeps
//! the build small: every test binary links the whole library with its ONNX runtime, and two
//! dozen of them took more than 10 GB of disk in a debug build.
//!
//! The binary's global allocator counts allocations per thread, so that the `*_allocation`
//! modules can prove a code path allocates nothing while other tests run on other threads.

mod common;

use common::counting_allocator::CountingAllocator;

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

mod assignment;
mod assignment_allocation;
mod association;
mod class_imm;
mod cli_late_frames;
mod cli_offline;
mod cli_release;
mod cli_soak;
mod clutter_flood;
mod crate_layout;
mod duplicates;
mod eval_metrics;
mod eval_plots;
mod existence;
mod extended_objects;
mod gate_distance;
mod imm_allocation;
mod imm_behaviour;
mod imm_properties;
mod imm_spread_of_means;
mod inference_faults;
mod late_frames;
mod latency_files;
mod layered_config;
mod learned_covariance;
mod logging;
mod motion_models;
mod multipath_ghosts;
mod point_cloud_faults;
mod point_clouds;
mod predictor_allocation;
mod predictor_classes;
mod predictor_native;
mod predictor_onnx;
mod predictor_remembered;
mod predictor_request;
mod predictor_split;
mod predictor_threaded;
mod predictor_usefulness;
mod process_noise;
mod radial_velocity_update;
mod recording;
mod scenario;
mod sensor_layout;
mod sensor_models;
mod sensor_noise;
mod service_allocation;
mod service_faults;
mod service_overload;
mod service_python;
mod service_realtime;
mod service_replay;
mod shm_hygiene;
mod speculation;
mod speed_bound;
mod staged_association;
mod stationary_sensors;
mod track_loops;
mod tracker;
mod tracker_allocation;
#[cfg(feature = "tunnel")]
mod tunnel_loopback;
mod unknown_sensor_view;
mod world_frame;
