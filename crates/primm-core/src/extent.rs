//! Extended objects: where on a car the radar's reflection is expected, so that a track's state
//! is the object's centre and not the reflection point.
//!
//! A radar sees a car at a point of its outline facing the sensor, which moves over the body as
//! the aspect and the sensor change; the paper's point model (`eq:observation`) then tracks a
//! point that jumps between scans and sensors by up to half the car's length. With
//! `classes.<class>.extent.enabled` the measurement model becomes
//!
//! ```text
//! z = p + o(p, θ, s) + w,   w ~ N(0, R + C(p, θ, s))
//! ```
//!
//! with `p` the centre, `θ` the heading (of the track's velocity), `s` the sensor's position,
//! `o` the expected offset of the reflection from the centre and `C` the spread of the
//! reflection along the visible contour ([`expected_reflection`]; ARCHITECTURE.md, "Extended
//! objects"). The offset is evaluated at the track's fused prior and treated as known, so the
//! update is the ordinary one with `z − o` and `R + C`; association and the existence
//! likelihood score `z − o` against the prior with `C` added to the innovation covariance, and
//! a new track starts at `z − o` (without heading: the disc model below).
//!
//! * **Box (heading known).** A box of `length_m × width_m` centred at `p`, its long axis along
//!   the velocity: the expected reflection is the box's point nearest to the sensor (the sensor
//!   position clamped to the box in the box's axes), the point a radar return concentrates on.
//!   The spread `contour_std_m` lies along the contour there, across the direction from that
//!   point to the sensor.
//! * **Disc (no heading).** Below `min_heading_speed_mps` the heading of a velocity estimate
//!   means nothing; the box is replaced by the expectation over every heading, approximated by
//!   a disc: the reflection lies `(length + width)/4` from the centre toward the sensor, spread
//!   by `(length − width)/4` along the line of sight and `contour_std_m` across it.
//! * Between one and two times `min_heading_speed_mps` the two are blended (a two-component
//!   mixture: mean and covariance with the spread of the means), so that the offset does not
//!   jump when a track speeds up.

use crate::math;
use glam::{DMat2, DVec2};

/// The section `classes.<class>.extent`: the object's nominal size and the reflection's spread.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct ExtentConfig {
    /// Whether the class is tracked as an extended object (its state the centre).
    pub enabled: bool,
    /// Nominal length along the heading, m.
    pub length_m: f64,
    /// Nominal width across the heading, m (at most `length_m`).
    pub width_m: f64,
    /// Standard deviation of the reflection along the visible contour, m.
    pub contour_std_m: f64,
    /// Speed below which the velocity gives no heading (the disc model), m/s; the box model
    /// takes over fully at twice this speed.
    pub min_heading_speed_mps: f64,
    /// How far toward the nearest point of the outline a reported detection lies, from the
    /// centre (0) to the point itself (1), dimensionless in (0, 1]: a single strongest
    /// reflection sits on the outline, a detection that a radar's clustering averaged over the
    /// visible faces lies further in. Scales the offset, and the spread's standard deviations.
    #[cfg_attr(feature = "serde", serde(default = "default_offset_scale"))]
    pub offset_scale: f64,
    /// Whether a measurement left unassigned that lies on a confirmed track's object (its box,
    /// grown by `absorb_margin_m`) is taken as a second detection of that object rather than
    /// the start of a new track (counted; it updates nothing).
    #[cfg_attr(feature = "serde", serde(default))]
    pub absorb_extra_detections: bool,
    /// How far outside a track's box an extra detection may lie and still be absorbed, m.
    #[cfg_attr(feature = "serde", serde(default = "default_absorb_margin_m"))]
    pub absorb_margin_m: f64,
}

#[cfg(feature = "serde")]
fn default_offset_scale() -> f64 {
    1.0
}

#[cfg(feature = "serde")]
fn default_absorb_margin_m() -> f64 {
    1.0
}

impl Default for ExtentConfig {
    /// Off; a 4.5 × 1.8 m car with 0.5 m of contour spread, headings from 1 m/s, extra
    /// detections not absorbed (1 m of margin when they are).
    fn default() -> Self {
        ExtentConfig {
            enabled: false,
            length_m: 4.5,
            width_m: 1.8,
            contour_std_m: 0.5,
            min_heading_speed_mps: 1.0,
            offset_scale: 1.0,
            absorb_extra_detections: false,
            absorb_margin_m: 1.0,
        }
    }
}

impl ExtentConfig {
    /// The largest offset the model can give, m: half the box's diagonal.
    pub fn max_offset_m(&self) -> f64 {
        math::sqrt(math::square(0.5 * self.length_m) + math::square(0.5 * self.width_m))
    }

    /// An upper bound on every diagonal element of [`ExpectedReflection::covariance_m2`], m²:
    /// each box axis adds at most `h²` (`h` its half extent: a mixture on `[−h, h]`), the contour spread its
    /// variance, and the spread of the means of any mixture of offsets, all within
    /// [`max_offset_m`](Self::max_offset_m) of the centre, at most that squared.
    pub fn max_spread_m2(&self) -> f64 {
        (math::square(self.length_m) + math::square(self.width_m)) / 4.0
            + math::square(self.contour_std_m)
            + math::square(self.max_offset_m())
    }
}

/// Where the reflection of an object is expected, relative to its centre.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ExpectedReflection {
    /// Expected offset of the reflection from the centre, m (in the frame of the positions).
    pub offset_m: DVec2,
    /// Covariance of the reflection around that point, m² (added to `R`).
    pub covariance_m2: DMat2,
}

impl ExpectedReflection {
    /// A point object: no offset, no spread.
    pub const POINT: ExpectedReflection =
        ExpectedReflection { offset_m: DVec2::ZERO, covariance_m2: DMat2::ZERO };
}

/// What the tracker believes of an object before the measurement: its fused prior.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ObjectPrior {
    /// Centre, m.
    pub centre_m: DVec2,
    /// Covariance of the centre, m².
    pub centre_covariance_m2: DMat2,
    /// Velocity, m/s (its direction is the heading).
    pub velocity_mps: DVec2,
    /// Covariance of the velocity, m²/s².
    pub velocity_covariance_m2: DMat2,
}

/// Heading uncertainty from which the box model starts to give way to the disc, rad.
const HEADING_STD_BOX_RAD: f64 = 0.6;
/// Heading uncertainty at which only the disc model is left, rad.
const HEADING_STD_DISC_RAD: f64 = 1.0;

/// The expected reflection of an object of `extent` with prior `object`, seen by a sensor at
/// `sensor_m` (all in one frame), for a sensor whose detections lie `scale` of the way from the
/// centre (0) to the outline (1): the outline's offset and spread, scaled (the sensor's
/// measurement model, `crate::sensor`; see the module documentation for the box and disc
/// models). At scale 0, a point.
pub fn expected_reflection(
    extent: &ExtentConfig,
    object: &ObjectPrior,
    sensor_m: DVec2,
    scale: f64,
) -> ExpectedReflection {
    if !(scale > 0.0) {
        return ExpectedReflection::POINT;
    }
    let reflection = outline_reflection(extent, object, sensor_m);
    ExpectedReflection {
        offset_m: reflection.offset_m * scale,
        covariance_m2: reflection.covariance_m2 * (scale * scale),
    }
}

/// [`expected_reflection`] on the outline itself (scale 1).
pub fn outline_reflection(
    extent: &ExtentConfig,
    object: &ObjectPrior,
    sensor_m: DVec2,
) -> ExpectedReflection {
    let to_sensor = sensor_m - object.centre_m;
    let range = to_sensor.length();
    if !(range > 1e-6) {
        return ExpectedReflection { offset_m: DVec2::ZERO, covariance_m2: disc_spread(extent, DVec2::X) };
    }
    let line_of_sight = to_sensor / range;
    let disc = ExpectedReflection {
        offset_m: line_of_sight * (0.25 * (extent.length_m + extent.width_m)).min(range),
        covariance_m2: disc_spread(extent, line_of_sight),
    };
    let speed = object.velocity_mps.length();
    let by_speed = ((speed - extent.min_heading_speed_mps) / extent.min_heading_speed_mps).clamp(0.0, 1.0);
    if !(by_speed > 0.0) {
        return disc;
    }
    let heading = object.velocity_mps / speed;
    let across = heading.perp();
    let heading_std = math::sqrt(across.dot(object.velocity_covariance_m2 * across).max(0.0)) / speed;
    let by_heading =
        ((HEADING_STD_DISC_RAD - heading_std) / (HEADING_STD_DISC_RAD - HEADING_STD_BOX_RAD)).clamp(0.0, 1.0);
    let weight = by_speed * by_heading;
    if !(weight > 0.0) {
        return disc;
    }
    let position_variance =
        0.5 * (object.centre_covariance_m2.x_axis.x + object.centre_covariance_m2.y_axis.y);
    let boxed = box_over_heading(
        extent,
        to_sensor,
        heading,
        heading_std.min(HEADING_STD_DISC_RAD),
        position_variance,
    );
    if weight >= 1.0 {
        return boxed;
    }
    mixture(&[(1.0 - weight, disc), (weight, boxed)])
}

/// The box model averaged over the heading's uncertainty: three-point Gauss–Hermite quadrature
/// (headings `θ` and `θ ± √3 σ_θ`, weights 2/3, 1/6, 1/6) of [`box_reflection`].
fn box_over_heading(
    extent: &ExtentConfig,
    to_sensor: DVec2,
    heading: DVec2,
    heading_std_rad: f64,
    position_variance_m2: f64,
) -> ExpectedReflection {
    let centre = box_reflection(extent, to_sensor, heading, position_variance_m2);
    if !(heading_std_rad > 1e-9) {
        return centre;
    }
    // One sine and cosine serve both turns: sin(−a) = −sin(a), cos(−a) = cos(a).
    let (sin, cos) = math::sin_cos(1.732_050_807_568_877_2 * heading_std_rad);
    let turned = |sin: f64| {
        let heading = DVec2::new(heading.x * cos - heading.y * sin, heading.x * sin + heading.y * cos);
        box_reflection(extent, to_sensor, heading, position_variance_m2)
    };
    mixture(&[(2.0 / 3.0, centre), (1.0 / 6.0, turned(sin)), (1.0 / 6.0, turned(-sin))])
}

/// The mean and covariance (with the spread of the means) of a mixture of reflections.
fn mixture(components: &[(f64, ExpectedReflection)]) -> ExpectedReflection {
    let offset_m: DVec2 = components.iter().map(|(w, c)| c.offset_m * *w).sum();
    let covariance_m2 = components.iter().fold(DMat2::ZERO, |sum, (w, c)| {
        let difference = c.offset_m - offset_m;
        sum + (c.covariance_m2 + outer(difference, difference)) * *w
    });
    ExpectedReflection { offset_m, covariance_m2 }
}

/// The point of a `length_m × width_m` box centred at `centre_m` with its long axis along the
/// unit vector `heading` that is nearest to `point_m` (`point_m` itself when inside).
pub fn nearest_point_of_box(
    length_m: f64,
    width_m: f64,
    centre_m: DVec2,
    heading: DVec2,
    point_m: DVec2,
) -> DVec2 {
    let d = point_m - centre_m;
    let along = d.dot(heading).clamp(-0.5 * length_m, 0.5 * length_m);
    let across = d.dot(heading.perp()).clamp(-0.5 * width_m, 0.5 * width_m);
    centre_m + heading * along + heading.perp() * across
}

/// Whether `point_m` lies on the object of `extent` centred at `centre_m` and moving with
/// `velocity_mps`: inside its box grown by `absorb_margin_m` (heading from the velocity), or,
/// below `min_heading_speed_mps`, within the disc of radius `length_m / 2` grown likewise.
pub fn lies_on_object(extent: &ExtentConfig, centre_m: DVec2, velocity_mps: DVec2, point_m: DVec2) -> bool {
    let offset = point_m - centre_m;
    let speed = velocity_mps.length();
    let margin = extent.absorb_margin_m;
    if !(speed >= extent.min_heading_speed_mps) {
        return offset.length() <= 0.5 * extent.length_m + margin;
    }
    let heading = velocity_mps / speed;
    offset.dot(heading).abs() <= 0.5 * extent.length_m + margin
        && offset.dot(heading.perp()).abs() <= 0.5 * extent.width_m + margin
}

/// The box model for one heading, axis by axis in the box's axes. Along an axis on which the
/// sensor lies beyond the box (the reflection on the face toward it, or a corner) the offset is
/// that face's, exactly; along an axis on which the sensor lies within the box's extent, the
/// reflection sits opposite the sensor wherever the centre is, so it says where the centre is
/// only up to the face's length: offset 0 and the variance of a uniform position over the face
/// (`extent²/12`). Which case holds is soft, a logistic of how far beyond the face the sensor
/// is against the prior's position spread, so the model changes smoothly. The contour spread
/// lies along the outline at the expected point.
fn box_reflection(
    extent: &ExtentConfig,
    to_sensor: DVec2,
    heading: DVec2,
    position_variance_m2: f64,
) -> ExpectedReflection {
    let spread_m = math::sqrt(position_variance_m2 + math::square(extent.contour_std_m));
    let mut offset_m = DVec2::ZERO;
    let mut covariance_m2 = DMat2::ZERO;
    for (axis, half) in [(heading, 0.5 * extent.length_m), (heading.perp(), 0.5 * extent.width_m)] {
        let d = to_sensor.dot(axis);
        // Probabilities that the sensor lies beyond the positive and the negative face; the
        // three-component mixture (either face, or within) has a mean continuous in `d`.
        let beyond = |excess: f64| 1.0 / (1.0 + math::exp(-1.702 * excess / spread_m));
        let (positive, negative) = (beyond(d - half), beyond(-d - half));
        let within = (1.0 - positive - negative).max(0.0);
        let mean = half * (positive - negative);
        let variance = positive * math::square(half - mean)
            + negative * math::square(half + mean)
            + within * (math::square(2.0 * half) / 12.0 + mean * mean);
        offset_m += axis * mean;
        covariance_m2 += outer(axis, axis) * variance;
    }
    let normal = to_sensor - offset_m;
    let length = normal.length();
    if length > 1e-6 {
        let tangent = (normal / length).perp();
        covariance_m2 += outer(tangent, tangent) * math::square(extent.contour_std_m);
    }
    ExpectedReflection { offset_m, covariance_m2 }
}

/// The disc model's spread: `(length − width)/4` along the line of sight, the contour spread
/// across it.
fn disc_spread(extent: &ExtentConfig, line_of_sight: DVec2) -> DMat2 {
    let across = line_of_sight.perp();
    outer(line_of_sight, line_of_sight) * math::square(0.25 * (extent.length_m - extent.width_m))
        + outer(across, across) * math::square(extent.contour_std_m)
}

fn outer(a: DVec2, b: DVec2) -> DMat2 {
    DMat2::from_cols(a * b.x, a * b.y)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn car() -> ExtentConfig {
        ExtentConfig { enabled: true, ..ExtentConfig::default() }
    }

    /// A prior at `centre` moving with `velocity`, its centre known to 0.3 m and its velocity
    /// to 0.2 m/s.
    fn prior(centre: DVec2, velocity: DVec2) -> ObjectPrior {
        ObjectPrior {
            centre_m: centre,
            centre_covariance_m2: DMat2::from_diagonal(DVec2::splat(0.09)),
            velocity_mps: velocity,
            velocity_covariance_m2: DMat2::from_diagonal(DVec2::splat(0.04)),
        }
    }

    fn near(a: DVec2, b: DVec2, tolerance: f64) -> bool {
        (a - b).length() < tolerance
    }

    #[test]
    fn seen_from_behind_the_reflection_is_on_the_rear_and_says_little_across_it() {
        // A car driving along +x at 10 m/s, the sensor 20 m behind it.
        let reflection = expected_reflection(
            &car(),
            &prior(DVec2::new(20.0, 0.0), DVec2::new(10.0, 0.0)),
            DVec2::ZERO,
            1.0,
        );
        assert!(near(reflection.offset_m, DVec2::new(-2.25, 0.0), 0.05), "{reflection:?}");
        // Along x the rear face pins the centre; across it, the reflection is opposite the
        // sensor wherever the car is: the width's uniform spread and the contour spread.
        assert!(reflection.covariance_m2.x_axis.x < 0.01, "{reflection:?}");
        assert!(reflection.covariance_m2.y_axis.y > 1.8 * 1.8 / 12.0, "{reflection:?}");
    }

    #[test]
    fn seen_from_a_diagonal_the_reflection_is_the_nearest_corner() {
        let reflection = expected_reflection(
            &car(),
            &prior(DVec2::new(10.0, 10.0), DVec2::new(0.0, 5.0)),
            DVec2::ZERO,
            1.0,
        );
        // Heading +y: the long axis is y, the width x; the corner toward the origin.
        assert!(near(reflection.offset_m, DVec2::new(-0.9, -2.25), 0.05), "{reflection:?}");
    }

    #[test]
    fn abeam_the_reflection_is_on_the_near_side_and_the_position_along_it_is_left_open() {
        let reflection = expected_reflection(
            &car(),
            &prior(DVec2::new(0.5, 10.0), DVec2::new(-8.0, 0.0)),
            DVec2::ZERO,
            1.0,
        );
        assert!(near(reflection.offset_m, DVec2::new(0.0, -0.9), 0.05), "{reflection:?}");
        // Along the side (x) the variance is the length's uniform spread.
        assert!(reflection.covariance_m2.x_axis.x > 4.5 * 4.5 / 12.0 * 0.95, "{reflection:?}");
        assert!(reflection.covariance_m2.y_axis.y < 0.05, "{reflection:?}");
    }

    #[test]
    fn the_nearest_point_of_a_box_matches_a_search_over_its_outline() {
        for i in 0..200 {
            let angle = f64::from(i) * 0.31;
            let heading = DVec2::new(angle.cos(), angle.sin());
            let centre = DVec2::new(15.0 + 3.0 * (0.7 * angle).sin(), -4.0 + 6.0 * (1.3 * angle).cos());
            let sensor = DVec2::new(3.0 * (0.4 * angle).cos(), 2.0 * (0.9 * angle).sin());
            let ours = nearest_point_of_box(4.5, 1.8, centre, heading, sensor);
            let best = (0..=4000)
                .map(|k| {
                    let u = f64::from(k) / 4000.0 * 4.0;
                    let (along, across) = match u as u32 {
                        0 => (-2.25 + 4.5 * u, -0.9),
                        1 => (2.25, -0.9 + 1.8 * (u - 1.0)),
                        2 => (2.25 - 4.5 * (u - 2.0), 0.9),
                        _ => (-2.25, 0.9 - 1.8 * (u - 3.0)),
                    };
                    centre + heading * along + heading.perp() * across
                })
                .map(|point| (point - sensor).length())
                .fold(f64::INFINITY, f64::min);
            let distance = (ours - sensor).length();
            assert!(distance <= best + 1e-9 && distance >= best - 2e-3, "case {i}: {distance} vs {best}");
        }
    }

    #[test]
    fn without_a_heading_the_reflection_lies_toward_the_sensor() {
        let reflection = expected_reflection(
            &car(),
            &prior(DVec2::new(0.0, 30.0), DVec2::new(0.3, 0.0)),
            DVec2::ZERO,
            1.0,
        );
        assert!(near(reflection.offset_m, DVec2::new(0.0, -1.575), 1e-12), "{reflection:?}");
        let spread = reflection.covariance_m2;
        assert!((spread.y_axis.y - 0.675f64.powi(2)).abs() < 1e-12 && (spread.x_axis.x - 0.25).abs() < 1e-12);
        // An uncertain heading is no heading either.
        let mut unsure = prior(DVec2::new(0.0, 30.0), DVec2::new(5.0, 0.0));
        unsure.velocity_covariance_m2 = DMat2::from_diagonal(DVec2::splat(100.0));
        let reflection = expected_reflection(&car(), &unsure, DVec2::ZERO, 1.0);
        assert!(near(reflection.offset_m, DVec2::new(0.0, -1.575), 1e-12), "{reflection:?}");
    }

    #[test]
    fn the_offset_moves_smoothly_as_the_speed_and_the_heading_change() {
        let extent = car();
        let at = |speed: f64, angle: f64| {
            let velocity = DVec2::new(angle.cos(), angle.sin()) * speed;
            expected_reflection(&extent, &prior(DVec2::new(20.0, 3.0), velocity), DVec2::ZERO, 1.0)
        };
        let mut previous = at(1.0, 0.3).offset_m;
        for k in 1..=100 {
            let speed = 1.0 + f64::from(k) / 100.0;
            let offset = at(speed, 0.3).offset_m;
            assert!((offset - previous).length() < 0.05, "a jump at {speed} m/s");
            previous = offset;
        }
        previous = at(6.0, 0.3).offset_m;
        // A turn of the heading by δ moves the sensor's projection on the box's axes by up to
        // range·δ (here 20 m × 1 mrad).
        for k in 1..=3000 {
            let angle = 0.3 + f64::from(k) * 0.001;
            let reflection = at(6.0, angle);
            assert!((reflection.offset_m - previous).length() < 0.05, "a jump at {angle} rad");
            previous = reflection.offset_m;
            let c = reflection.covariance_m2;
            assert!((c.x_axis.y - c.y_axis.x).abs() < 1e-12);
            assert!(c.x_axis.x >= 0.0 && c.determinant() >= -1e-12);
            assert!(c.x_axis.x <= extent.max_spread_m2() && c.y_axis.y <= extent.max_spread_m2());
            assert!(reflection.offset_m.length() <= extent.max_offset_m() + 1e-12);
        }
    }

    #[test]
    fn a_point_on_the_box_or_within_the_margin_lies_on_the_object() {
        let extent = car();
        let (centre, velocity) = (DVec2::new(10.0, 0.0), DVec2::new(0.0, 8.0));
        // Heading +y: 4.5 m along y, 1.8 m along x, plus 1 m.
        assert!(lies_on_object(&extent, centre, velocity, DVec2::new(11.8, 3.2)));
        assert!(!lies_on_object(&extent, centre, velocity, DVec2::new(12.0, 0.0)));
        assert!(!lies_on_object(&extent, centre, velocity, DVec2::new(10.0, 3.3)));
        // Standing: a disc of 2.25 + 1 m.
        assert!(lies_on_object(&extent, centre, DVec2::ZERO, DVec2::new(13.2, 0.0)));
        assert!(!lies_on_object(&extent, centre, DVec2::ZERO, DVec2::new(13.3, 0.0)));
    }

    #[test]
    fn a_sensor_at_the_centre_gives_no_offset() {
        let reflection =
            expected_reflection(&car(), &prior(DVec2::ZERO, DVec2::new(5.0, 0.0)), DVec2::ZERO, 1.0);
        assert_eq!(reflection.offset_m, DVec2::ZERO);
        assert!(reflection.covariance_m2.determinant() > 0.0);
    }
}
