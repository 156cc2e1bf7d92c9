//! The JSON document of an evaluation, as types: what `primm eval --json` writes and the tools
//! under `tools/` read.
//!
//! Every value here is derived from an [`EvaluationReport`] (and, for the run's settings, from
//! [`Evaluation`](super::evaluate::Evaluation)) and serialised with `serde`. Keys are written in
//! alphabetical order (the file is written through [`serde_json::Value`], whose maps are sorted),
//! so that two runs can be compared with a plain `diff`. Units are in the names (`_m`, `_mps`,
//! `_deg`, `_s`); RMSE values without a unit suffix (`rmse_x`, `rmse_y`, `rmse_xy`) are metres.
//! A metric without samples is `null`. `docs/evaluation-metrics.md` defines every metric.
//!
//! ```text
//! {
//!   "methods": { "<method key>": MethodDocument, ... },   // every method, evaluated or not
//!   "mode_probabilities": ModeProbabilitiesDocument,      // PR-IMM's mean mode probabilities
//!   "truth": "centre" | "measurement",                    // only in `primm eval`'s file
//!   "displacement_oracle": bool,                          // only in `primm eval`'s file
//!   "displacement_oracle_noise_m": number                 // with the oracle only
//! }
//! ```

use super::confirmed::ConfirmedTrackCounts;
use super::ego_motion::EgoMotion;
use super::identity::IdentityCounts;
use super::modes::{ModeProbabilityAccumulator, MODE_NAMES};
use super::record::Method;
use super::report::{EvaluationReport, MethodResult};
use super::rmse::RmseAccumulator;
use super::scenario::MotionCategory;
use super::velocity::{SpeedHeadingAccumulator, VelocityRmseAccumulator, HEADING_MIN_TRUE_SPEED_MPS};
use serde::Serialize;
use std::collections::BTreeMap;

/// The whole document of an [`EvaluationReport`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReportDocument {
    /// One entry per method of [`Method::ALL`], under its key (`cv`, `ca`, `ct`, `imm`, `pr`,
    /// `pr_imm`).
    pub methods: BTreeMap<&'static str, MethodDocument>,
    /// PR-IMM's mean mode probabilities (the paper's `fig:mode_probability`), overall and per
    /// class.
    pub mode_probabilities: ModeProbabilitiesDocument,
}

/// One method's results. A method that was not evaluated has `available: false`, a `reason`,
/// `null` metrics and no scenarios.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodDocument {
    /// Whether the method was evaluated.
    pub available: bool,
    /// Why it was not (only when `available` is false).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// One-step prior RMSE along x, m (Table II).
    pub rmse_x: Option<f64>,
    /// One-step prior RMSE along y, m.
    pub rmse_y: Option<f64>,
    /// One-step prior RMSE in the plane, m.
    pub rmse_xy: Option<f64>,
    /// Identity switches over every measurement (Table IV).
    pub idsw: Option<u64>,
    /// IDF1 over every measurement.
    pub idf1: Option<f64>,
    /// The counts behind the metrics.
    pub counts: Option<MethodCounts>,
    /// The subsets of Tables III and V, per class and by the ego vehicle's motion, keyed as
    /// [`ScenarioDocuments`] says.
    pub scenarios: ScenarioDocuments,
    /// Identity, false-track and fragmentation counts on the rows of confirmed tracks.
    pub confirmed_tracks: Option<ConfirmedTracksDocument>,
    /// Velocity errors, where the data carry true velocities.
    pub velocity: Option<VelocityDocument>,
}

/// The counts of one evaluated method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct MethodCounts {
    /// Sequences evaluated.
    pub sequences: u64,
    /// Priors scored in the RMSE.
    pub rmse_samples: u64,
    /// Ground-truth object frames ((frame, object) pairs with a measurement).
    pub gt_object_frames: u64,
    /// Estimated object frames ((frame, track) pairs with a measurement the track took).
    pub estimated_object_frames: u64,
    /// Identity true positives.
    pub idtp: u64,
    /// Identity false positives.
    pub idfp: u64,
    /// Identity false negatives.
    pub idfn: u64,
    /// Updates whose mode probabilities were averaged (PR-IMM; 0 for the other methods).
    pub mode_probability_samples: u64,
}

/// The scenario entries of one method, written as one object whose keys are
/// `straight`, `accel_decel`, `left_right_turn`, `nonlinear` ([`MotionDocument`]),
/// `close_proximity`, `crossing_motion` and `miss_<percent>` ([`IdentityDocument`]),
/// `class_<class>` ([`RmseDocument`]) and `ego_straight`, `ego_turning` ([`EgoDocument`]).
/// Empty for a method that was not evaluated.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct ScenarioDocuments {
    /// Table III: RMSE per motion scenario, by [`MotionCategory::key`].
    #[serde(flatten)]
    pub motion: BTreeMap<&'static str, MotionDocument>,
    /// Table V: identity metrics of the close-proximity subset.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub close_proximity: Option<IdentityDocument>,
    /// Table V: identity metrics of the crossing-motion subset.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub crossing_motion: Option<IdentityDocument>,
    /// Table V: identity metrics with measurements removed, keyed `miss_<percent>`.
    #[serde(flatten)]
    pub missed_detection: BTreeMap<String, IdentityDocument>,
    /// RMSE per object class, keyed `class_<class>`.
    #[serde(flatten)]
    pub classes: BTreeMap<String, RmseDocument>,
    /// Tables II and IV split by the ego vehicle's motion, keyed `ego_straight`, `ego_turning`.
    #[serde(flatten)]
    pub ego_motion: BTreeMap<&'static str, EgoDocument>,
}

/// The RMSE of one motion scenario (Table III).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MotionDocument {
    /// RMSE along x, m.
    pub rmse_x: Option<f64>,
    /// RMSE along y, m.
    pub rmse_y: Option<f64>,
    /// RMSE in the plane, m.
    pub rmse_xy: Option<f64>,
    /// Priors scored.
    pub rmse_samples: u64,
    /// Ground-truth object frames labelled with the scenario.
    pub gt_object_frames: u64,
}

/// An RMSE in the plane and its sample count, over every row and over the rows of confirmed
/// tracks.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RmseDocument {
    /// RMSE in the plane, m.
    pub rmse_xy: Option<f64>,
    /// Priors scored.
    pub rmse_samples: u64,
    /// RMSE in the plane over the rows a confirmed track took, m (`None` on other entries than
    /// classes, and where no confirmed track took a row).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub confirmed_rmse_xy: Option<f64>,
    /// Priors scored in `confirmed_rmse_xy`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub confirmed_rmse_samples: Option<u64>,
}

/// Identity metrics of a subset of the rows (Table V).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct IdentityDocument {
    /// Identity switches.
    pub idsw: u64,
    /// IDF1.
    pub idf1: Option<f64>,
    /// Identity true positives.
    pub idtp: u64,
    /// Identity false positives.
    pub idfp: u64,
    /// Identity false negatives.
    pub idfn: u64,
    /// Ground-truth object frames of the subset.
    pub gt_object_frames: u64,
    /// Estimated object frames of the subset.
    pub estimated_object_frames: u64,
}

/// Identity metrics and RMSE of the frames of one ego motion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EgoDocument {
    /// The identity metrics.
    #[serde(flatten)]
    pub identity: IdentityDocument,
    /// RMSE in the plane, m (absent when no prior was scored in such frames).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rmse_xy: Option<Option<f64>>,
    /// Priors scored (absent with `rmse_xy`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rmse_samples: Option<u64>,
}

/// The counts on confirmed tracks ([`ConfirmedTrackCounts`]), as `primm eval` and `primm score`
/// write them under `confirmed_tracks`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ConfirmedTracksDocument {
    /// Sequences counted.
    pub sequences: u64,
    /// IDF1 on the rows of confirmed tracks.
    pub idf1: Option<f64>,
    /// Identity switches.
    pub idsw: u64,
    /// Identity true positives.
    pub idtp: u64,
    /// Identity false positives (clutter rows taken count here).
    pub idfp: u64,
    /// Identity false negatives.
    pub idfn: u64,
    /// Ground-truth object frames.
    pub gt_object_frames: u64,
    /// (Frame, track) pairs of confirmed tracks.
    pub estimated_object_frames: u64,
    /// Confirmed tracks.
    pub tracks: u64,
    /// Confirmed tracks born of clutter.
    pub false_tracks: u64,
    /// False tracks per minute of data.
    pub false_tracks_per_minute: Option<f64>,
    /// Confirmed tracks per ground-truth object frame (estimated over ground-truth object
    /// frames).
    pub tracks_per_object_frame: Option<f64>,
    /// Confirmed tracks whose first measurement was a multipath ghost.
    pub ghost_born_tracks: u64,
    /// Their share of the confirmed tracks; `None` where the data do not say which
    /// measurements are ghosts.
    pub ghost_born_share: Option<f64>,
    /// Fragmentations.
    pub fragmentations: u64,
    /// Rows without a ground-truth object (clutter).
    pub clutter_rows: u64,
    /// Clutter rows taken by confirmed tracks.
    pub clutter_rows_in_confirmed_tracks: u64,
    /// Duration of the data, s.
    pub duration_s: f64,
}

impl From<&ConfirmedTrackCounts> for ConfirmedTracksDocument {
    fn from(counts: &ConfirmedTrackCounts) -> Self {
        ConfirmedTracksDocument {
            sequences: counts.sequences,
            idf1: counts.idf1(),
            idsw: counts.identity.idsw,
            idtp: counts.identity.idtp,
            idfp: counts.identity.idfp,
            idfn: counts.identity.idfn,
            gt_object_frames: counts.identity.gt_object_frames,
            estimated_object_frames: counts.identity.estimated_object_frames,
            tracks: counts.confirmed_tracks,
            false_tracks: counts.false_tracks,
            false_tracks_per_minute: counts.false_tracks_per_minute(),
            tracks_per_object_frame: counts.tracks_per_object_frame(),
            ghost_born_tracks: counts.ghost_born_tracks,
            ghost_born_share: counts.ghost_born_share(),
            fragmentations: counts.fragmentations,
            clutter_rows: counts.clutter_rows,
            clutter_rows_in_confirmed_tracks: counts.clutter_rows_in_confirmed_tracks,
            duration_s: counts.duration_s,
        }
    }
}

/// A velocity RMSE.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct VelocityRmseDocument {
    /// RMSE of the velocity vector, m/s.
    pub rmse_mps: Option<f64>,
    /// RMSE along x, m/s.
    pub rmse_x_mps: Option<f64>,
    /// RMSE along y, m/s.
    pub rmse_y_mps: Option<f64>,
    /// Velocities scored.
    pub samples: u64,
}

impl From<&VelocityRmseAccumulator> for VelocityRmseDocument {
    fn from(acc: &VelocityRmseAccumulator) -> Self {
        VelocityRmseDocument {
            rmse_mps: acc.rmse_mps(),
            rmse_x_mps: acc.rmse_x_mps(),
            rmse_y_mps: acc.rmse_y_mps(),
            samples: acc.count(),
        }
    }
}

/// Speed and heading errors of confirmed tracks.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpeedHeadingDocument {
    /// RMSE of the speed, m/s.
    pub speed_rmse_mps: Option<f64>,
    /// Mean speed error (track minus truth), m/s.
    pub speed_mean_error_mps: Option<f64>,
    /// Speeds scored.
    pub speed_samples: u64,
    /// RMSE of the heading, degrees.
    pub heading_rmse_deg: Option<f64>,
    /// Mean absolute heading error, degrees.
    pub heading_mean_abs_error_deg: Option<f64>,
    /// Headings scored (true speed at least `heading_min_true_speed_mps`).
    pub heading_samples: u64,
}

impl From<&SpeedHeadingAccumulator> for SpeedHeadingDocument {
    fn from(acc: &SpeedHeadingAccumulator) -> Self {
        SpeedHeadingDocument {
            speed_rmse_mps: acc.speed_rmse_mps(),
            speed_mean_error_mps: acc.speed_mean_error_mps(),
            speed_samples: acc.speed_count(),
            heading_rmse_deg: acc.heading_rmse_deg(),
            heading_mean_abs_error_deg: acc.heading_mean_abs_deg(),
            heading_samples: acc.heading_count(),
        }
    }
}

/// Speed and heading errors of confirmed tracks, overall and per class.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConfirmedMotionDocument {
    /// Over every class.
    #[serde(flatten)]
    pub total: SpeedHeadingDocument,
    /// Per class name.
    pub by_class: BTreeMap<&'static str, SpeedHeadingDocument>,
}

/// A method's velocity errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct VelocityDocument {
    /// The velocity RMSE over every class.
    #[serde(flatten)]
    pub total: VelocityRmseDocument,
    /// The velocity RMSE per class name.
    pub by_class: BTreeMap<&'static str, VelocityRmseDocument>,
    /// Speed and heading errors of confirmed tracks.
    pub confirmed_tracks: ConfirmedMotionDocument,
    /// Slowest true speed at which a heading is scored, m/s.
    pub heading_min_true_speed_mps: f64,
}

/// Mean mode probabilities over the updates of one accumulator; `null` without updates.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModeMeansDocument {
    /// Updates averaged.
    pub samples: u64,
    /// Mean probability of the PR mode.
    pub pr: Option<f64>,
    /// Mean probability of the CV mode.
    pub cv: Option<f64>,
    /// Mean probability of the CA mode.
    pub ca: Option<f64>,
    /// Mean probability of the CT mode.
    pub ct: Option<f64>,
}

impl From<&ModeProbabilityAccumulator> for ModeMeansDocument {
    fn from(acc: &ModeProbabilityAccumulator) -> Self {
        let mean = acc.mean();
        let mode = |name: &str| {
            let index = MODE_NAMES.iter().position(|mode| *mode == name).expect("a mode of MODE_NAMES");
            mean.map(|means| means[index])
        };
        ModeMeansDocument {
            samples: acc.count(),
            pr: mode("PR"),
            cv: mode("CV"),
            ca: mode("CA"),
            ct: mode("CT"),
        }
    }
}

/// PR-IMM's mean mode probabilities.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeProbabilitiesDocument {
    /// The method they are of (`pr_imm`).
    pub method: &'static str,
    /// Over every class.
    #[serde(flatten)]
    pub total: ModeMeansDocument,
    /// Per class name, for the classes with updates.
    pub by_class: BTreeMap<&'static str, ModeMeansDocument>,
}

impl From<&IdentityCounts> for IdentityDocument {
    fn from(counts: &IdentityCounts) -> Self {
        IdentityDocument {
            idsw: counts.idsw,
            idf1: counts.idf1(),
            idtp: counts.idtp,
            idfp: counts.idfp,
            idfn: counts.idfn,
            gt_object_frames: counts.gt_object_frames,
            estimated_object_frames: counts.estimated_object_frames,
        }
    }
}

impl From<&RmseAccumulator> for RmseDocument {
    fn from(acc: &RmseAccumulator) -> Self {
        RmseDocument {
            rmse_xy: acc.rmse_xy(),
            rmse_samples: acc.count(),
            confirmed_rmse_xy: None,
            confirmed_rmse_samples: None,
        }
    }
}

impl MethodDocument {
    /// The entry of a method that was not evaluated.
    pub fn unavailable(reason: &str) -> Self {
        MethodDocument {
            available: false,
            reason: Some(reason.to_owned()),
            rmse_x: None,
            rmse_y: None,
            rmse_xy: None,
            idsw: None,
            idf1: None,
            counts: None,
            scenarios: ScenarioDocuments::default(),
            confirmed_tracks: None,
            velocity: None,
        }
    }

    /// The entry of an evaluated method.
    pub fn of(result: &MethodResult) -> Self {
        MethodDocument {
            available: true,
            reason: None,
            rmse_x: result.rmse.rmse_x(),
            rmse_y: result.rmse.rmse_y(),
            rmse_xy: result.rmse.rmse_xy(),
            idsw: Some(result.identity.idsw),
            idf1: result.identity.idf1(),
            counts: Some(MethodCounts {
                sequences: result.sequences,
                rmse_samples: result.rmse.count(),
                gt_object_frames: result.identity.gt_object_frames,
                estimated_object_frames: result.identity.estimated_object_frames,
                idtp: result.identity.idtp,
                idfp: result.identity.idfp,
                idfn: result.identity.idfn,
                mode_probability_samples: result.modes.count(),
            }),
            scenarios: ScenarioDocuments::of(result),
            confirmed_tracks: result.confirmed.as_ref().map(ConfirmedTracksDocument::from),
            velocity: Some(VelocityDocument::of(result)),
        }
    }
}

impl ScenarioDocuments {
    fn of(result: &MethodResult) -> Self {
        let motion = MotionCategory::ALL
            .into_iter()
            .map(|category| {
                let acc = result.scenario(category);
                let document = MotionDocument {
                    rmse_x: acc.rmse_x(),
                    rmse_y: acc.rmse_y(),
                    rmse_xy: acc.rmse_xy(),
                    rmse_samples: acc.count(),
                    gt_object_frames: result.scenario_frames(category),
                };
                (category.key(), document)
            })
            .collect();
        let missed_detection = result
            .missed_detection
            .iter()
            .map(|(percent, counts)| (format!("miss_{percent}"), IdentityDocument::from(counts)))
            .collect();
        let classes = result
            .class_rmse
            .iter()
            .map(|(class, acc)| {
                let confirmed = result.class_confirmed_rmse.get(class).copied().unwrap_or_default();
                let document = RmseDocument {
                    confirmed_rmse_xy: confirmed.rmse_xy(),
                    confirmed_rmse_samples: Some(confirmed.count()),
                    ..RmseDocument::from(acc)
                };
                (format!("class_{}", class.name()), document)
            })
            .collect();
        let ego_motion = result
            .ego_identity
            .iter()
            .map(|(motion, counts)| {
                let key = match motion {
                    EgoMotion::Straight => "ego_straight",
                    EgoMotion::Turning => "ego_turning",
                };
                let rmse = result.ego_rmse.get(motion);
                let document = EgoDocument {
                    identity: IdentityDocument::from(counts),
                    rmse_xy: rmse.map(RmseAccumulator::rmse_xy),
                    rmse_samples: rmse.map(RmseAccumulator::count),
                };
                (key, document)
            })
            .collect();
        ScenarioDocuments {
            motion,
            close_proximity: Some(IdentityDocument::from(&result.close_proximity)),
            crossing_motion: Some(IdentityDocument::from(&result.crossing)),
            missed_detection,
            classes,
            ego_motion,
        }
    }
}

impl VelocityDocument {
    fn of(result: &MethodResult) -> Self {
        VelocityDocument {
            total: VelocityRmseDocument::from(&result.velocity),
            by_class: result
                .class_velocity
                .iter()
                .map(|(class, acc)| (class.name(), VelocityRmseDocument::from(acc)))
                .collect(),
            confirmed_tracks: ConfirmedMotionDocument {
                total: SpeedHeadingDocument::from(&result.confirmed_motion),
                by_class: result
                    .class_confirmed_motion
                    .iter()
                    .map(|(class, acc)| (class.name(), SpeedHeadingDocument::from(acc)))
                    .collect(),
            },
            heading_min_true_speed_mps: HEADING_MIN_TRUE_SPEED_MPS,
        }
    }
}

impl ReportDocument {
    /// The document of `report`.
    pub fn of(report: &EvaluationReport) -> Self {
        let methods = Method::ALL
            .into_iter()
            .map(|method| {
                let document = match report.result(method) {
                    Some(result) => MethodDocument::of(result),
                    None => MethodDocument::unavailable(
                        report.unavailable_reason(method).unwrap_or("not evaluated"),
                    ),
                };
                (method.key(), document)
            })
            .collect();
        let pr_imm = report.result(Method::PrImm);
        let mode_probabilities = ModeProbabilitiesDocument {
            method: Method::PrImm.key(),
            total: ModeMeansDocument::from(&pr_imm.map(|result| result.modes).unwrap_or_default()),
            by_class: pr_imm
                .into_iter()
                .flat_map(|result| &result.class_modes)
                .map(|(class, acc)| (class.name(), ModeMeansDocument::from(acc)))
                .collect(),
        };
        ReportDocument { methods, mode_probabilities }
    }
}
