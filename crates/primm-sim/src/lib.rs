//! # primm-sim: radar scenarios, file formats and evaluation
//!
//! Everything primm needs around the tracker but never on its real-time path:
//!
//! * [`scenario`]: a seeded generator of realistic automotive radar sequences (road layouts,
//!   cars and pedestrians, four interleaved radars with noise and missed detections, optional
//!   clutter and multipath ghosts), with train / validation / evaluation splits and presets;
//! * [`io`]: the measurement CSV format (also written by `tools/radarscenes_to_csv.py` from
//!   RadarScenes), the track CSV format and the association CSV format;
//! * [`offline`]: running a tracker over a recorded sequence;
//! * [`oracle`]: a displacement predictor that reads the true motion (a diagnostic: the ceiling
//!   of any learned predictor);
//! * [`eval`]: the metrics and tables of the paper's Section IV, JSON and SVG figures.
//!
//! ```
//! use primm_core::config::Config;
//! use primm_core::mode::Method;
//! use primm_core::tracker::Tracker;
//! use primm_sim::offline::track_sequence;
//! use primm_sim::scenario::{Preset, ScenarioGenerator};
//!
//! let mut scenario = Preset::Default.config();
//! scenario.sequence.duration_s = 2.0;
//! let sequence = ScenarioGenerator::new(scenario)?.generate_seeded(7, "example").sequence;
//! let mut tracker = Tracker::new(Config::default().with_modes(Method::Imm.modes()))?;
//! let mut rows = 0;
//! track_sequence(&mut tracker, &sequence, |_frame, tracks| rows += tracks.len())?;
//! assert!(rows > 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod eval;
pub mod io;
pub mod offline;
pub mod oracle;
pub mod scenario;
