//! Motion-scenario labels for the scenario-wise RMSE table (`tab:scenario_rmse`).
//!
//! The paper derives scenarios from an object's previous ten ground-truth positions, timestamps
//! and headings but does not publish the rules; the rules below are this implementation's exact
//! definition (also in `docs/evaluation-metrics.md`).
//!
//! # Window
//! For a ground-truth object frame, the window is the ten most recent rows of the same
//! ground-truth object up to and including that row (the row's own position is part of the
//! motion whose prior is being scored). Positions are reference positions (true position when
//! known, else the measurement) in the records' coordinate frame, x forward and y to the left.
//! A row gets no label when fewer than ten rows are available, when two successive window rows are
//! not strictly increasing in time or are more than [`ScenarioRules::max_step_gap_s`] apart, or
//! when any step is slower than [`ScenarioRules::min_step_speed_mps`] (its heading would be
//! undefined).
//!
//! # Features (n points, n − 1 steps, n − 2 heading changes)
//! * step `i`: displacement `d_i = p_i − p_{i−1}`, duration `dt_i`, speed `v_i = |d_i| / dt_i`,
//!   heading `ψ_i = atan2(d_i.y, d_i.x)`, mid-time `τ_i = (t_i + t_{i−1}) / 2`;
//! * heading changes `Δψ_j = wrap(ψ_{j+1} − ψ_j)` into (−180°, 180°];
//! * net turn `Θ = Σ Δψ_j` (degrees, positive = counter-clockwise = left),
//!   total turn `Φ = Σ |Δψ_j|`, turn consistency `c = |Θ| / Φ` (1 when `Φ = 0`);
//! * acceleration `a`: least-squares slope of `v_i` over `τ_i` (m/s²);
//! * speed consistency `s = |Σ δv_i| / Σ |δv_i|` with `δv_i = v_{i+1} − v_i` (1 when all are 0).
//!
//! # Decision (first match wins; thresholds are the defaults of [`ScenarioRules`])
//! 1. Straight heading, `|Θ| ≤ 10°` and `Φ ≤ 20°`:
//!    `|a| < 0.5 m/s²` → **Straight**; else `s ≥ 0.6` → **Accel./Decel.**;
//!    else (speed rises and falls) → **Nonlinear**.
//! 2. Consistent turn, `|Θ| ≥ 15°` and `c ≥ 0.8`:
//!    `|a| < 1.0 m/s²` → **Left turn** (`Θ > 0`) or **Right turn** (`Θ < 0`);
//!    else (turning while changing speed strongly) → **Nonlinear**.
//! 3. Mixed heading changes, `Φ ≥ 30°` and `c < 0.8` (zig-zag, S-curve) → **Nonlinear**.
//! 4. Anything else (gentle curves, small wiggles) → no label; the row is excluded from the
//!    scenario-wise table.

use std::collections::HashMap;

use glam::DVec2;
use serde::{Deserialize, Serialize};

use super::record::{time_order, AssociationRecord, EvalError};

/// Fine-grained motion label of one ground-truth object frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionScenario {
    /// Nearly constant heading and speed.
    Straight,
    /// Nearly constant heading, speed rising or falling steadily.
    AccelDecel,
    /// Consistent counter-clockwise heading change at moderate speed change.
    LeftTurn,
    /// Consistent clockwise heading change at moderate speed change.
    RightTurn,
    /// Significant heading and/or speed changes that do not fit one of the above.
    Nonlinear,
}

impl MotionScenario {
    /// The row of the scenario-wise table this label belongs to (left and right turns share one).
    pub fn category(self) -> MotionCategory {
        match self {
            MotionScenario::Straight => MotionCategory::Straight,
            MotionScenario::AccelDecel => MotionCategory::AccelDecel,
            MotionScenario::LeftTurn | MotionScenario::RightTurn => MotionCategory::Turn,
            MotionScenario::Nonlinear => MotionCategory::Nonlinear,
        }
    }
}

/// Rows of the scenario-wise RMSE table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionCategory {
    /// Straight.
    Straight,
    /// Accel./Decel.
    AccelDecel,
    /// Left/Right Turn.
    Turn,
    /// Nonlinear.
    Nonlinear,
}

impl MotionCategory {
    /// All categories in table order.
    pub const ALL: [MotionCategory; 4] = [
        MotionCategory::Straight,
        MotionCategory::AccelDecel,
        MotionCategory::Turn,
        MotionCategory::Nonlinear,
    ];

    /// JSON key.
    pub fn key(self) -> &'static str {
        match self {
            MotionCategory::Straight => "straight",
            MotionCategory::AccelDecel => "accel_decel",
            MotionCategory::Turn => "left_right_turn",
            MotionCategory::Nonlinear => "nonlinear",
        }
    }

    /// Table label.
    pub fn label(self) -> &'static str {
        match self {
            MotionCategory::Straight => "Straight",
            MotionCategory::AccelDecel => "Accel./Decel.",
            MotionCategory::Turn => "Left/Right Turn",
            MotionCategory::Nonlinear => "Nonlinear",
        }
    }
}

/// Thresholds of the scenario rules; see the module documentation for how they are used.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ScenarioRules {
    /// Number of positions in the window, the current one included (≥ 3).
    pub window_len: usize,
    /// Largest time between two successive window positions, seconds.
    pub max_step_gap_s: f64,
    /// Smallest speed of every step, m/s; slower windows have no reliable heading.
    pub min_step_speed_mps: f64,
    /// Largest |net turn| of a straight heading, degrees.
    pub straight_max_net_turn_deg: f64,
    /// Largest total turn of a straight heading, degrees.
    pub straight_max_total_turn_deg: f64,
    /// |acceleration| below which speed counts as steady, m/s².
    pub steady_max_accel_mps2: f64,
    /// Smallest speed consistency of an accelerating or decelerating window.
    pub ramp_min_speed_consistency: f64,
    /// Smallest |net turn| of a turn, degrees.
    pub turn_min_net_turn_deg: f64,
    /// Smallest turn consistency of a turn.
    pub turn_min_consistency: f64,
    /// |acceleration| below which a turn stays a turn, m/s²; above, it is nonlinear.
    pub turn_max_accel_mps2: f64,
    /// Smallest total turn of a window with mixed turn directions to count as nonlinear, degrees.
    pub nonlinear_min_total_turn_deg: f64,
}

impl Default for ScenarioRules {
    fn default() -> Self {
        Self {
            window_len: 10,
            max_step_gap_s: 1.0,
            min_step_speed_mps: 0.5,
            straight_max_net_turn_deg: 10.0,
            straight_max_total_turn_deg: 20.0,
            steady_max_accel_mps2: 0.5,
            ramp_min_speed_consistency: 0.6,
            turn_min_net_turn_deg: 15.0,
            turn_min_consistency: 0.8,
            turn_max_accel_mps2: 1.0,
            nonlinear_min_total_turn_deg: 30.0,
        }
    }
}

/// Features of one window (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MotionFeatures {
    /// Net heading change Θ, degrees, positive counter-clockwise.
    pub net_turn_deg: f64,
    /// Total absolute heading change Φ, degrees.
    pub total_turn_deg: f64,
    /// |Θ| / Φ in [0, 1].
    pub turn_consistency: f64,
    /// Least-squares slope of step speed over time, m/s².
    pub acceleration_mps2: f64,
    /// |Σ δv| / Σ |δv| in [0, 1].
    pub speed_consistency: f64,
    /// Mean of the step speeds, m/s.
    pub mean_speed_mps: f64,
}

impl ScenarioRules {
    /// Checks that the rules can be applied.
    pub fn validate(&self) -> Result<(), EvalError> {
        if self.window_len < 3 {
            return Err(EvalError::InvalidRules(format!(
                "window_len must be at least 3, got {}",
                self.window_len
            )));
        }
        let values = [
            ("max_step_gap_s", self.max_step_gap_s),
            ("min_step_speed_mps", self.min_step_speed_mps),
            ("straight_max_net_turn_deg", self.straight_max_net_turn_deg),
            ("straight_max_total_turn_deg", self.straight_max_total_turn_deg),
            ("steady_max_accel_mps2", self.steady_max_accel_mps2),
            ("ramp_min_speed_consistency", self.ramp_min_speed_consistency),
            ("turn_min_net_turn_deg", self.turn_min_net_turn_deg),
            ("turn_min_consistency", self.turn_min_consistency),
            ("turn_max_accel_mps2", self.turn_max_accel_mps2),
            ("nonlinear_min_total_turn_deg", self.nonlinear_min_total_turn_deg),
        ];
        for (name, value) in values {
            if !value.is_finite() || value < 0.0 {
                return Err(EvalError::InvalidRules(format!(
                    "{name} must be finite and non-negative, got {value}"
                )));
            }
        }
        if self.max_step_gap_s == 0.0 {
            return Err(EvalError::InvalidRules("max_step_gap_s must be positive".into()));
        }
        Ok(())
    }

    /// Features of a window of `times` (seconds) and `positions` (metres), oldest first; `None`
    /// when the window breaks a precondition (length, time order, gap, speed).
    pub fn features(&self, times: &[f64], positions: &[DVec2]) -> Option<MotionFeatures> {
        if times.len() != positions.len() || positions.len() != self.window_len {
            return None;
        }
        let steps = positions.len() - 1;
        let mut speeds = Vec::with_capacity(steps);
        let mut mid_times = Vec::with_capacity(steps);
        let mut headings = Vec::with_capacity(steps);
        for i in 1..positions.len() {
            let dt = times[i] - times[i - 1];
            if !(dt > 0.0 && dt <= self.max_step_gap_s) {
                return None;
            }
            let displacement = positions[i] - positions[i - 1];
            let speed = displacement.length() / dt;
            if !speed.is_finite() || speed < self.min_step_speed_mps || displacement.length() == 0.0 {
                return None;
            }
            speeds.push(speed);
            mid_times.push(0.5 * (times[i] + times[i - 1]));
            headings.push(displacement.y.atan2(displacement.x));
        }
        let turns: Vec<f64> = headings.windows(2).map(|pair| wrap_angle(pair[1] - pair[0])).collect();
        let net_turn: f64 = turns.iter().sum();
        let total_turn: f64 = turns.iter().map(|turn| turn.abs()).sum();
        let turn_consistency = if total_turn > 0.0 { net_turn.abs() / total_turn } else { 1.0 };
        let speed_changes: Vec<f64> = speeds.windows(2).map(|pair| pair[1] - pair[0]).collect();
        let net_speed_change: f64 = speed_changes.iter().sum();
        let total_speed_change: f64 = speed_changes.iter().map(|change| change.abs()).sum();
        let speed_consistency =
            if total_speed_change > 0.0 { net_speed_change.abs() / total_speed_change } else { 1.0 };
        Some(MotionFeatures {
            net_turn_deg: net_turn.to_degrees(),
            total_turn_deg: total_turn.to_degrees(),
            turn_consistency,
            acceleration_mps2: least_squares_slope(&mid_times, &speeds),
            speed_consistency,
            mean_speed_mps: speeds.iter().sum::<f64>() / speeds.len() as f64,
        })
    }

    /// Label of a window's features (decision list of the module documentation).
    pub fn classify_features(&self, features: &MotionFeatures) -> Option<MotionScenario> {
        let net = features.net_turn_deg.abs();
        let accel = features.acceleration_mps2.abs();
        if net <= self.straight_max_net_turn_deg
            && features.total_turn_deg <= self.straight_max_total_turn_deg
        {
            return Some(if accel < self.steady_max_accel_mps2 {
                MotionScenario::Straight
            } else if features.speed_consistency >= self.ramp_min_speed_consistency {
                MotionScenario::AccelDecel
            } else {
                MotionScenario::Nonlinear
            });
        }
        if net >= self.turn_min_net_turn_deg && features.turn_consistency >= self.turn_min_consistency {
            return Some(if accel >= self.turn_max_accel_mps2 {
                MotionScenario::Nonlinear
            } else if features.net_turn_deg > 0.0 {
                MotionScenario::LeftTurn
            } else {
                MotionScenario::RightTurn
            });
        }
        if features.total_turn_deg >= self.nonlinear_min_total_turn_deg
            && features.turn_consistency < self.turn_min_consistency
        {
            return Some(MotionScenario::Nonlinear);
        }
        None
    }

    /// Label of a window of `times` and `positions`, oldest first.
    pub fn classify_window(&self, times: &[f64], positions: &[DVec2]) -> Option<MotionScenario> {
        self.features(times, positions).and_then(|features| self.classify_features(&features))
    }
}

/// Motion label of every row of one sequence (`None`: no ground-truth id, too little history, or
/// no rule matches). The result has one entry per row, in input order. The window holds one row
/// per frame of the object, its first in input order; the object's other rows of that frame
/// (several detections of it) take that row's label.
pub fn classify_sequence(
    records: &[AssociationRecord],
    rules: &ScenarioRules,
) -> Vec<Option<MotionScenario>> {
    let mut labels = vec![None; records.len()];
    let mut history: HashMap<u64, Vec<usize>> = HashMap::new();
    for index in time_order(records) {
        let Some(gt) = records[index].ground_truth_id else {
            continue;
        };
        let rows = history.entry(gt).or_default();
        if let Some(&last) = rows.last().filter(|&&last| records[last].frame == records[index].frame) {
            labels[index] = labels[last];
            continue;
        }
        rows.push(index);
        if rows.len() < rules.window_len {
            continue;
        }
        let window = &rows[rows.len() - rules.window_len..];
        let times: Vec<f64> = window.iter().map(|&row| records[row].timestamp_s).collect();
        let positions: Vec<DVec2> = window.iter().map(|&row| records[row].reference_position()).collect();
        labels[index] = rules.classify_window(&times, &positions);
    }
    labels
}

/// Wraps an angle in radians into (−π, π].
pub(crate) fn wrap_angle(angle: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let wrapped = angle - tau * (angle / tau).round();
    if wrapped <= -std::f64::consts::PI {
        wrapped + tau
    } else {
        wrapped
    }
}

fn least_squares_slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let mean_x = x.iter().sum::<f64>() / n;
    let mean_y = y.iter().sum::<f64>() / n;
    let mut covariance = 0.0;
    let mut variance = 0.0;
    for (xi, yi) in x.iter().zip(y) {
        covariance += (xi - mean_x) * (yi - mean_y);
        variance += (xi - mean_x) * (xi - mean_x);
    }
    if variance > 0.0 {
        covariance / variance
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::record::test_support::position_row;

    const DT: f64 = 0.1;

    fn times(n: usize) -> Vec<f64> {
        (0..n).map(|k| k as f64 * DT).collect()
    }

    /// Positions of a constant-speed, constant-yaw-rate motion starting at the origin heading +x.
    fn arc(speed: f64, yaw_rate: f64, n: usize) -> Vec<DVec2> {
        (0..n)
            .map(|k| {
                let t = k as f64 * DT;
                if yaw_rate == 0.0 {
                    DVec2::new(speed * t, 0.0)
                } else {
                    let r = speed / yaw_rate;
                    DVec2::new(r * (yaw_rate * t).sin(), r * (1.0 - (yaw_rate * t).cos()))
                }
            })
            .collect()
    }

    #[test]
    fn straight_line() {
        // 10 m/s along +x: no heading change (Θ = Φ = 0), equal step speeds (a = 0).
        let rules = ScenarioRules::default();
        let features = rules.features(&times(10), &arc(10.0, 0.0, 10)).unwrap();
        assert!(features.net_turn_deg.abs() < 1e-9);
        assert!(features.acceleration_mps2.abs() < 1e-9);
        assert!((features.mean_speed_mps - 10.0).abs() < 1e-9);
        assert_eq!(rules.classify_features(&features), Some(MotionScenario::Straight));
    }

    #[test]
    fn constant_deceleration() {
        // x(t) = 10 t − t² (a = −2 m/s²) along a diagonal heading. The mean speed over a step
        // equals the speed at its mid-time, so the fitted slope is exactly −2 m/s².
        let direction = DVec2::new(1.0, 1.0).normalize();
        let positions: Vec<DVec2> = times(10).iter().map(|&t| direction * (10.0 * t - t * t)).collect();
        let rules = ScenarioRules::default();
        let features = rules.features(&times(10), &positions).unwrap();
        assert!((features.acceleration_mps2 + 2.0).abs() < 1e-9);
        assert!((features.speed_consistency - 1.0).abs() < 1e-12);
        assert!(features.total_turn_deg < 1e-6);
        assert_eq!(rules.classify_features(&features), Some(MotionScenario::AccelDecel));
    }

    #[test]
    fn constant_rate_turns() {
        // 8 m/s at ±0.6 rad/s: each chord turns by ω·dt = 0.06 rad, 8 heading changes
        // → Θ = ±0.48 rad = ±27.5°, Φ = 27.5°, c = 1, equal chord lengths → a = 0.
        let rules = ScenarioRules::default();
        let left = rules.features(&times(10), &arc(8.0, 0.6, 10)).unwrap();
        assert!((left.net_turn_deg - 0.48f64.to_degrees()).abs() < 1e-9);
        assert!((left.turn_consistency - 1.0).abs() < 1e-12);
        assert!(left.acceleration_mps2.abs() < 1e-9);
        assert_eq!(rules.classify_features(&left), Some(MotionScenario::LeftTurn));
        let right = rules.features(&times(10), &arc(8.0, -0.6, 10)).unwrap();
        assert!((right.net_turn_deg + 0.48f64.to_degrees()).abs() < 1e-9);
        assert_eq!(rules.classify_features(&right), Some(MotionScenario::RightTurn));
        assert_eq!(MotionScenario::RightTurn.category(), MotionCategory::Turn);
    }

    #[test]
    fn zig_zag_is_nonlinear() {
        // Steps alternate between headings +30° and −30° at 1 m per step: 8 heading changes of
        // ±60°, Θ = 0 (they cancel), Φ = 480°, c = 0 → mixed heading changes.
        let mut positions = vec![DVec2::ZERO];
        for k in 0..9 {
            let heading = if k % 2 == 0 { 30f64 } else { -30f64 }.to_radians();
            let last = *positions.last().unwrap();
            positions.push(last + DVec2::new(heading.cos(), heading.sin()));
        }
        let rules = ScenarioRules::default();
        let features = rules.features(&times(10), &positions).unwrap();
        assert!(features.net_turn_deg.abs() < 1e-9);
        assert!((features.total_turn_deg - 480.0).abs() < 1e-9);
        assert_eq!(rules.classify_features(&features), Some(MotionScenario::Nonlinear));
    }

    #[test]
    fn turn_with_strong_speed_change_is_nonlinear() {
        // Speeds 4, 5, …, 12 m/s (slope 10 m/s², consistent) while turning 0.06 rad per step.
        let mut positions = vec![DVec2::ZERO];
        for k in 0..9 {
            let heading = 0.06 * k as f64;
            let step = (4.0 + k as f64) * DT;
            let last = *positions.last().unwrap();
            positions.push(last + step * DVec2::new(heading.cos(), heading.sin()));
        }
        let rules = ScenarioRules::default();
        let features = rules.features(&times(10), &positions).unwrap();
        assert!((features.acceleration_mps2 - 10.0).abs() < 1e-9);
        assert_eq!(rules.classify_features(&features), Some(MotionScenario::Nonlinear));
    }

    #[test]
    fn excluded_windows() {
        let rules = ScenarioRules::default();
        // Too short.
        assert_eq!(rules.classify_window(&times(9), &arc(10.0, 0.0, 9)), None);
        // Standing still: step speed 0.1 m/s < 0.5 m/s.
        assert_eq!(rules.classify_window(&times(10), &arc(0.1, 0.0, 10)), None);
        // A 2 s gap inside the window.
        let mut gapped = times(10);
        for t in gapped.iter_mut().skip(5) {
            *t += 2.0;
        }
        assert_eq!(rules.classify_window(&gapped, &arc(10.0, 0.0, 10)), None);
        // A gentle curve, 0.3 rad/s: Θ = 13.75° lies between the straight and turn limits.
        let gentle = rules.features(&times(10), &arc(8.0, 0.3, 10)).unwrap();
        assert!(gentle.net_turn_deg > 10.0 && gentle.net_turn_deg < 15.0);
        assert_eq!(rules.classify_features(&gentle), None);
    }

    #[test]
    fn sequence_labels_need_ten_rows_of_the_same_object() {
        // Object 1 moves straight for 12 frames; object 2 is present in frames 0..=11 but only
        // every other frame (6 rows). Rows 0..=8 of object 1 have fewer than 10 positions.
        let mut records = Vec::new();
        for (k, position) in arc(10.0, 0.0, 12).into_iter().enumerate() {
            records.push(position_row(k as u64, k as f64 * DT, 1, position));
            if k % 2 == 0 {
                records.push(position_row(k as u64, k as f64 * DT, 2, position + DVec2::Y * 20.0));
            }
        }
        let labels = classify_sequence(&records, &ScenarioRules::default());
        let object1: Vec<Option<MotionScenario>> = records
            .iter()
            .zip(&labels)
            .filter(|(row, _)| row.ground_truth_id == Some(1))
            .map(|(_, label)| *label)
            .collect();
        assert_eq!(object1.iter().filter(|label| label.is_none()).count(), 9);
        assert!(object1[9..].iter().all(|label| *label == Some(MotionScenario::Straight)));
        let object2_labelled = records
            .iter()
            .zip(&labels)
            .filter(|(row, label)| row.ground_truth_id == Some(2) && label.is_some())
            .count();
        assert_eq!(object2_labelled, 0);
    }

    #[test]
    fn several_rows_of_an_object_in_one_frame_fill_one_place_of_the_window_and_share_its_label() {
        // Object 1 moves straight for 12 frames with three detections in every frame.
        let mut records = Vec::new();
        for (k, position) in arc(10.0, 0.0, 12).into_iter().enumerate() {
            for offset in [0.0, 0.5, -0.5] {
                let mut row = position_row(k as u64, k as f64 * DT, 1, position);
                row.measured += DVec2::Y * offset;
                records.push(row);
            }
        }
        let labels = classify_sequence(&records, &ScenarioRules::default());
        // Ten frames make a window, as with one row per frame: frames 9, 10 and 11 are labelled,
        // every row of them.
        for (row, label) in records.iter().zip(&labels) {
            let expected = (row.frame >= 9).then_some(MotionScenario::Straight);
            assert_eq!(*label, expected, "frame {}", row.frame);
        }
    }

    #[test]
    fn rules_validation() {
        assert!(ScenarioRules::default().validate().is_ok());
        let short = ScenarioRules { window_len: 2, ..ScenarioRules::default() };
        assert!(short.validate().is_err());
        let negative = ScenarioRules { turn_min_net_turn_deg: -1.0, ..ScenarioRules::default() };
        assert!(negative.validate().is_err());
    }

    #[test]
    fn wrap_angle_range() {
        use std::f64::consts::PI;
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-12);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(0.25) - 0.25).abs() < 1e-12);
    }
}
