//! Planar motion of one object with bounded acceleration, jerk, yaw rate and yaw acceleration.

use std::f64::consts::PI;

use glam::DVec2;

/// Hard physical limits of a class of objects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Limits {
    pub max_speed: f64,
    pub max_accel: f64,
    pub max_decel: f64,
    pub max_jerk: f64,
    pub max_yaw_rate: f64,
    pub max_yaw_accel: f64,
    /// Largest `speed × yaw rate`; infinite for classes without that limit.
    pub max_lateral_accel: f64,
    /// Braking is faded out as `speed / stop_taper` near standstill, seconds.
    pub stop_taper: f64,
}

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
    pub(crate) fn step(&mut self, accel_cmd: f64, yaw_rate_cmd: f64, dt: f64, limits: &Limits) {
        let mut target = accel_cmd.clamp(-limits.max_decel, limits.max_accel);
        if target < 0.0 {
            // Drivers and walkers release the brake as they come to a stop.
            target = target.max(-(self.speed / limits.stop_taper).max(0.3));
        } else {
            // Ease off in time to meet the speed limit without exceeding the jerk limit.
            let headroom = (limits.max_speed - self.speed).max(0.0);
            target = target.min((limits.max_jerk * headroom).sqrt());
        }
        let jerk_step = limits.max_jerk * dt;
        let accel = (self.accel + (target - self.accel).clamp(-jerk_step, jerk_step))
            .clamp(-limits.max_decel, limits.max_accel);
        let old_speed = self.speed;
        let mut speed = old_speed + accel * dt;
        let mut accel_applied = accel;
        let mut moving_time = dt;
        if speed <= 0.0 {
            // Standstill within this step.
            moving_time = if accel < 0.0 { (old_speed / -accel).min(dt) } else { dt };
            speed = 0.0;
            accel_applied = 0.0;
        } else if speed > limits.max_speed {
            speed = limits.max_speed;
            accel_applied = (speed - old_speed) / dt;
        }

        let lateral_cap = limits.max_lateral_accel / speed.max(0.5);
        let yaw_cap = limits.max_yaw_rate.min(lateral_cap);
        let yaw_step = limits.max_yaw_accel * dt;
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

    fn limits() -> Limits {
        Limits {
            max_speed: 15.0,
            max_accel: 3.0,
            max_decel: 7.0,
            max_jerk: 6.0,
            max_yaw_rate: 0.7,
            max_yaw_accel: 1.2,
            max_lateral_accel: 3.5,
            stop_taper: 0.8,
        }
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
            assert!(k.speed >= 0.0 && k.speed <= l.max_speed + 1e-9);
            assert!(k.accel <= l.max_accel + 1e-9 && k.accel >= -l.max_decel - 1e-9);
            assert!(k.yaw_rate.abs() <= l.max_yaw_rate + 1e-9);
            assert!(k.speed * k.yaw_rate.abs() <= l.max_lateral_accel + 1e-6);
            if k.speed > 0.0 && previous.speed > 0.0 {
                assert!(
                    (k.accel - previous.accel).abs() <= l.max_jerk * dt + 1e-9,
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
