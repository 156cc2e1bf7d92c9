//! Where the centre of a tracked object lies behind a group of its detections.
//!
//! A detection-level radar's points on a vehicle lie on the faces it turns to the radar, each
//! face holding about as many as it spans resolution cells, so in proportion to its apparent
//! width: its length times the cosine between its outward normal and the line of sight. The
//! mean of a group is therefore expected at the visible contour's centroid with those weights,
//! not at the nearest point of the box (the single reflection of `crate::extent`) and not at
//! the centre. Given the heading and size of the object, the centre is the group's mean less
//! that centroid's offset. Without a heading (a slow object) the box is a disc of radius
//! `(length + width) / 4`, whose visible arc weighted alike has its centroid `π/4` of the radius
//! towards the sensor.

use crate::extent::ExtentConfig;
use glam::DVec2;

/// The offset from the centre of the centroid of the visible contour of an object of `extent`
/// centred at `centre_m`, moving with `velocity_mps` (the heading; below the extent's
/// `min_heading_speed_mps` the disc), seen by a sensor at `sensor_m`, m. Zero when the sensor
/// lies inside the object.
pub fn visible_contour_offset(
    extent: &ExtentConfig,
    centre_m: DVec2,
    velocity_mps: DVec2,
    sensor_m: DVec2,
) -> DVec2 {
    let to_sensor = sensor_m - centre_m;
    let distance_m = to_sensor.length();
    if !(distance_m > 0.0) {
        return DVec2::ZERO;
    }
    let speed = velocity_mps.length();
    if !(speed >= extent.min_heading_speed_mps) {
        let radius_m = 0.25 * (extent.length_m + extent.width_m);
        if distance_m <= radius_m {
            return DVec2::ZERO;
        }
        return to_sensor / distance_m * (core::f64::consts::FRAC_PI_4 * radius_m);
    }
    let heading = velocity_mps / speed;
    let (half_length, half_width) = (0.5 * extent.length_m, 0.5 * extent.width_m);
    let faces = [
        (heading, half_length, extent.width_m),
        (-heading, half_length, extent.width_m),
        (heading.perp(), half_width, extent.length_m),
        (-heading.perp(), half_width, extent.length_m),
    ];
    let (mut weighted_m, mut total) = (DVec2::ZERO, 0.0);
    for (normal, half_depth, face_length_m) in faces {
        let middle_m = normal * half_depth;
        let towards = to_sensor - middle_m;
        let cosine = normal.dot(towards) / towards.length().max(1e-9);
        if cosine > 0.0 {
            let weight = face_length_m * cosine;
            weighted_m += middle_m * weight;
            total += weight;
        }
    }
    if total > 0.0 {
        weighted_m / total
    } else {
        DVec2::ZERO
    }
}

/// `π/4`, the share of a disc's radius at which its visible arc's centroid lies (for tests).
#[cfg(test)]
const QUARTER_PI: f64 = core::f64::consts::FRAC_PI_4;

#[cfg(test)]
mod tests {
    use super::*;

    fn car() -> ExtentConfig {
        ExtentConfig { enabled: true, length_m: 4.5, width_m: 1.8, ..ExtentConfig::default() }
    }

    #[test]
    fn a_car_seen_from_straight_behind_shows_its_rear_face_half_a_length_back() {
        let offset =
            visible_contour_offset(&car(), DVec2::new(30.0, 0.0), DVec2::new(10.0, 0.0), DVec2::ZERO);
        assert!((offset - DVec2::new(-2.25, 0.0)).length() < 1e-9, "{offset}");
    }

    #[test]
    fn a_car_seen_from_its_corner_shows_both_near_faces_by_their_apparent_widths() {
        let centre = DVec2::new(30.0, 30.0);
        let offset = visible_contour_offset(&car(), centre, DVec2::new(10.0, 0.0), DVec2::ZERO);
        // The rear face (1.8 m wide) and the right side (4.5 m long) are seen at about 45°.
        let expected_x = -2.25 * 1.8 / (1.8 + 4.5);
        let expected_y = -0.9 * 4.5 / (1.8 + 4.5);
        assert!((offset.x - expected_x).abs() < 0.05 && (offset.y - expected_y).abs() < 0.05, "{offset}");
        assert!(offset.dot(-centre) > 0.0, "the offset points towards the sensor");
    }

    #[test]
    fn a_standing_car_is_a_disc_and_a_sensor_inside_gives_no_offset() {
        let extent = car();
        let offset = visible_contour_offset(&extent, DVec2::new(0.0, 20.0), DVec2::ZERO, DVec2::ZERO);
        let radius = 0.25 * (extent.length_m + extent.width_m);
        assert!((offset - DVec2::new(0.0, -QUARTER_PI * radius)).length() < 1e-12, "{offset}");
        let inside =
            visible_contour_offset(&extent, DVec2::new(0.5, 0.0), DVec2::new(10.0, 0.0), DVec2::ZERO);
        assert_eq!(inside, DVec2::ZERO);
    }
}
