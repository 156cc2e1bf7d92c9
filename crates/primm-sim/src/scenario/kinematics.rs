//! Planar motion of one object with bounded acceleration, jerk, yaw rate and yaw acceleration.

use std::f64::consts::PI;

use glam::DVec2;

use super::config::MotionLimits;

/// Braking fades out near standstill, but never below this deceleration, m/s², so that a
/// stop is reached in finite time.
const MIN_STOPPING_DECELERATION_MPS2: f64 = 0.3;
/// The lateral acceleration limit caps the yaw rate as if the object were at least this
/// fast, m/s.
const MIN_LATERAL_LIMIT_SPEED_MPS: f64 = 0.5;

/// Kinematic state: centre position, heading, speed and their rates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Kinematics {
    pub position: DVec2,
    pub heading: f64,
    pub speed: f64,
    pub accel: f64,
    pub yaw_rate: f64,
}

/// Wraps an angle into `(-π, π]`.
pub(crate) fn wrap_angle(angle: f64) -> f64 {
    let a = (angle + PI).rem_euclid(2.0 * PI) - PI;
    if a <= -PI {
        a + 2.0 * PI
    } else {
        a
    }
}

impl Kinematics {
    pub(crate) fn new(position: DVec2, heading: f64, speed: f64) -> Self {
        Self { position, heading: wrap_angle(heading), speed, accel: 0.0, yaw_rate: 0.0 }
    }

    /// Unit vector of the heading.
    pub(crate) fn direction(&self) -> DVec2 {
        DVec2::from_angle(self.heading)
    }

    /// World velocity, m/s.
    pub(crate) fn velocity(&self) -> DVec2 {
        self.direction() * self.speed
    }

    /// Advances by `dt` seconds towards the commanded acceleration and yaw rate, respecting
    /// `limits`. The speed never becomes negative; reaching standstill ends braking.
    pub(crate) fn step(&mut self, accel_cmd: f64, yaw_rate_cmd: f64, dt: f64, limits: &MotionLimits) {
        let (max_accel, max_decel) = (limits.max_acceleration_mps2, limits.max_deceleration_mps2);
        let mut target = accel_cmd.clamp(-max_decel, max_accel);
        if target < 0.0 {
            // Drivers and walkers release the brake as they come to a stop.
            target = target.max(-(self.speed / limits.stop_taper_s).max(MIN_STOPPING_DECELERATION_MPS2));
        } else {
            // Ease off in time to meet the speed limit without exceeding the jerk limit.
            let headroom = (limits.max_speed_mps - self.speed).max(0.0);
            target = target.min((limits.max_jerk_mps3 * headroom).sqrt());
        }
        let jerk_step = limits.max_jerk_mps3 * dt;
        let accel =
            (self.accel + (target - self.accel).clamp(-jerk_step, jerk_step)).clamp(-max_decel, max_accel);
        let old_speed = self.speed;
        let mut speed = old_speed + accel * dt;
        let mut accel_applied = accel;
        let mut moving_time = dt;
        if speed <= 0.0 {
            // Standstill within this step.
            moving_time = if accel < 0.0 { (old_speed / -accel).min(dt) } else { dt };
            speed = 0.0;
            accel_applied = 0.0;
        } else if speed > limits.max_speed_mps {
            speed = limits.max_speed_mps;
            accel_applied = (speed - old_speed) / dt;
        }

        let yaw_cap = match limits.max_lateral_acceleration_mps2 {
            Some(max_lateral) => {
                limits.max_yaw_rate_radps.min(max_lateral / speed.max(MIN_LATERAL_LIMIT_SPEED_MPS))
            }
            None => limits.max_yaw_rate_radps,
        };
        let yaw_step = limits.max_yaw_acceleration_radps2 * dt;
        let yaw_target = yaw_rate_cmd.clamp(-yaw_cap, yaw_cap);
        let yaw_rate = (self.yaw_rate + (yaw_target - self.yaw_rate).clamp(-yaw_step, yaw_step))
            .clamp(-yaw_cap, yaw_cap);

        let distance =
            if moving_time < dt { 0.5 * old_speed * moving_time } else { 0.5 * (old_speed + speed) * dt };
        let mid_heading = self.heading + 0.5 * yaw_rate * dt;
        self.position += DVec2::from_angle(mid_heading) * distance;
        self.heading = wrap_angle(self.heading + yaw_rate * dt);
        self.speed = speed;
        self.accel = accel_applied;
        self.yaw_rate = yaw_rate;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> MotionLimits {
        MotionLimits { max_speed_mps: 15.0, ..MotionLimits::car() }
    }

    #[test]
    fn jerk_and_limits_are_respected() {
        let l = limits();
        let mut k = Kinematics::new(DVec2::ZERO, 0.0, 0.0);
        let dt = 0.015;
        let mut previous = k;
        for step in 0..2000 {
            let (a, w) = if step < 800 { (10.0, 2.0) } else { (-10.0, -2.0) };
            k.step(a, w, dt, &l);
            assert!(k.speed >= 0.0 && k.speed <= l.max_speed_mps + 1e-9);
            assert!(k.accel <= l.max_acceleration_mps2 + 1e-9 && k.accel >= -l.max_deceleration_mps2 - 1e-9);
            assert!(k.yaw_rate.abs() <= l.max_yaw_rate_radps + 1e-9);
            assert!(k.speed * k.yaw_rate.abs() <= l.max_lateral_acceleration_mps2.unwrap() + 1e-6);
            if k.speed > 0.0 && previous.speed > 0.0 {
                assert!(
                    (k.accel - previous.accel).abs() <= l.max_jerk_mps3 * dt + 1e-9,
                    "step {step}: {previous:?} -> {k:?}"
                );
            }
            let moved = k.position.distance(previous.position);
            assert!((moved - 0.5 * (k.speed + previous.speed) * dt).abs() < 1e-6 + previous.speed * dt * 0.5);
            previous = k;
        }
        assert_eq!(k.speed, 0.0);
        assert_eq!(k.accel, 0.0);
    }

    #[test]
    fn wrap_angle_range() {
        for k in -20..20 {
            let a = wrap_angle(k as f64 * 0.9);
            assert!(a > -PI && a <= PI);
            assert!(
                ((k as f64 * 0.9 - a) / (2.0 * PI)).fract().abs() < 1e-9
                    || ((k as f64 * 0.9 - a) / (2.0 * PI)).fract().abs() > 1.0 - 1e-9
            );
        }
    }
}
