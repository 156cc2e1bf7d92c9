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
//! - [`frame_step`]: one received frame through the tracker, as the loop does it.
//! - [`latency`]: latency histograms, reports and tables.
//! - [`latency_files`]: the histograms as HdrHistogram interval logs (`.hlog`) and percentile
//!   distributions (`.hgrm`) in a directory (`--latency-out`).
//! - [`latency_plot`]: latency-by-percentile plots (SVG).
//! - [`clock`]: the monotonic clock the latencies are measured with.
//! - [`shutdown`]: SIGINT/SIGTERM handling.
//! - [`log_limit`]: bounded logging of repeated faults.
//! - [`logging`]: the programs' log output.
//! - [`realtime`]: CPU affinity, `SCHED_FIFO` priority and locked memory for the programs' threads.
//!
//! The publisher's replay loop and the subscriber's loop live in the `primm-publisher` and
//! `primm-subscriber` packages; both use [`catalog`] to open the same services.
//!
//! Hosting a tracker (any `DisplacementPredictor`; here the physics-only IMM) under a private
//! prefix, so that it does not meet another setup on the same machine:
//!
//! ```no_run
//! use primm_core::config::Config;
//! use primm_core::mode::Method;
//! use primm_core::tracker::Tracker;
//! use primm_service::{ServiceNames, ShutdownFlag, TrackingOptions, TrackingService};
//!
//! let tracker = Tracker::new(Config::default().with_modes(Method::Imm.modes()))?;
//! let options = TrackingOptions { names: ServiceNames::new("example"), ..TrackingOptions::default() };
//! let mut service = TrackingService::new(tracker, options)?;
//! let shutdown = ShutdownFlag::on_signals()?;
//! service.run(&shutdown)?; // until SIGINT or SIGTERM
//! println!("{}", service.summary());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod catalog;
pub mod clock;
pub mod frame_step;
pub mod latency;
pub mod latency_files;
pub mod latency_plot;
pub mod log_limit;
pub mod logging;
pub mod realtime;
pub mod shutdown;
pub mod tracking;

pub use catalog::{ConnectError, ServiceNames};
pub use shutdown::ShutdownFlag;
pub use tracking::{
    PublishTime, ServiceCounters, TrackingLoopError, TrackingOptions, TrackingService, WaitMode,
};
