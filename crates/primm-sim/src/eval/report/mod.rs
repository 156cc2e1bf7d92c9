//! Aggregation of per-method results into the paper's result tables and JSON.
//!
//! [`MethodEvaluator`] consumes the rows of one method sequence by sequence; its
//! [`MethodResult`] holds additive counters only, so results of separately evaluated sequences
//! can be merged. [`EvaluationReport`] collects the results of all methods, prints
//!
//! * Table II (`tab:prior_rmse`): RMSE_x, RMSE_y, RMSE_xy per method, by class, and the
//!   velocity errors (velocity RMSE per class, speed and heading errors of confirmed tracks),
//! * Table III (`tab:scenario_rmse`): RMSE_xy per motion scenario (rows) and method (columns),
//! * Table IV (`tab:overall_mot`): IDSW and IDF1 per method,
//! * Table V (`tab:scenario_mot`): IDSW and IDF1 per interaction/missed-detection scenario
//!   (rows) and method (columns),
//! * the mean PR-IMM mode probabilities (`fig:mode_probability`),
//! * beside the paper's tables, identity, false tracks and fragmentations on confirmed tracks
//!   only ([`super::confirmed`]),
//!
//! as aligned plain text, marking the best value of each comparison with `*`, and writes the same
//! numbers as JSON. A method without results is printed as `n/a`, never estimated.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use primm_core::measurement::ObjectClass;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::confirmed::{confirmed_track_counts, ConfirmedTrackCounts};
use super::document::ReportDocument;
use super::ego_motion::EgoMotion;
use super::identity::{identity_counts, identity_counts_subset, IdentityCounts};
use super::interaction::{interaction_flags, InteractionRules};
use super::modes::{ModeProbabilityAccumulator, MODE_NAMES};
use super::record::{
    ground_truth_frame_rows, object_classes, object_frame_rows, AssociationRecord, EvalError, Method,
};
use super::rmse::RmseAccumulator;
use super::scenario::{classify_sequence, MotionCategory, ScenarioRules};
mod tables;

use super::velocity::{SpeedHeadingAccumulator, VelocityRmseAccumulator, HEADING_MIN_TRUE_SPEED_MPS};
pub(crate) use tables::group_thousands;

/// Drop rates, in percent, of the missed-detection rows printed even without data.
pub const DEFAULT_MISS_PERCENTS: [u32; 2] = [10, 20];

/// Everything measured for one method; all fields add up over sequences.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MethodResult {
    /// The method.
    pub method: Method,
    /// Number of nominal sequences evaluated.
    pub sequences: u64,
    /// Prior RMSE over all rows with a prior.
    pub rmse: RmseAccumulator,
    /// Prior RMSE per motion scenario.
    pub scenario_rmse: BTreeMap<MotionCategory, RmseAccumulator>,
    /// Ground-truth object frames per motion scenario (with or without a prior).
    pub scenario_gt_frames: BTreeMap<MotionCategory, u64>,
    /// Identity counts of the nominal sequences.
    pub identity: IdentityCounts,
    /// Identity counts restricted to the close-proximity subset.
    pub close_proximity: IdentityCounts,
    /// Identity counts restricted to the crossing-motion subset.
    pub crossing: IdentityCounts,
    /// Identity counts of the missed-detection re-runs, keyed by drop rate in percent.
    pub missed_detection: BTreeMap<u32, IdentityCounts>,
    /// Posterior mode probabilities of all updates.
    pub modes: ModeProbabilityAccumulator,
    /// Prior RMSE per object class.
    #[serde(default)]
    pub class_rmse: BTreeMap<ObjectClass, RmseAccumulator>,
    /// Prior RMSE per object class over the rows a confirmed track took
    /// ([`AssociationRecord::is_confirmed_track_frame`]): the error of the tracks a user sees.
    #[serde(default)]
    pub class_confirmed_rmse: BTreeMap<ObjectClass, RmseAccumulator>,
    /// Posterior mode probabilities of the updates per object class (classes with updates only).
    #[serde(default)]
    pub class_modes: BTreeMap<ObjectClass, ModeProbabilityAccumulator>,
    /// Prior RMSE per ego motion (sequences with ego poses only).
    #[serde(default)]
    pub ego_rmse: BTreeMap<EgoMotion, RmseAccumulator>,
    /// Identity counts per ego motion (sequences with ego poses only).
    #[serde(default)]
    pub ego_identity: BTreeMap<EgoMotion, IdentityCounts>,
    /// Counts on confirmed tracks of the nominal sequences; `None` once a sequence's rows did
    /// not say whether their tracks were confirmed (then the counts of the others would mislead).
    #[serde(default)]
    pub confirmed: Option<ConfirmedTrackCounts>,
    /// Velocity RMSE over the rows of the prior RMSE that carry both velocities.
    #[serde(default)]
    pub velocity: VelocityRmseAccumulator,
    /// Velocity RMSE per object class.
    #[serde(default)]
    pub class_velocity: BTreeMap<ObjectClass, VelocityRmseAccumulator>,
    /// Speed and heading errors of confirmed tracks.
    #[serde(default)]
    pub confirmed_motion: SpeedHeadingAccumulator,
    /// Speed and heading errors of confirmed tracks per object class.
    #[serde(default)]
    pub class_confirmed_motion: BTreeMap<ObjectClass, SpeedHeadingAccumulator>,
}

impl MethodResult {
    /// An empty result.
    pub fn new(method: Method) -> Self {
        Self {
            method,
            sequences: 0,
            rmse: RmseAccumulator::new(),
            scenario_rmse: BTreeMap::new(),
            scenario_gt_frames: BTreeMap::new(),
            identity: IdentityCounts::default(),
            close_proximity: IdentityCounts::default(),
            crossing: IdentityCounts::default(),
            missed_detection: BTreeMap::new(),
            modes: ModeProbabilityAccumulator::new(),
            class_rmse: BTreeMap::new(),
            class_confirmed_rmse: BTreeMap::new(),
            class_modes: BTreeMap::new(),
            ego_rmse: BTreeMap::new(),
            ego_identity: BTreeMap::new(),
            confirmed: Some(ConfirmedTrackCounts::default()),
            velocity: VelocityRmseAccumulator::new(),
            class_velocity: BTreeMap::new(),
            confirmed_motion: SpeedHeadingAccumulator::new(),
            class_confirmed_motion: BTreeMap::new(),
        }
    }

    /// Adds the counters of another result of the same method (other sequences).
    ///
    /// # Panics
    /// When the methods differ.
    pub fn merge(&mut self, other: &MethodResult) {
        assert_eq!(self.method, other.method, "cannot merge results of different methods");
        self.sequences += other.sequences;
        self.rmse.merge(&other.rmse);
        for (category, acc) in &other.scenario_rmse {
            self.scenario_rmse.entry(*category).or_default().merge(acc);
        }
        for (category, count) in &other.scenario_gt_frames {
            *self.scenario_gt_frames.entry(*category).or_default() += count;
        }
        self.identity.merge(&other.identity);
        self.close_proximity.merge(&other.close_proximity);
        self.crossing.merge(&other.crossing);
        for (percent, counts) in &other.missed_detection {
            self.missed_detection.entry(*percent).or_default().merge(counts);
        }
        self.modes.merge(&other.modes);
        for (class, acc) in &other.class_rmse {
            self.class_rmse.entry(*class).or_default().merge(acc);
        }
        for (class, acc) in &other.class_confirmed_rmse {
            self.class_confirmed_rmse.entry(*class).or_default().merge(acc);
        }
        for (class, acc) in &other.class_modes {
            self.class_modes.entry(*class).or_default().merge(acc);
        }
        for (motion, acc) in &other.ego_rmse {
            self.ego_rmse.entry(*motion).or_default().merge(acc);
        }
        for (motion, counts) in &other.ego_identity {
            self.ego_identity.entry(*motion).or_default().merge(counts);
        }
        match (&mut self.confirmed, &other.confirmed) {
            (Some(mine), Some(theirs)) => mine.merge(theirs),
            _ => self.confirmed = None,
        }
        self.velocity.merge(&other.velocity);
        for (class, acc) in &other.class_velocity {
            self.class_velocity.entry(*class).or_default().merge(acc);
        }
        self.confirmed_motion.merge(&other.confirmed_motion);
        for (class, acc) in &other.class_confirmed_motion {
            self.class_confirmed_motion.entry(*class).or_default().merge(acc);
        }
    }

    /// RMSE accumulator of a motion scenario (empty if none was seen).
    pub fn scenario(&self, category: MotionCategory) -> RmseAccumulator {
        self.scenario_rmse.get(&category).copied().unwrap_or_default()
    }

    /// Ground-truth object frames of a motion scenario.
    pub fn scenario_frames(&self, category: MotionCategory) -> u64 {
        self.scenario_gt_frames.get(&category).copied().unwrap_or(0)
    }
}

/// Evaluates one method sequence by sequence.
#[derive(Debug, Clone)]
pub struct MethodEvaluator {
    scenario_rules: ScenarioRules,
    interaction_rules: InteractionRules,
    result: MethodResult,
}

impl MethodEvaluator {
    /// An evaluator with the default scenario and interaction rules.
    pub fn new(method: Method) -> Self {
        Self {
            scenario_rules: ScenarioRules::default(),
            interaction_rules: InteractionRules::default(),
            result: MethodResult::new(method),
        }
    }

    /// Adds the rows of one nominal sequence (all of its measurements). Metrics computed row by
    /// row count one row per object frame and track ([`object_frame_rows`]); per-class metrics
    /// score an object's rows under its majority class ([`object_classes`]).
    pub fn add_sequence(&mut self, records: &[AssociationRecord]) {
        let labels = classify_sequence(records, &self.scenario_rules);
        let flags = interaction_flags(records, &self.interaction_rules);
        let representative = object_frame_rows(records);
        let object_frame = ground_truth_frame_rows(records);
        let classes = object_classes(records);
        let result = &mut self.result;
        let rows = records.iter().zip(&labels).zip(representative.iter().zip(&object_frame)).zip(&classes);
        for (((record, label), (&representative, &object_frame)), &class) in rows {
            if let Some(label) = label.filter(|_| object_frame) {
                *result.scenario_gt_frames.entry(label.category()).or_default() += 1;
            }
            if !representative {
                continue;
            }
            result.rmse.push_record(record);
            result.class_rmse.entry(class).or_default().push_record(record);
            if record.is_confirmed_track_frame() {
                result.class_confirmed_rmse.entry(class).or_default().push_record(record);
            }
            if result.velocity.push_record(record) {
                result.class_velocity.entry(class).or_default().push_record(record);
            }
            if result.confirmed_motion.push_record(record) {
                result.class_confirmed_motion.entry(class).or_default().push_record(record);
            }
            if result.modes.push_record(record) {
                result.class_modes.entry(class).or_default().push_record(record);
            }
            if let Some(label) = label {
                result.scenario_rmse.entry(label.category()).or_default().push_record(record);
            }
        }
        result.identity.merge(&identity_counts(records));
        let close: Vec<bool> = flags.iter().map(|flag| flag.close_proximity).collect();
        result.close_proximity.merge(&identity_counts_subset(records, &close));
        let crossing: Vec<bool> = flags.iter().map(|flag| flag.crossing).collect();
        result.crossing.merge(&identity_counts_subset(records, &crossing));
        match (&mut result.confirmed, confirmed_track_counts(records)) {
            (Some(total), Ok(counts)) => total.merge(&counts),
            _ => result.confirmed = None,
        }
        result.sequences += 1;
    }

    /// Adds the rows of one nominal sequence (as given to [`add_sequence`](Self::add_sequence))
    /// to the per-ego-motion results, with each row's ego motion (`None`: unknown, not counted).
    pub fn add_ego_motion(&mut self, records: &[AssociationRecord], labels: &[Option<EgoMotion>]) {
        for motion in EgoMotion::ALL {
            let selected: Vec<bool> = labels.iter().map(|label| *label == Some(motion)).collect();
            if !selected.contains(&true) {
                continue;
            }
            let acc = self.result.ego_rmse.entry(motion).or_default();
            let representative = object_frame_rows(records);
            for ((record, _), _) in
                records.iter().zip(&selected).zip(&representative).filter(|((_, &s), &r)| s && r)
            {
                acc.push_record(record);
            }
            self.result
                .ego_identity
                .entry(motion)
                .or_default()
                .merge(&identity_counts_subset(records, &selected));
        }
    }

    /// Adds the rows of one sequence re-run with `drop_percent` % of its measurements removed
    /// (see [`super::dropout`]); dropped measurements must be present as rows without a track.
    pub fn add_missed_detection_sequence(&mut self, drop_percent: u32, records: &[AssociationRecord]) {
        self.result.missed_detection.entry(drop_percent).or_default().merge(&identity_counts(records));
    }

    /// The result so far.
    pub fn result(&self) -> &MethodResult {
        &self.result
    }

    /// The final result.
    pub fn finish(self) -> MethodResult {
        self.result
    }
}

/// Results of all methods plus the reasons of those that could not be evaluated.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct EvaluationReport {
    results: BTreeMap<Method, MethodResult>,
    unavailable: BTreeMap<Method, String>,
}

impl EvaluationReport {
    /// An empty report; every method is `n/a` until a result is inserted.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds (or merges into) the result of a method.
    pub fn insert(&mut self, result: MethodResult) {
        self.unavailable.remove(&result.method);
        match self.results.get_mut(&result.method) {
            Some(existing) => existing.merge(&result),
            None => {
                self.results.insert(result.method, result);
            }
        }
    }

    /// Records why a method has no result (e.g. no prediction model available). Ignored when the
    /// method already has a result.
    pub fn mark_unavailable(&mut self, method: Method, reason: impl Into<String>) {
        if !self.results.contains_key(&method) {
            self.unavailable.insert(method, reason.into());
        }
    }

    /// The result of a method, if evaluated.
    pub fn result(&self, method: Method) -> Option<&MethodResult> {
        self.results.get(&method)
    }

    /// The recorded reason a method is unavailable.
    pub fn unavailable_reason(&self, method: Method) -> Option<&str> {
        self.unavailable.get(&method).map(String::as_str)
    }

    /// Missed-detection drop rates to show: the defaults plus any present in a result.
    pub fn miss_percents(&self) -> Vec<u32> {
        let mut percents: Vec<u32> = DEFAULT_MISS_PERCENTS.to_vec();
        for result in self.results.values() {
            percents.extend(result.missed_detection.keys().copied());
        }
        percents.sort_unstable();
        percents.dedup();
        percents
    }

    /// All tables, separated by blank lines (Table VI only with ego poses).
    pub fn to_text(&self) -> String {
        [
            self.table_prior_rmse(),
            self.table_class_rmse(),
            self.table_velocity(),
            self.table_scenario_rmse(),
            self.table_overall_mot(),
            self.table_scenario_mot(),
            self.table_ego_motion(),
            self.table_confirmed_tracks(),
            self.mode_probability_table(),
        ]
        .into_iter()
        .filter(|table| !table.is_empty())
        .collect::<Vec<_>>()
        .join("\n")
    }

    /// The report as JSON: [`ReportDocument`] (its module documents the schema) as a
    /// [`serde_json::Value`].
    pub fn to_json(&self) -> Value {
        serde_json::to_value(ReportDocument::of(self)).expect("the report document serialises")
    }

    /// Writes [`EvaluationReport::to_json`] pretty-printed to `path`.
    pub fn write_json(&self, path: impl AsRef<Path>) -> Result<(), EvalError> {
        let text = serde_json::to_string_pretty(&self.to_json())?;
        std::fs::write(path, text + "\n")?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::tables::*;
    use super::*;
    use crate::eval::record::test_support::position_row;
    use glam::DVec2;
    use serde_json::json;

    /// One sequence: object 1 drives straight along +x at 10 m/s for 12 frames (0.1 s apart);
    /// object 2 drives parallel 3 m to the left. The tracker of `method` gives object 1 track 1
    /// throughout and object 2 track 2 until frame 5, then track 3 (one switch). Every prior is
    /// off by `error` metres in x, except each track's first row (no prior).
    fn sequence(error: f64) -> Vec<AssociationRecord> {
        let mut rows = Vec::new();
        for k in 0..12u64 {
            let t = k as f64 * 0.1;
            let p1 = DVec2::new(10.0 * t, 0.0);
            let mut r1 = position_row(k, t, 1, p1);
            r1.track_id = Some(1);
            r1.prior = (k > 0).then_some(p1 + DVec2::new(error, 0.0));
            r1.mode_probabilities = Some([0.4, 0.3, 0.2, 0.1]);
            rows.push(r1);
            let p2 = DVec2::new(10.0 * t, 3.0);
            let mut r2 = position_row(k, t, 2, p2);
            r2.track_id = Some(if k <= 5 { 2 } else { 3 });
            r2.prior = (k > 0 && k != 6).then_some(p2 + DVec2::new(error, 0.0));
            r2.mode_probabilities = Some([0.1, 0.2, 0.3, 0.4]);
            rows.push(r2);
        }
        rows
    }

    fn evaluate(method: Method, error: f64) -> MethodResult {
        let mut evaluator = MethodEvaluator::new(method);
        evaluator.add_sequence(&sequence(error));
        evaluator.finish()
    }

    #[test]
    fn several_detections_of_an_object_are_scored_once_per_frame_under_its_majority_class() {
        // Object 1 (a car) seen with three detections per frame over 12 frames, all taken by
        // track 1 with the same prior; one detection in three frames is labelled pedestrian.
        let mut records = Vec::new();
        for frame in 0..12u64 {
            let truth = DVec2::new(frame as f64, 0.0);
            for k in 0..3 {
                let mut row = position_row(frame, frame as f64 * 0.1, 1, truth);
                row.measured = truth + DVec2::new(0.0, k as f64);
                row.prior = (frame > 0).then_some(truth + DVec2::X * 0.5);
                if k == 2 && frame % 4 == 0 {
                    row.class = ObjectClass::Pedestrian;
                }
                records.push(row);
            }
        }
        let mut evaluator = MethodEvaluator::new(Method::Imm);
        evaluator.add_sequence(&records);
        let result = evaluator.finish();
        // One prior per frame after the first, all under the car class.
        assert_eq!(result.rmse.count(), 11);
        assert!((result.rmse.rmse_xy().unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(result.class_rmse.keys().copied().collect::<Vec<_>>(), vec![ObjectClass::Car]);
        assert_eq!(result.class_rmse[&ObjectClass::Car].count(), 11);
        assert_eq!((result.identity.gt_object_frames, result.identity.idtp), (12, 12));
        // The straight motion is labelled from the tenth frame on, once per frame.
        assert_eq!(result.scenario_frames(MotionCategory::Straight), 3);
    }

    #[test]
    fn a_class_error_over_confirmed_rows_leaves_out_the_tentative_tracks_priors() {
        // Object 1's track is tentative for its first four frames, with priors 3 m off; later
        // 0.5 m off. Object 2's rows are all confirmed, 0.5 m off.
        let mut records = sequence(0.5);
        for record in records.iter_mut().filter(|record| record.ground_truth_id == Some(1)) {
            if record.frame < 4 {
                record.track_confirmed = Some(false);
                record.prior = record.prior.map(|_| record.true_position.unwrap() + DVec2::new(3.0, 0.0));
            }
        }
        let mut evaluator = MethodEvaluator::new(Method::Imm);
        evaluator.add_sequence(&records);
        let result = evaluator.finish();
        let all = result.class_rmse[&ObjectClass::Car];
        let confirmed = result.class_confirmed_rmse[&ObjectClass::Car];
        // All rows: 3 tentative priors (frames 1-3) 3 m off, 18 at 0.5 m.
        assert_eq!((all.count(), confirmed.count()), (21, 18));
        assert!((all.rmse_xy().unwrap() - ((3.0 * 9.0 + 18.0 * 0.25) / 21.0f64).sqrt()).abs() < 1e-12);
        assert!((confirmed.rmse_xy().unwrap() - 0.5).abs() < 1e-12);
        let document = crate::eval::document::MethodDocument::of(&result);
        let car = &document.scenarios.classes["class_car"];
        assert_eq!((car.confirmed_rmse_xy, car.confirmed_rmse_samples), (confirmed.rmse_xy(), Some(18)));
        // Merging adds the confirmed rows as well.
        let mut merged = result.clone();
        merged.merge(&result);
        assert_eq!(merged.class_confirmed_rmse[&ObjectClass::Car].count(), 36);
    }

    #[test]
    fn evaluator_collects_all_metrics() {
        let result = evaluate(Method::PrImm, 0.5);
        // Priors: object 1 has 11, object 2 has 10 (frames 0 and 6 start tracks) → 21 samples.
        assert_eq!(result.rmse.count(), 21);
        assert!((result.rmse.rmse_x().unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(result.rmse.rmse_y(), Some(0.0));
        // Identity: 24 GT frames, 24 estimated; overlap (1,1)=12, (2,2)=6, (2,3)=6 → IDTP 18.
        assert_eq!(result.identity.idsw, 1);
        assert_eq!(result.identity.idtp, 18);
        assert_eq!((result.identity.idfp, result.identity.idfn), (6, 6));
        // The objects are 3 m apart in every frame → every row is close proximity; parallel
        // headings → no crossing.
        assert_eq!(result.close_proximity.gt_object_frames, 24);
        assert_eq!(result.close_proximity.idsw, 1);
        assert_eq!(result.crossing.gt_object_frames, 0);
        // Straight motion: rows of frames 9..=11 of both objects have ten positions → 6 rows.
        assert_eq!(result.scenario_frames(MotionCategory::Straight), 6);
        assert_eq!(result.scenario(MotionCategory::Straight).count(), 6);
        assert_eq!(result.scenario_frames(MotionCategory::Turn), 0);
        // Mode probabilities averaged over 24 updates: (0.25, 0.25, 0.25, 0.25).
        let mean = result.modes.mean().unwrap();
        assert!(mean.iter().all(|p| (p - 0.25).abs() < 1e-12));
    }

    #[test]
    fn velocity_errors_are_reported_per_class_in_the_table_and_the_json() {
        // Object 1 (car): true (10, 0), estimate (10, 1): error 1 m/s, heading atan(0.1).
        // Object 2 (pedestrian): true (1, 0), estimate (4, 0): error 3 m/s, heading 0.
        // Object 1's first row is a tentative track's: no speed or heading sample there.
        let mut records = sequence(0.5);
        for record in &mut records {
            if record.ground_truth_id == Some(1) {
                record.true_velocity = Some(DVec2::new(10.0, 0.0));
                record.velocity = Some(DVec2::new(10.0, 1.0));
            } else {
                record.class = ObjectClass::Pedestrian;
                record.true_velocity = Some(DVec2::new(1.0, 0.0));
                record.velocity = Some(DVec2::new(4.0, 0.0));
            }
        }
        records[0].track_confirmed = Some(false);
        let mut evaluator = MethodEvaluator::new(Method::Imm);
        evaluator.add_sequence(&records);
        let imm = evaluator.finish();
        // Rows with a prior: 11 of object 1, 10 of object 2.
        assert_eq!(imm.velocity.count(), 21);
        let expected = ((11.0 * 1.0 + 10.0 * 9.0) / 21.0f64).sqrt();
        assert!((imm.velocity.rmse_mps().unwrap() - expected).abs() < 1e-12);
        assert_eq!(imm.class_velocity[&ObjectClass::Car].rmse_mps(), Some(1.0));
        assert_eq!(imm.class_velocity[&ObjectClass::Pedestrian].rmse_mps(), Some(3.0));
        // Confirmed rows: 11 of object 1, 12 of object 2 (starting rows included).
        let motion = imm.confirmed_motion;
        assert_eq!((motion.speed_count(), motion.heading_count()), (23, 23));
        let car_speed_error = 101f64.sqrt() - 10.0;
        let speed_rmse = ((11.0 * car_speed_error.powi(2) + 12.0 * 9.0) / 23.0).sqrt();
        assert!((motion.speed_rmse_mps().unwrap() - speed_rmse).abs() < 1e-12);
        let heading_rmse = (11.0 * 0.1f64.atan().powi(2) / 23.0).sqrt().to_degrees();
        assert!((motion.heading_rmse_deg().unwrap() - heading_rmse).abs() < 1e-9);

        // Merging two halves gives the joint result.
        let mut merged = evaluate(Method::Imm, 0.5);
        merged.merge(&imm);
        assert_eq!(merged.velocity, imm.velocity);
        assert_eq!(merged.class_confirmed_motion, imm.class_confirmed_motion);

        let mut report = EvaluationReport::new();
        report.insert(imm);
        report.insert(evaluate(Method::ConstantVelocity, 1.0)); // rows without velocities
        let table = report.table_velocity();
        assert!(table.starts_with("Table II, velocity"), "{table}");
        // Only one method has values: nothing is marked.
        let cells = row(&table, "IMM (CV+CA+CT)");
        assert_eq!(cells[..4], [format!("{expected:.3}"), "1.000".into(), "3.000".into(), "21".into()]);
        assert_eq!(cells[4], format!("{speed_rmse:.3}"));
        assert_eq!(cells[6], format!("{heading_rmse:.2}"));
        assert_eq!(cells[7], "23");
        assert_eq!(row(&table, "CV "), vec!["n/a", "n/a", "n/a", "0", "n/a", "n/a", "n/a", "0"]);
        assert!(!table.contains("the data carry no true velocity"));
        assert!(report.to_text().contains("Table II, velocity"));

        let json = report.to_json();
        let velocity = &json["methods"]["imm"]["velocity"];
        assert!((velocity["rmse_mps"].as_f64().unwrap() - expected).abs() < 1e-12);
        assert_eq!(velocity["samples"], json!(21));
        assert_eq!(velocity["by_class"]["pedestrian"]["rmse_mps"], json!(3.0));
        assert_eq!(velocity["by_class"]["car"]["rmse_x_mps"], json!(0.0));
        let confirmed = &velocity["confirmed_tracks"];
        assert_eq!(confirmed["speed_samples"], json!(23));
        assert_eq!(confirmed["by_class"]["pedestrian"]["speed_mean_error_mps"], json!(3.0));
        assert_eq!(confirmed["by_class"]["pedestrian"]["heading_rmse_deg"], json!(0.0));
        assert_eq!(velocity["heading_min_true_speed_mps"], json!(HEADING_MIN_TRUE_SPEED_MPS));
        assert!(json["methods"]["cv"]["velocity"]["rmse_mps"].is_null());
        assert_eq!(json["methods"]["cv"]["velocity"]["samples"], json!(0));
        assert!(json["methods"]["pr"]["velocity"].is_null());

        // Data without true velocities say so.
        let mut report = EvaluationReport::new();
        report.insert(evaluate(Method::Imm, 1.0));
        assert!(report.table_velocity().contains("n/a: the data carry no true velocity"));
    }

    #[test]
    fn mode_probabilities_are_averaged_per_class_as_well() {
        let mut records = sequence(0.5);
        // Object 2's rows become pedestrians: (0.1, 0.2, 0.3, 0.4) there, (0.4, 0.3, 0.2, 0.1)
        // for the cars; a row without a track is counted nowhere.
        for record in records.iter_mut().filter(|r| r.ground_truth_id == Some(2)) {
            record.class = ObjectClass::Pedestrian;
        }
        records[0].track_id = None;
        let mut evaluator = MethodEvaluator::new(Method::PrImm);
        evaluator.add_sequence(&records);
        let result = evaluator.finish();
        let car = result.class_modes[&ObjectClass::Car];
        let pedestrian = result.class_modes[&ObjectClass::Pedestrian];
        assert_eq!((car.count(), pedestrian.count()), (11, 12));
        assert_eq!(car.count() + pedestrian.count(), result.modes.count());
        let close = |got: [f64; 4], want: [f64; 4]| got.iter().zip(want).all(|(g, w)| (g - w).abs() < 1e-12);
        assert!(close(car.mean().unwrap(), [0.4, 0.3, 0.2, 0.1]), "{car:?}");
        assert!(close(pedestrian.mean().unwrap(), [0.1, 0.2, 0.3, 0.4]), "{pedestrian:?}");
        assert!(!result.class_modes.contains_key(&ObjectClass::TwoWheeler));
        // Single-model methods have none.
        let mut evaluator = MethodEvaluator::new(Method::ConstantVelocity);
        let mut plain = records.clone();
        plain.iter_mut().for_each(|r| r.mode_probabilities = None);
        evaluator.add_sequence(&plain);
        assert!(evaluator.finish().class_modes.is_empty());
    }

    #[test]
    fn merged_results_equal_joint_evaluation() {
        let mut joint = MethodEvaluator::new(Method::ConstantVelocity);
        joint.add_sequence(&sequence(1.0));
        joint.add_sequence(&sequence(2.0));
        let joint = joint.finish();
        let mut merged = evaluate(Method::ConstantVelocity, 1.0);
        merged.merge(&evaluate(Method::ConstantVelocity, 2.0));
        // Sums of floating-point squares may differ in the last bit with the order of addition;
        // all integer counters must agree exactly.
        assert_eq!(merged.identity, joint.identity);
        assert_eq!(merged.close_proximity, joint.close_proximity);
        assert_eq!(merged.crossing, joint.crossing);
        assert_eq!(merged.scenario_gt_frames, joint.scenario_gt_frames);
        assert_eq!(merged.rmse.count(), joint.rmse.count());
        assert!((merged.rmse.rmse_xy().unwrap() - joint.rmse.rmse_xy().unwrap()).abs() < 1e-12);
        assert_eq!(merged.modes, joint.modes);
        assert_eq!(merged.class_modes, joint.class_modes);
        assert_eq!(merged.confirmed, joint.confirmed);
        assert_eq!(merged.confirmed.unwrap().sequences, 2);
        assert_eq!(merged.sequences, 2);
        assert_eq!(merged.identity.idsw, 2);
        // RMSE over both: sqrt((21·1 + 21·4) / 42) = sqrt(2.5).
        assert!((merged.rmse.rmse_x().unwrap() - 2.5f64.sqrt()).abs() < 1e-12);
    }

    fn report() -> EvaluationReport {
        let mut report = EvaluationReport::new();
        report.insert(evaluate(Method::ConstantVelocity, 2.0));
        report.insert(evaluate(Method::Imm, 1.0));
        let mut pr_imm = MethodEvaluator::new(Method::PrImm);
        pr_imm.add_sequence(&sequence(0.5));
        // A 10 % miss re-run where two measurements were dropped (rows without track).
        let mut reduced = sequence(0.5);
        reduced[4].track_id = None;
        reduced[4].prior = None;
        reduced[9].track_id = None;
        reduced[9].prior = None;
        pr_imm.add_missed_detection_sequence(10, &reduced);
        report.insert(pr_imm.finish());
        report.mark_unavailable(Method::Learned, "no prediction model loaded");
        report
    }

    #[test]
    fn json_shape() {
        let json = report().to_json();
        let methods = json["methods"].as_object().unwrap();
        let keys: Vec<&str> = methods.keys().map(String::as_str).collect();
        let mut expected: Vec<&str> = Method::ALL.iter().map(|m| m.key()).collect();
        expected.sort_unstable();
        assert_eq!(keys, expected);
        for key in ["rmse_x", "rmse_y", "rmse_xy", "idsw", "idf1", "scenarios"] {
            assert!(methods["cv"].get(key).is_some(), "missing {key}");
            assert!(methods["pr"].get(key).is_some(), "missing {key} in unavailable entry");
        }
        assert_eq!(methods["cv"]["rmse_x"].as_f64().unwrap(), 2.0);
        assert_eq!(methods["pr_imm"]["idsw"].as_u64().unwrap(), 1);
        assert!((methods["pr_imm"]["idf1"].as_f64().unwrap() - 36.0 / 48.0).abs() < 1e-12);
        // Unavailable and never-evaluated methods are null, not zero.
        assert_eq!(methods["pr"]["available"], json!(false));
        assert_eq!(methods["pr"]["reason"], json!("no prediction model loaded"));
        assert!(methods["pr"]["rmse_xy"].is_null() && methods["pr"]["idf1"].is_null());
        assert!(methods["ct"]["idsw"].is_null());
        // Scenario entries.
        let scenarios = methods["pr_imm"]["scenarios"].as_object().unwrap();
        for key in [
            "straight",
            "accel_decel",
            "left_right_turn",
            "nonlinear",
            "close_proximity",
            "crossing_motion",
            "miss_10",
        ] {
            assert!(scenarios.contains_key(key), "missing scenario {key}");
        }
        assert_eq!(scenarios["straight"]["gt_object_frames"], json!(6));
        assert!(scenarios["accel_decel"]["rmse_xy"].is_null());
        assert_eq!(scenarios["close_proximity"]["gt_object_frames"], json!(24));
        assert_eq!(scenarios["crossing_motion"]["idf1"], Value::Null);
        // Miss run: 24 GT frames, 22 tracked; overlap (1,1)=11, (2,2)=5, (2,3)=6 → IDTP 17.
        assert_eq!(scenarios["miss_10"]["gt_object_frames"], json!(24));
        assert_eq!(scenarios["miss_10"]["idtp"], json!(17));
        assert!(!methods["cv"]["scenarios"].as_object().unwrap().contains_key("miss_10"));
        let modes = &json["mode_probabilities"];
        assert_eq!(modes["method"], json!("pr_imm"));
        assert_eq!(modes["samples"], json!(24));
        for key in ["pr", "cv", "ca", "ct"] {
            assert!((modes[key].as_f64().unwrap() - 0.25).abs() < 1e-12);
        }
    }

    #[test]
    fn report_state_serialises_and_restores() {
        // The additive state (not the rendered JSON) can be stored and merged later.
        let report = report();
        let text = serde_json::to_string(&report).unwrap();
        let restored: EvaluationReport = serde_json::from_str(&text).unwrap();
        assert_eq!(restored.to_json(), report.to_json());
        assert_eq!(restored.unavailable_reason(Method::Learned), Some("no prediction model loaded"));
    }

    #[test]
    fn json_round_trips_through_text() {
        let dir = std::env::temp_dir().join(format!("primm-eval-report-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("report.json");
        let report = report();
        report.write_json(&path).unwrap();
        let parsed: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        assert_eq!(parsed, report.to_json());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The line of `table` whose first cell is `label`, split into cells.
    fn row<'a>(table: &'a str, label: &str) -> Vec<&'a str> {
        let line = table
            .lines()
            .find(|line| line.starts_with(label))
            .unwrap_or_else(|| panic!("no row {label} in\n{table}"));
        line[label.len()..].split_whitespace().collect()
    }

    #[test]
    fn tables_mark_best_and_print_na() {
        let report = report();
        let table = report.table_prior_rmse();
        assert_eq!(row(&table, "CV "), vec!["2.000", "0.000*", "2.000", "21"]);
        assert_eq!(row(&table, "PR-IMM"), vec!["0.500*", "0.000*", "0.500*", "21"]);
        assert_eq!(row(&table, "PR "), vec!["n/a", "n/a", "n/a", "n/a"]);
        assert!(table.contains("n/a PR: no prediction model loaded"));
        assert!(table.contains("n/a CT: not evaluated"));
        let table = report.table_overall_mot();
        assert!(table.contains("GT object frames = 24"));
        assert_eq!(row(&table, "IMM (CV+CA+CT)"), vec!["1*", "0.7500*", "18", "6", "6"]);
        let table = report.table_scenario_rmse();
        assert_eq!(row(&table, "Straight (6)"), vec!["2.000", "n/a", "n/a", "n/a", "1.000", "0.500*"]);
        assert_eq!(row(&table, "Left/Right Turn (0)"), vec!["n/a"; 6]);
        let table = report.table_scenario_mot();
        assert_eq!(row(&table, "Close Proximity (24)"), vec!["IDSW", "1*", "n/a", "n/a", "n/a", "1*", "1*"]);
        // Only PR-IMM has a 10 % run: a single value is not marked.
        assert_eq!(row(&table, "10% Miss (24)"), vec!["IDSW", "n/a", "n/a", "n/a", "n/a", "n/a", "1"]);
        assert_eq!(row(&table, "20% Miss (n/a)"), vec!["IDSW", "n/a", "n/a", "n/a", "n/a", "n/a", "n/a"]);
        let table = report.mode_probability_table();
        assert!(table.contains("updates = 24"));
        assert_eq!(row(&table, "PR "), vec!["0.250", "##########"]);
        let text = report.to_text();
        for title in ["Table II", "Table III", "Table IV", "Table V", "Mean mode probability"] {
            assert!(text.contains(title));
        }
    }

    #[test]
    fn the_confirmed_tracks_table_and_json_count_only_rows_of_confirmed_tracks() {
        // Track 3 takes over object 2 in frame 6 and is confirmed from frame 8 on: object 2 is
        // uncovered in frames 6 and 7 (one fragmentation), and its switch happens in frame 8.
        let mut records = sequence(0.5);
        for record in records.iter_mut().filter(|r| r.track_id == Some(3) && r.frame < 8) {
            record.track_confirmed = Some(false);
        }
        let mut evaluator = MethodEvaluator::new(Method::Imm);
        evaluator.add_sequence(&records);
        let imm = evaluator.finish();
        // The paper's counts are untouched by the status.
        assert_eq!(imm.identity, evaluate(Method::Imm, 0.5).identity);
        let confirmed = imm.confirmed.unwrap();
        // 24 GT frames, 22 confirmed rows; overlap (1,1)=12, (2,2)=6, (2,3)=4 → IDTP 18.
        assert_eq!(confirmed.identity.estimated_object_frames, 22);
        assert_eq!((confirmed.identity.idtp, confirmed.identity.idfp, confirmed.identity.idfn), (18, 4, 6));
        assert_eq!((confirmed.identity.idsw, confirmed.fragmentations), (1, 1));
        assert_eq!((confirmed.confirmed_tracks, confirmed.false_tracks), (3, 0));
        assert!((confirmed.duration_s - 1.1).abs() < 1e-9);

        // Rows that do not say whether their track was confirmed (an old association file).
        let mut unknown = sequence(0.5);
        unknown.iter_mut().for_each(|record| record.track_confirmed = None);
        let mut evaluator = MethodEvaluator::new(Method::ConstantVelocity);
        evaluator.add_sequence(&sequence(0.5));
        evaluator.add_sequence(&unknown);
        let cv = evaluator.finish();
        assert_eq!(cv.confirmed, None);
        assert_eq!(cv.identity.idsw, 2, "the paper's metrics still count every sequence");

        let mut report = EvaluationReport::new();
        report.insert(imm);
        report.insert(cv);
        report.insert(evaluate(Method::PrImm, 0.5));
        let table = report.table_confirmed_tracks();
        assert!(table.starts_with("Confirmed tracks (GT object frames = 24, clutter rows = 0"), "{table}");
        // 22 confirmed track frames over 24 object frames; no row says whether it is a ghost.
        assert_eq!(
            row(&table, "IMM (CV+CA+CT)"),
            vec!["0.7826*", "1*", "4*", "0*", "0.00*", "1", "0*", "0.92", "n/a", "3"]
        );
        assert_eq!(
            row(&table, "PR-IMM"),
            vec!["0.7500", "1*", "6", "0*", "0.00*", "0*", "0*", "1.00", "n/a", "3"]
        );
        assert_eq!(row(&table, "CV "), vec!["n/a"; 10]);
        assert!(table.contains("n/a CV: the rows do not say whether their track was confirmed"), "{table}");
        assert!(table.contains("n/a PR: not evaluated"), "{table}");
        assert!(report.to_text().contains("Confirmed tracks"));

        let json = report.to_json();
        let imm = &json["methods"]["imm"]["confirmed_tracks"];
        assert_eq!(imm["idfp"], json!(4));
        assert_eq!(imm["fragmentations"], json!(1));
        assert_eq!(imm["tracks"], json!(3));
        assert_eq!(imm["false_tracks_per_minute"], json!(0.0));
        assert!((imm["idf1"].as_f64().unwrap() - 36.0 / 46.0).abs() < 1e-12);
        assert!(json["methods"]["cv"]["confirmed_tracks"].is_null());
        assert!(json["methods"]["pr"]["confirmed_tracks"].is_null());
    }

    #[test]
    fn best_marking_compares_displayed_values() {
        let cells = mark_best(&[Some(1.0004), Some(1.0001), None, Some(2.0)], Better::Lower, 3);
        let text: Vec<String> = cells.iter().map(Cell::to_string).collect();
        assert_eq!(text, vec!["1.000*", "1.000*", "n/a", "2.000"]);
        let cells = mark_best(&[Some(954.0), Some(1245.0)], Better::Higher, 0);
        let text: Vec<String> = cells.iter().map(Cell::to_string).collect();
        assert_eq!(text, vec!["954", "1,245*"]);
        assert_eq!(group_thousands(17866), "17,866");
        assert_eq!(group_thousands(999), "999");
        assert_eq!(group_thousands(1_000_000), "1,000,000");
    }

    #[test]
    fn inserting_twice_merges_and_clears_unavailable() {
        let mut report = EvaluationReport::new();
        report.mark_unavailable(Method::ConstantVelocity, "later");
        report.insert(evaluate(Method::ConstantVelocity, 1.0));
        report.insert(evaluate(Method::ConstantVelocity, 1.0));
        assert_eq!(report.unavailable_reason(Method::ConstantVelocity), None);
        assert_eq!(report.result(Method::ConstantVelocity).unwrap().sequences, 2);
        report.mark_unavailable(Method::ConstantVelocity, "ignored");
        assert_eq!(report.unavailable_reason(Method::ConstantVelocity), None);
    }
}
