//! # primm-core: the PR-IMM tracker, without I/O
//!
//! The estimation core of primm, the radar multi-object tracker of Lim, Paek and Kong's PR-IMM
//! (an Interacting Multiple Model filter over constant-velocity, constant-acceleration and
//! coordinated-turn Kalman filters plus a learned displacement predictor). It is what an
//! automotive middleware embeds: measurements and their validation, the Gaussian machinery, the
//! motion models, the IMM, per-class optimal association, the track table, the tracker, the
//! configuration types and their validation, and the [`predictor::DisplacementPredictor`]
//! trait through which a learned model (for example `primm-predictor`'s ONNX runtime) plugs in.
//!
//! * **`no_std`.** With default features off the crate needs only `core` and `alloc`; float
//!   functions then come from libm. The `std` feature (on by default) uses std's float
//!   functions and picks the fastest build of the per-track loops for the CPU at run time.
//!   The two builds may differ in the last bits of a transcendental function, so results are
//!   bit-for-bit repeatable within one build, not across them.
//! * **Fixed allocation.** Memory is allocated once, while a [`tracker::Tracker`] is built;
//!   every capacity is in [`limits`], and a step allocates nothing.
//! * **No clock.** Time comes from the frames, so a replay gives the same tracks every time.
//! * **No file formats.** The TOML configuration file is read by `primm-config`; here the
//!   configuration is a plain value with [`config::Config::validate`].
//! * **`serde`** (optional feature): `Serialize`/`Deserialize` for the configuration and the
//!   output types.
//!
//! ```
//! use primm_core::config::Config;
//! use primm_core::measurement::{Frame, Measurement, ObjectClass};
//! use primm_core::mode::Method;
//! use primm_core::tracker::Tracker;
//!
//! let mut tracker = Tracker::new(Config::default().with_modes(Method::Imm.modes()))?;
//! let mut frame = Frame::new(0.0);
//! frame.measurements.push(Measurement {
//!     x_m: 20.0,
//!     y_m: 1.5,
//!     radial_velocity_mps: 4.0,
//!     rcs_dbsm: 8.0,
//!     class: ObjectClass::Car,
//!     sensor_id: Some(0),
//!     ground_truth_id: None,
//! });
//! let mut tracks = 0;
//! tracker.step_into(&frame, |track| {
//!     assert_eq!(track.class, ObjectClass::Car);
//!     tracks += 1;
//! })?;
//! assert_eq!(tracks, 1);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![cfg_attr(not(feature = "std"), no_std)]

extern crate alloc;

pub mod association;
pub mod class_label;
pub mod config;
pub mod coordinates;
pub mod displacement_check;
pub mod duplicates;
pub mod existence;
pub mod extent;
pub mod gaussian;
pub mod grouping;
pub mod imm;
pub mod invariants;
pub mod limits;
mod math;
pub mod measurement;
pub mod mode;
pub mod motion;
pub mod occlusion;
pub mod pose;
pub mod prediction;
pub mod predictor;
pub mod readable_number;
mod recorded_frame;
mod replay;
pub mod sensor;
pub mod sensor_noise;
pub mod stage_timing;
pub mod track;
pub mod track_loops;
pub mod track_table;
pub mod tracker;
mod validated_frame;
pub mod validation;
