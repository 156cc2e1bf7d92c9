//! # primm-service: the tracker as a shared-memory service (iceoryx2)
//!
//! ```text
//! primm/measurements ──► TrackingService ──► primm/tracks
//!  (MeasurementFrame)     Tracker::step_observed      (TrackFrame, written in place)
//!                         reads the sample in place ──► primm/latency (LatencyReport)
//! ```
//!
//! - [`tracking`]: the tracking loop.
//! - [`frame_step`]: one received frame through the tracker, as the loop does it.
//!
//! The plumbing every primm program shares lives in `primm-ipc`; its modules are re-exported
//! here, so that a program hosting the tracker names one crate: [`catalog`] (service names and
//! QoS), [`clock`], [`shutdown`], [`log_limit`], [`logging`], [`realtime`], [`latency`],
//! [`latency_files`] and [`latency_plot`].
//!
//! The publisher's replay loop and the subscriber's loop live in the `primm-publisher` and
//! `primm-subscriber` packages; both open the same services through `primm-ipc`'s catalogue and
//! do not depend on this crate.
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

pub mod frame_step;
mod summary_lines;
pub mod tracking;

pub use primm_ipc::{
    catalog, clock, latency, latency_files, latency_plot, log_limit, logging, realtime, shutdown,
};

pub use catalog::{ConnectError, ServiceNames};
pub use shutdown::ShutdownFlag;
pub use tracking::{
    PublishTime, ServiceCounters, TrackingLoopError, TrackingOptions, TrackingService, WaitMode,
};
