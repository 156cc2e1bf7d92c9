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
//!
//! Where on the contour a detection falls is random, so the mean of `n` detections scatters
//! about that centroid with the contour's own covariance over `n`: each visible face spreads
//! its points uniformly along its length (`ℓ²/12` along it), and the faces' middles spread
//! about the centroid by their weights. Each detection's own radar noise averages down the
//! same way, so the group's measurement carries both over `n` ([`group_noise_m2`]).

use crate::extent::ExtentConfig;
use glam::{DMat2, DVec2};

/// The visible contour of an object seen by one sensor: where the centroid of its points
/// lies from the object's centre, and how single points scatter about it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VisibleContour {
    /// The centroid's offset from the centre, m.
    pub offset_m: DVec2,
    /// The covariance of one point of the contour about the centroid, m².
    pub covariance_m2: DMat2,
}

/// The visible contour of an object of `extent` centred at `centre_m`, moving with
/// `velocity_mps` (the heading; below the extent's `min_heading_speed_mps` the disc), seen by
/// a sensor at `sensor_m`. With the sensor inside the object, no offset and the spread of the
/// whole outline.
pub fn visible_contour(
    extent: &ExtentConfig,
    centre_m: DVec2,
    velocity_mps: DVec2,
    sensor_m: DVec2,
) -> VisibleContour {
    let to_sensor = sensor_m - centre_m;
    let distance_m = to_sensor.length();
    let radius_m = 0.25 * (extent.length_m + extent.width_m);
    let speed = velocity_mps.length();
    if !(distance_m > 0.0) || !(speed >= extent.min_heading_speed_mps) {
        if !(distance_m > radius_m) {
            return VisibleContour {
                offset_m: DVec2::ZERO,
                covariance_m2: DMat2::from_diagonal(DVec2::splat(0.5 * radius_m * radius_m)),
            };
        }
        // The half circle facing the sensor, weighted by the cosine to the line of sight:
        // its points lie `E[cos² φ] = 2/3` of the radius² along the line of sight (less the
        // centroid's `(π/4)²`) and `E[sin² φ] = 1/3` across it.
        let line_of_sight = to_sensor / distance_m;
        let quarter_pi = core::f64::consts::FRAC_PI_4;
        let along_m2 = radius_m * radius_m * (2.0 / 3.0 - quarter_pi * quarter_pi);
        let across_m2 = radius_m * radius_m / 3.0;
        return VisibleContour {
            offset_m: line_of_sight * (quarter_pi * radius_m),
            covariance_m2: outer(line_of_sight) * along_m2 + outer(line_of_sight.perp()) * across_m2,
        };
    }
    let heading = velocity_mps / speed;
    let (half_length, half_width) = (0.5 * extent.length_m, 0.5 * extent.width_m);
    let faces = [
        (heading, half_length, extent.width_m),
        (-heading, half_length, extent.width_m),
        (heading.perp(), half_width, extent.length_m),
        (-heading.perp(), half_width, extent.length_m),
    ];
    let (mut weighted_m, mut second_m2, mut total) = (DVec2::ZERO, DMat2::ZERO, 0.0);
    for (normal, half_depth, face_length_m) in faces {
        let middle_m = normal * half_depth;
        let towards = to_sensor - middle_m;
        let cosine = normal.dot(towards) / towards.length().max(1e-9);
        if cosine > 0.0 {
            let weight = face_length_m * cosine;
            weighted_m += middle_m * weight;
            // About the centre: the middle's outer product and the face's uniform spread.
            second_m2 +=
                (outer(middle_m) + outer(normal.perp()) * (face_length_m * face_length_m / 12.0)) * weight;
            total += weight;
        }
    }
    if total > 0.0 {
        let centroid_m = weighted_m / total;
        VisibleContour { offset_m: centroid_m, covariance_m2: second_m2 / total - outer(centroid_m) }
    } else {
        let half_m2 = 0.5 * radius_m * radius_m;
        VisibleContour { offset_m: DVec2::ZERO, covariance_m2: DMat2::from_diagonal(DVec2::splat(half_m2)) }
    }
}

/// The noise of a group's mean of `count` detections moved to the centre, m²: each detection
/// carries the radar's noise `radar_noise_m2` and falls on the contour with the contour's
/// covariance of one point `contour_m2`, independently, so the mean carries
/// `(R + Σ_c) / count`; the tracker takes `scale` of it (the grouping's `group_noise_scale`,
/// in (0, 1]).
pub fn group_noise_m2(radar_noise_m2: DMat2, contour_m2: DMat2, count: usize, scale: f64) -> DMat2 {
    (radar_noise_m2 + contour_m2) * (scale / count.max(1) as f64)
}

/// `v vᵀ`.
fn outer(v: DVec2) -> DMat2 {
    DMat2::from_cols(v * v.x, v * v.y)
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
            visible_contour(&car(), DVec2::new(30.0, 0.0), DVec2::new(10.0, 0.0), DVec2::ZERO).offset_m;
        assert!((offset - DVec2::new(-2.25, 0.0)).length() < 1e-9, "{offset}");
    }

    #[test]
    fn a_car_seen_from_its_corner_shows_both_near_faces_by_their_apparent_widths() {
        let centre = DVec2::new(30.0, 30.0);
        let offset = visible_contour(&car(), centre, DVec2::new(10.0, 0.0), DVec2::ZERO).offset_m;
        // The rear face (1.8 m wide) and the right side (4.5 m long) are seen at about 45°.
        let expected_x = -2.25 * 1.8 / (1.8 + 4.5);
        let expected_y = -0.9 * 4.5 / (1.8 + 4.5);
        assert!((offset.x - expected_x).abs() < 0.05 && (offset.y - expected_y).abs() < 0.05, "{offset}");
        assert!(offset.dot(-centre) > 0.0, "the offset points towards the sensor");
    }

    #[test]
    fn a_standing_car_is_a_disc_and_a_sensor_inside_gives_no_offset() {
        let extent = car();
        let offset = visible_contour(&extent, DVec2::new(0.0, 20.0), DVec2::ZERO, DVec2::ZERO).offset_m;
        let radius = 0.25 * (extent.length_m + extent.width_m);
        assert!((offset - DVec2::new(0.0, -QUARTER_PI * radius)).length() < 1e-12, "{offset}");
        let inside =
            visible_contour(&extent, DVec2::new(0.5, 0.0), DVec2::new(10.0, 0.0), DVec2::ZERO).offset_m;
        assert_eq!(inside, DVec2::ZERO);
    }

    #[test]
    fn seen_from_straight_behind_the_points_spread_along_the_rear_face_only() {
        let contour = visible_contour(&car(), DVec2::new(30.0, 0.0), DVec2::new(10.0, 0.0), DVec2::ZERO);
        // A uniform spread over the 1.8 m rear face: 1.8² / 12 across the line of sight.
        let covariance = contour.covariance_m2;
        assert!(covariance.x_axis.x.abs() < 1e-12, "{covariance}");
        assert!((covariance.y_axis.y - 1.8f64.powi(2) / 12.0).abs() < 1e-12, "{covariance}");
    }

    #[test]
    fn seen_from_its_corner_the_points_spread_over_both_faces_about_their_centroid() {
        let extent = car();
        let centre = DVec2::new(30.0, 30.0);
        let contour = visible_contour(&extent, centre, DVec2::new(10.0, 0.0), DVec2::ZERO);
        // Sample the two visible faces densely, each point weighted by its face's cosine.
        let sensor_from_centre = -centre;
        let faces = [(DVec2::new(-1.0, 0.0), 2.25, 1.8), (DVec2::new(0.0, -1.0), 0.9, 4.5)];
        let (mut sum, mut second, mut total) = (DVec2::ZERO, DMat2::ZERO, 0.0);
        for (normal, half_depth, length) in faces {
            let middle = normal * half_depth;
            let towards = sensor_from_centre - middle;
            let cosine = normal.dot(towards) / towards.length();
            let steps = 2000;
            for step in 0..steps {
                let along = length * ((step as f64 + 0.5) / steps as f64 - 0.5);
                let point = middle + normal.perp() * along;
                let weight = cosine * length / steps as f64;
                sum += point * weight;
                second += outer(point) * weight;
                total += weight;
            }
        }
        let mean = sum / total;
        let expected = second / total - outer(mean);
        assert!((contour.offset_m - mean).length() < 1e-9, "{} {mean}", contour.offset_m);
        for (got, want) in contour.covariance_m2.to_cols_array().iter().zip(expected.to_cols_array()) {
            assert!((got - want).abs() < 1e-4, "{} {expected}", contour.covariance_m2);
        }
    }

    #[test]
    fn a_standing_car_spreads_its_points_mostly_across_the_line_of_sight() {
        let extent = car();
        let contour = visible_contour(&extent, DVec2::new(0.0, 20.0), DVec2::ZERO, DVec2::ZERO);
        let radius = 0.25 * (extent.length_m + extent.width_m);
        let covariance = contour.covariance_m2;
        assert!((covariance.x_axis.x - radius * radius / 3.0).abs() < 1e-12, "{covariance}");
        let along = radius * radius * (2.0 / 3.0 - QUARTER_PI * QUARTER_PI);
        assert!((covariance.y_axis.y - along).abs() < 1e-12 && covariance.x_axis.y.abs() < 1e-12);
        assert!(covariance.y_axis.y < 0.2 * covariance.x_axis.x);
    }

    #[test]
    fn the_mean_of_a_groups_detections_scatters_about_the_centre_as_its_noise_says() {
        // Groups of 4 detections on a car seen from its corner: each falls on a visible face
        // (by the faces' weights, uniformly along it) and carries the radar's noise. The
        // moved means' covariance about the centre is the contour's and the radar's over 4.
        let extent = car();
        let centre = DVec2::new(30.0, 30.0);
        let contour = visible_contour(&extent, centre, DVec2::new(10.0, 0.0), DVec2::ZERO);
        let radar_noise = DMat2::from_diagonal(DVec2::new(0.09, 0.25));
        let faces = [(DVec2::new(-1.0, 0.0), 2.25, 1.8), (DVec2::new(0.0, -1.0), 0.9, 4.5)];
        let weights: Vec<f64> = faces
            .iter()
            .map(|&(normal, half_depth, length)| {
                let towards = -centre - normal * half_depth;
                length * normal.dot(towards) / towards.length()
            })
            .collect();
        let mut state = 7u64;
        let mut uniform = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let (count, trials) = (4usize, 40_000usize);
        let mut second = DMat2::ZERO;
        for _ in 0..trials {
            let mut sum = DVec2::ZERO;
            for _ in 0..count {
                let (normal, half_depth, length) =
                    if uniform() * (weights[0] + weights[1]) < weights[0] { faces[0] } else { faces[1] };
                let point = normal * half_depth + normal.perp() * (length * (uniform() - 0.5));
                // Box–Muller for the radar's noise, axis by axis.
                let (u1, u2) = (uniform(), uniform());
                let radius = (-2.0 * u1.ln()).sqrt();
                let angle = 2.0 * core::f64::consts::PI * u2;
                let noise = DVec2::new(0.3 * radius * angle.cos(), 0.5 * radius * angle.sin());
                sum += point + noise;
            }
            let error = sum / count as f64 - contour.offset_m;
            second += outer(error);
        }
        let measured = second / trials as f64;
        let expected = group_noise_m2(radar_noise, contour.covariance_m2, count, 1.0);
        for (got, want) in measured.to_cols_array().iter().zip(expected.to_cols_array()) {
            assert!(
                (got - want).abs() < 0.05 * expected.x_axis.x.max(expected.y_axis.y),
                "{measured} {expected}"
            );
        }
        // The radar's noise undivided would overstate it by far.
        let undivided = radar_noise + contour.covariance_m2 * (1.0 / count as f64);
        assert!(undivided.y_axis.y > 1.5 * measured.y_axis.y, "{undivided} {measured}");
    }

    #[test]
    fn the_group_noise_scale_takes_its_share_of_the_means_spread() {
        let radar_noise = DMat2::from_diagonal(DVec2::new(0.09, 1.0));
        let contour = DMat2::from_cols(DVec2::new(1.2, 0.3), DVec2::new(0.3, 0.4));
        let full = group_noise_m2(radar_noise, contour, 3, 1.0);
        let scaled = group_noise_m2(radar_noise, contour, 3, 0.3);
        for (got, want) in scaled.to_cols_array().iter().zip(full.to_cols_array()) {
            assert!((got - 0.3 * want).abs() < 1e-12, "{scaled} {full}");
        }
        // A count below one counts as one detection: its own noise and the contour's spread.
        assert_eq!(group_noise_m2(radar_noise, contour, 0, 1.0), radar_noise + contour);
    }
}
