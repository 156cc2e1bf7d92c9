//! # primm-service: the tracker as a shared-memory service (iceoryx2)
//!
//! ```text
//! primm/measurements ──► TrackingService ──► primm/tracks
//!  (MeasurementFrame)     Tracker::step_observed      (TrackFrame, written in place)
//!                         reads the sample in place ──► primm/latency (LatencyReport)
//! ```
//!
//! - [`catalog`]: service names and QoS, shared by every primm program.
//! - [`tracking`]: the tracking loop.
//! - [`latency`]: latency histograms, reports and tables.
//! - [`clock`]: the monotonic clock the latencies are measured with.
//! - [`shutdown`]: SIGINT/SIGTERM handling.
//! - [`log_limit`]: bounded logging of repeated faults.
//! - [`logging`]: the programs' log output.
//!
//! The publisher's replay loop and the subscriber's loop live in the `primm-publisher` and
//! `primm-subscriber` packages; both use [`catalog`] to open the same services.

pub mod catalog;
pub mod clock;
pub mod latency;
pub mod log_limit;
pub mod logging;
pub mod shutdown;
pub mod tracking;

pub use catalog::{ConnectError, ServiceNames};
pub use shutdown::ShutdownFlag;
pub use tracking::{ServiceCounters, TrackingLoopError, TrackingOptions, TrackingService, WaitMode};
