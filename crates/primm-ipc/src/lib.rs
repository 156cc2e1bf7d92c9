//! # primm-ipc: what primm's programs share around iceoryx2
//!
//! Every primm program that talks over shared memory opens the same services, reads the same
//! clock, stops on the same signals and logs the same way. This crate holds that plumbing, and
//! nothing of the tracker's loop, so that a program that only sends or receives frames does not
//! build the tracking service:
//!
//! - [`catalog`]: service names and QoS, shared by every primm program.
//! - [`clock`]: the monotonic clock the latencies are measured with.
//! - [`shutdown`]: SIGINT/SIGTERM handling.
//! - [`log_limit`]: bounded logging of repeated faults.
//! - [`logging`]: the programs' log output.
//! - [`realtime`]: CPU affinity, `SCHED_FIFO` priority and locked memory for the programs' threads.
//! - [`latency`]: latency histograms, reports and tables.
//! - [`latency_files`]: the histograms as HdrHistogram interval logs (`.hlog`) and percentile
//!   distributions (`.hgrm`) in a directory (`--latency-out`).
//! - [`latency_plot`]: latency-by-percentile plots (SVG).
//!
//! Its users: `primm-service` (the tracking loop, which re-exports these modules under its own
//! name, so the `primm` binary reaches them there), `primm-publisher`, `primm-subscriber` and
//! `primm-tunnel`. The `clap` feature adds the command-line options of the real-time settings
//! (`realtime::RealtimeArgs`, `realtime::TrackerRealtimeArgs`).

pub mod catalog;
pub mod clock;
pub mod latency;
pub mod latency_files;
pub mod latency_plot;
pub mod log_limit;
pub mod logging;
pub mod realtime;
pub mod shutdown;

pub use catalog::{ConnectError, ServiceNames};
pub use shutdown::ShutdownFlag;
