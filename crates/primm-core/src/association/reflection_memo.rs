//! Expected reflections of one track per sensor position, computed once per frame.
//!
//! The reflection of an extended object depends on the track's prior and the sensor, not on
//! the measurement, so gating computes it once per track and sensor instead of once per
//! candidate pair, and the update reuses the one of the assigned measurement's sensor
//! ([`super::associator::Associator::assigned_reflection`]) instead of computing it again.

use super::cost::PreparedReflection;
use crate::extent::ExpectedReflection;
use glam::DVec2;

/// A track's expected reflection for one sensor, with it prepared for the likelihood cost where
/// that cost is used.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RowReflection {
    /// The expected reflection.
    pub reflection: ExpectedReflection,
    /// It prepared for the likelihood cost (`None` with the paper's cost, or when `S + C` is
    /// not positive definite).
    pub prepared: Option<PreparedReflection>,
}

/// Values of one track's reflections, keyed by sensor position and the sensor's reflection
/// scale (`crate::sensor`), on the stack. With more sensor
/// positions than `N`, the rest are computed on every call (the same values).
#[derive(Debug, Clone, Copy)]
pub struct ReflectionMemo<T, const N: usize> {
    entries: [(DVec2, f64, T); N],
    len: usize,
}

/// Sensor positions a track's memo holds: a car carries four to six radars, and a frame
/// usually holds the detections of one or two of them.
pub const REFLECTION_MEMO_SENSORS: usize = 4;

impl<T: Copy + Default, const N: usize> Default for ReflectionMemo<T, N> {
    fn default() -> Self {
        ReflectionMemo { entries: [(DVec2::ZERO, 0.0, T::default()); N], len: 0 }
    }
}

impl<T: Copy + Default, const N: usize> ReflectionMemo<T, N> {
    /// An empty memo.
    pub fn new() -> Self {
        Self::default()
    }

    /// The value held for `sensor_m` and `scale` (compared bit for bit), if any.
    pub fn find(&self, sensor_m: DVec2, scale: f64) -> Option<T> {
        let same = |position: &DVec2, held_scale: f64| {
            position.x.to_bits() == sensor_m.x.to_bits()
                && position.y.to_bits() == sensor_m.y.to_bits()
                && held_scale.to_bits() == scale.to_bits()
        };
        self.entries[..self.len]
            .iter()
            .find(|(position, held_scale, _)| same(position, *held_scale))
            .map(|(_, _, value)| *value)
    }

    /// `compute()` for the reflection seen from `sensor_m`, called at most once per held
    /// position, so the answer is exactly the function's.
    pub fn get(&mut self, sensor_m: DVec2, scale: f64, compute: impl FnOnce() -> T) -> T {
        if let Some(value) = self.find(sensor_m, scale) {
            return value;
        }
        let value = compute();
        if self.len < N {
            self.entries[self.len] = (sensor_m, scale, value);
            self.len += 1;
        }
        value
    }

    /// Sensor positions held.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether none is held.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::extent::{expected_reflection, ExtentConfig, ObjectPrior};
    use glam::DMat2;

    #[test]
    fn the_reflection_memo_answers_exactly_what_the_model_computes_also_past_its_capacity() {
        let extent = ExtentConfig { enabled: true, offset_scale: 0.5, ..ExtentConfig::default() };
        let object = ObjectPrior {
            centre_m: DVec2::new(20.0, 3.0),
            centre_covariance_m2: DMat2::from_diagonal(DVec2::new(0.3, 0.2)),
            velocity_mps: DVec2::new(8.0, 1.0),
            velocity_covariance_m2: DMat2::from_diagonal(DVec2::new(0.5, 0.4)),
        };
        let mut memo: ReflectionMemo<ExpectedReflection, REFLECTION_MEMO_SENSORS> = ReflectionMemo::new();
        // Twelve sensor positions, each asked for three times in an interleaved order: more
        // positions than the memo holds, and repeats both of held and of unheld ones.
        let sensors: [DVec2; 12] =
            core::array::from_fn(|k| DVec2::new(-2.0 + 0.4 * k as f64, [0.8, -0.8][k % 2]));
        for round in 0..3 {
            for k in 0..sensors.len() {
                let sensor = sensors[(k + round * 5) % sensors.len()];
                assert_eq!(
                    memo.get(sensor, 0.5, || expected_reflection(&extent, &object, sensor, 0.5)),
                    expected_reflection(&extent, &object, sensor, 0.5)
                );
            }
        }
        assert_eq!(memo.len, REFLECTION_MEMO_SENSORS);
    }
}
