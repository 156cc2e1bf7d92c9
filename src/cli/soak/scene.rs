//! The synthetic scene of `primm soak`: a fixed number of objects kept in view forever.
//!
//! `primm-sim`'s generator writes finite sequences of road traffic; a soak needs one endless
//! stream with a steady load instead. Here `objects` point objects move in a 200 m × 200 m
//! square in front of one radar at the origin (x from 5 m to 205 m, y from −100 m to 100 m),
//! one frame every [`FRAME_INTERVAL_S`]:
//!
//! * classes in turn car, pedestrian, two-wheeler, with class-typical speeds (cars 5–25 m/s,
//!   pedestrians 0.5–2 m/s, two-wheelers 3–10 m/s), a random turn rate that changes now and
//!   then, and small random accelerations;
//! * an object that leaves the square is replaced by a new one at a random place inside it,
//!   so the tracks of the old objects coast and are deleted and new tracks start all the time;
//! * each object is measured with probability [`DETECTION_PROBABILITY`], with Gaussian position
//!   noise of its class's configured standard deviation, its radial velocity plus noise, and an
//!   RCS; up to [`CLUTTER_PER_FRAME`] false measurements at random places fill the frame up to
//!   its capacity of 256.
//!
//! Everything comes from one seeded generator (xorshift64*), so a soak is repeatable.

use primm_core::measurement::{Frame, Measurement, ObjectClass, MAX_MEASUREMENTS_PER_FRAME};

/// Time between frames, s.
pub const FRAME_INTERVAL_S: f64 = 0.05;
/// Probability that an object is measured in a frame.
pub const DETECTION_PROBABILITY: f64 = 0.9;
/// False measurements per frame (fewer when the frame is full).
pub const CLUTTER_PER_FRAME: usize = 2;
/// The square the objects move in: x range, m.
const X_RANGE_M: (f64, f64) = (5.0, 205.0);
/// The square the objects move in: y range, m.
const Y_RANGE_M: (f64, f64) = (-100.0, 100.0);

/// A small, fast, seeded random number generator (xorshift64*).
#[derive(Debug, Clone)]
struct Random(u64);

impl Random {
    fn new(seed: u64) -> Self {
        // Never zero: xorshift would stay at zero.
        Random(seed ^ 0x9E37_79B9_7F4A_7C15 | 1)
    }

    /// Uniform in [0, 1).
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        bits as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [low, high).
    fn between(&mut self, low: f64, high: f64) -> f64 {
        low + (high - low) * self.uniform()
    }

    /// Standard normal (Box–Muller).
    fn normal(&mut self) -> f64 {
        let u = 1.0 - self.uniform();
        let v = self.uniform();
        (-2.0 * u.ln()).sqrt() * (core::f64::consts::TAU * v).cos()
    }
}

/// One simulated object.
#[derive(Debug, Clone, Copy)]
struct Object {
    id: u64,
    class: ObjectClass,
    x_m: f64,
    y_m: f64,
    speed_mps: f64,
    heading_rad: f64,
    turn_rate_radps: f64,
}

/// The endless scene.
#[derive(Debug, Clone)]
pub struct SoakScene {
    random: Random,
    objects: Vec<Object>,
    /// Position noise standard deviation per class, m.
    position_std_m: [f64; ObjectClass::COUNT],
    next_id: u64,
    frame_index: u64,
    /// Objects replaced after leaving the square, so far.
    replaced: u64,
}

impl SoakScene {
    /// `objects` objects (at most 256), seeded with `seed`; position noise from the
    /// configuration's per-class measurement noise (its x variance).
    pub fn new(objects: usize, seed: u64, config: &primm_core::config::Config) -> Self {
        let position_std_m = ObjectClass::ALL
            .map(|class| config.classes.get(class).measurement_noise_covariance_m2[0][0].sqrt());
        let mut scene = SoakScene {
            random: Random::new(seed),
            objects: Vec::with_capacity(objects),
            position_std_m,
            next_id: 0,
            frame_index: 0,
            replaced: 0,
        };
        let objects = objects.min(MAX_MEASUREMENTS_PER_FRAME);
        for index in 0..objects {
            let class = ObjectClass::ALL[index % ObjectClass::COUNT];
            let object = scene.spawn(class);
            scene.objects.push(object);
        }
        scene
    }

    /// Objects in view.
    pub fn object_count(&self) -> usize {
        self.objects.len()
    }

    /// Objects replaced after leaving the square, so far.
    pub fn objects_replaced(&self) -> u64 {
        self.replaced
    }

    /// A new object of `class` at a random place and heading.
    fn spawn(&mut self, class: ObjectClass) -> Object {
        let (low, high) = match class {
            ObjectClass::Car => (5.0, 25.0),
            ObjectClass::Pedestrian => (0.5, 2.0),
            ObjectClass::TwoWheeler => (3.0, 10.0),
        };
        self.next_id += 1;
        Object {
            id: self.next_id,
            class,
            x_m: self.random.between(X_RANGE_M.0, X_RANGE_M.1),
            y_m: self.random.between(Y_RANGE_M.0, Y_RANGE_M.1),
            speed_mps: self.random.between(low, high),
            heading_rad: self.random.between(-core::f64::consts::PI, core::f64::consts::PI),
            turn_rate_radps: 0.0,
        }
    }

    /// Moves every object by one frame interval and returns the next frame.
    pub fn next_frame(&mut self) -> Frame {
        let dt = FRAME_INTERVAL_S;
        let mut frame = Frame::new(self.frame_index as f64 * dt);
        self.frame_index += 1;
        for index in 0..self.objects.len() {
            let mut object = self.objects[index];
            if self.random.uniform() < 0.01 {
                object.turn_rate_radps = 0.3 * self.random.normal();
            }
            object.heading_rad += object.turn_rate_radps * dt;
            object.speed_mps = (object.speed_mps + 0.5 * self.random.normal() * dt).max(0.0);
            object.x_m += object.speed_mps * object.heading_rad.cos() * dt;
            object.y_m += object.speed_mps * object.heading_rad.sin() * dt;
            let inside = (X_RANGE_M.0..=X_RANGE_M.1).contains(&object.x_m)
                && (Y_RANGE_M.0..=Y_RANGE_M.1).contains(&object.y_m);
            if !inside {
                object = self.spawn(object.class);
                self.replaced += 1;
            }
            self.objects[index] = object;
            if self.random.uniform() < DETECTION_PROBABILITY {
                let measurement = self.measure(&object);
                frame.measurements.push(measurement);
            }
        }
        for _ in 0..CLUTTER_PER_FRAME {
            if frame.measurements.is_full() {
                break;
            }
            let clutter = self.clutter();
            frame.measurements.push(clutter);
        }
        frame
    }

    /// A noisy measurement of `object`.
    fn measure(&mut self, object: &Object) -> Measurement {
        let std = self.position_std_m[object.class.index()];
        let range = (object.x_m * object.x_m + object.y_m * object.y_m).sqrt().max(1e-3);
        let vx = object.speed_mps * object.heading_rad.cos();
        let vy = object.speed_mps * object.heading_rad.sin();
        let radial = (vx * object.x_m + vy * object.y_m) / range;
        Measurement {
            x_m: object.x_m + std * self.random.normal(),
            y_m: object.y_m + std * self.random.normal(),
            radial_velocity_mps: radial + 0.3 * self.random.normal(),
            rcs_dbsm: 5.0 + 2.0 * self.random.normal(),
            class: object.class,
            sensor_id: Some(0),
            ground_truth_id: Some(object.id),
        }
    }

    /// A false measurement at a random place.
    fn clutter(&mut self) -> Measurement {
        let class = ObjectClass::ALL
            [(self.random.uniform() * ObjectClass::COUNT as f64) as usize % ObjectClass::COUNT];
        Measurement {
            x_m: self.random.between(X_RANGE_M.0, X_RANGE_M.1),
            y_m: self.random.between(Y_RANGE_M.0, Y_RANGE_M.1),
            radial_velocity_mps: self.random.between(-10.0, 10.0),
            rcs_dbsm: self.random.between(-10.0, 10.0),
            class,
            sensor_id: Some(0),
            ground_truth_id: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scene_keeps_its_objects_in_the_square_and_its_frames_within_capacity() {
        let mut scene = SoakScene::new(256, 7, &primm_core::config::Config::default());
        for _ in 0..2000 {
            let frame = scene.next_frame();
            assert!(frame.measurements.len() <= MAX_MEASUREMENTS_PER_FRAME);
            for object in &scene.objects {
                assert!((X_RANGE_M.0..=X_RANGE_M.1).contains(&object.x_m), "{object:?}");
                assert!((Y_RANGE_M.0..=Y_RANGE_M.1).contains(&object.y_m), "{object:?}");
            }
        }
        assert_eq!(scene.object_count(), 256);
        assert!(scene.objects_replaced() > 0, "objects leave and are replaced");
    }

    #[test]
    fn the_same_seed_gives_the_same_frames() {
        let config = primm_core::config::Config::default();
        let mut first = SoakScene::new(64, 3, &config);
        let mut second = SoakScene::new(64, 3, &config);
        for _ in 0..50 {
            assert_eq!(first.next_frame(), second.next_frame());
        }
    }
}
