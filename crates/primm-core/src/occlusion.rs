//! Whether one object hides another from a sensor: the line of sight from the sensor to the
//! hidden object's centre passes through the other object's box. The tracker asks it of its
//! confirmed tracks, so that a sensor's detection-probability estimate counts only the objects
//! the sensor could see (`crate::sensor::estimates`); the simulator asks it of its true objects,
//! for the same quantity's truth.

use crate::extent::ExtentConfig;
use arrayvec::ArrayVec;
use glam::DVec2;

/// An object's box in the plane: its centre, the unit direction of its length and its half
/// length and half width.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectBox {
    /// The box's centre, m.
    pub centre_m: DVec2,
    /// Unit vector along the box's length.
    pub heading: DVec2,
    /// Half the length (x) and half the width (y), m.
    pub half_extent_m: DVec2,
}

impl ObjectBox {
    /// The nominal box of an object of `extent` centred at `centre_m` and moving with
    /// `velocity_mps`: its length along the velocity, or, at speeds up to the extent's
    /// `min_heading_speed_mps` (no heading), a square of the extent's width.
    pub fn nominal(extent: &ExtentConfig, centre_m: DVec2, velocity_mps: DVec2) -> Self {
        let (heading, half_length_m) = match velocity_mps.try_normalize() {
            Some(heading) if velocity_mps.length() > extent.min_heading_speed_mps => {
                (heading, 0.5 * extent.length_m)
            }
            _ => (DVec2::X, 0.5 * extent.width_m),
        };
        ObjectBox { centre_m, heading, half_extent_m: DVec2::new(half_length_m, 0.5 * extent.width_m) }
    }

    /// Whether the segment from `from_m` to `to_m` passes through the box (its boundary
    /// included): the slab test in the box's own frame.
    pub fn crossed_by(&self, from_m: DVec2, to_m: DVec2) -> bool {
        let heading = self.heading;
        let to_local = |p: DVec2| {
            let relative = p - self.centre_m;
            DVec2::new(relative.dot(heading), relative.dot(heading.perp()))
        };
        let start = to_local(from_m);
        let delta = to_local(to_m) - start;
        let (mut enter, mut leave) = (0.0f64, 1.0f64);
        for axis in 0..2 {
            let (start, delta, half) = (start[axis], delta[axis], self.half_extent_m[axis]);
            if delta.abs() < 1e-12 {
                if start.abs() > half {
                    return false;
                }
            } else {
                let mut near = (-half - start) / delta;
                let mut far = (half - start) / delta;
                if near > far {
                    core::mem::swap(&mut near, &mut far);
                }
                enter = enter.max(near);
                leave = leave.min(far);
                if enter > leave {
                    return false;
                }
            }
        }
        true
    }
}

/// One object that may hide others: its box, the radius of the circle around the box, m, and
/// a caller's key for it (e.g. its row in the track table), so that an object does not hide
/// itself.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Occluder {
    /// The caller's key.
    pub key: u16,
    /// The object's box.
    pub object: ObjectBox,
    /// The radius of the smallest circle around the box's centre that holds it, m.
    pub radius_m: f64,
}

/// The objects that may hide others from a sensor in one frame; capacity `N` in the type.
#[derive(Debug, Clone)]
pub struct Occluders<const N: usize> {
    objects: ArrayVec<Occluder, N>,
}

impl<const N: usize> Default for Occluders<N> {
    fn default() -> Self {
        Occluders { objects: ArrayVec::new() }
    }
}

impl<const N: usize> Occluders<N> {
    /// Forgets every object.
    pub fn clear(&mut self) {
        self.objects.clear();
    }

    /// Adds `object` under `key`; returns it back when the capacity is full.
    pub fn push(&mut self, key: u16, object: ObjectBox) -> Result<(), ObjectBox> {
        let radius_m = object.half_extent_m.length();
        self.objects.try_push(Occluder { key, object, radius_m }).map_err(|_| object)
    }

    /// The objects held.
    pub fn objects(&self) -> &[Occluder] {
        &self.objects
    }

    /// Whether an object other than the one under `key` lies on the line of sight from
    /// `sensor_m` to `target_m`. Objects whose circle misses the line are passed over before the
    /// exact test.
    pub fn hide(&self, key: u16, sensor_m: DVec2, target_m: DVec2) -> bool {
        let sight = target_m - sensor_m;
        let range_m = sight.length();
        let Some(unit) = sight.try_normalize() else { return false };
        self.objects.iter().any(|occluder| {
            let relative = occluder.object.centre_m - sensor_m;
            let along_m = relative.dot(unit);
            occluder.key != key
                && along_m > -occluder.radius_m
                && along_m < range_m + occluder.radius_m
                && relative.perp_dot(unit).abs() <= occluder.radius_m
                && occluder.object.crossed_by(sensor_m, target_m)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn car_at(x_m: f64, y_m: f64) -> ObjectBox {
        ObjectBox { centre_m: DVec2::new(x_m, y_m), heading: DVec2::X, half_extent_m: DVec2::new(2.25, 0.9) }
    }

    #[test]
    fn a_box_on_the_line_of_sight_hides_what_lies_behind_it() {
        let sensor = DVec2::ZERO;
        assert!(car_at(20.0, 0.5).crossed_by(sensor, DVec2::new(40.0, 0.0)));
        // Beside the line, short of it, or beyond its end: not crossed.
        assert!(!car_at(20.0, 3.0).crossed_by(sensor, DVec2::new(40.0, 0.0)));
        assert!(!car_at(-20.0, 0.0).crossed_by(sensor, DVec2::new(40.0, 0.0)));
        assert!(!car_at(50.0, 0.0).crossed_by(sensor, DVec2::new(40.0, 0.0)));
    }

    #[test]
    fn a_turned_box_is_crossed_along_its_width() {
        // Turned across the line of sight: its length, 4.5 m, now spans y.
        let turned = ObjectBox { heading: DVec2::Y, ..car_at(20.0, 2.0) };
        assert!(turned.crossed_by(DVec2::ZERO, DVec2::new(40.0, 0.0)));
        assert!(!car_at(20.0, 2.0).crossed_by(DVec2::ZERO, DVec2::new(40.0, 0.0)));
    }

    #[test]
    fn an_object_hides_others_but_not_itself_and_the_first_look_agrees_with_the_exact_test() {
        let mut occluders = Occluders::<4>::default();
        occluders.push(0, car_at(20.0, 0.5)).unwrap();
        occluders.push(1, car_at(40.0, 0.0)).unwrap();
        let sensor = DVec2::ZERO;
        assert!(occluders.hide(1, sensor, DVec2::new(40.0, 0.0)));
        assert!(!occluders.hide(0, sensor, DVec2::new(20.0, 0.5)));
        // Every target on a grid: the pre-filter never overrules the box test.
        for x in -10..60 {
            for y in -8..8 {
                let target = DVec2::new(f64::from(x), f64::from(y) * 0.5);
                let exact =
                    occluders.objects().iter().any(|o| o.key != 9 && o.object.crossed_by(sensor, target));
                assert_eq!(occluders.hide(9, sensor, target), exact, "{target}");
            }
        }
    }

    #[test]
    fn a_moving_object_lies_along_its_velocity_and_a_slow_one_is_a_square_of_its_width() {
        let extent = ExtentConfig {
            length_m: 4.5,
            width_m: 1.8,
            min_heading_speed_mps: 1.0,
            ..ExtentConfig::default()
        };
        let moving = ObjectBox::nominal(&extent, DVec2::ONE, DVec2::new(0.0, 5.0));
        assert_eq!(
            (moving.centre_m, moving.heading, moving.half_extent_m),
            (DVec2::ONE, DVec2::Y, DVec2::new(2.25, 0.9))
        );
        let slow = ObjectBox::nominal(&extent, DVec2::ONE, DVec2::new(0.0, 0.5));
        assert_eq!(slow.half_extent_m, DVec2::new(0.9, 0.9));
    }

    #[test]
    fn a_full_set_of_occluders_returns_the_object_it_cannot_hold() {
        let mut occluders = Occluders::<1>::default();
        assert!(occluders.push(0, car_at(1.0, 0.0)).is_ok());
        assert_eq!(occluders.push(1, car_at(2.0, 0.0)), Err(car_at(2.0, 0.0)));
        occluders.clear();
        assert!(occluders.objects().is_empty());
    }

    #[test]
    fn a_segment_parallel_to_a_face_is_decided_by_that_face() {
        let car = car_at(0.0, 0.0);
        assert!(car.crossed_by(DVec2::new(-10.0, 0.9), DVec2::new(10.0, 0.9)));
        assert!(!car.crossed_by(DVec2::new(-10.0, 0.91), DVec2::new(10.0, 0.91)));
    }
}
