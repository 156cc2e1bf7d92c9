//! The tracks of a `TrackFrame` as a Foxglove `SceneUpdate`: per track a box (sized by class,
//! turned along the velocity), a velocity arrow (its length the distance covered in one second),
//! the 2σ position ellipse and a label with the id, class and speed.

use foxglove::schemas::{
    line_primitive, scene_entity_deletion, ArrowPrimitive, Color, CubePrimitive, KeyValuePair, LinePrimitive,
    Point3, Pose, Quaternion, SceneEntity, SceneEntityDeletion, SceneUpdate, TextPrimitive, Timestamp,
    Vector3,
};
use primm_wire::{TrackFrame, WireTrack};

/// Name of the world frame (the ego pose's frame).
pub const WORLD_FRAME: &str = "world";
/// Name of the vehicle frame (measurements and vehicle-frame tracks).
pub const VEHICLE_FRAME: &str = "vehicle";
/// Points of an ellipse's outline.
const ELLIPSE_POINTS: usize = 32;
/// Speeds below this draw no arrow and leave the box unturned, m/s.
const STILL_MPS: f64 = 0.2;

/// A class's name, colour and box size (length, width, height in m).
pub(crate) fn class_look(class_code: u8) -> (&'static str, Color, [f64; 3]) {
    match class_code {
        0 => ("car", rgb(0.20, 0.55, 0.95), [4.5, 1.8, 1.5]),
        1 => ("pedestrian", rgb(0.95, 0.60, 0.10), [0.6, 0.6, 1.7]),
        2 => ("two-wheeler", rgb(0.25, 0.80, 0.35), [2.0, 0.8, 1.4]),
        _ => ("unknown", rgb(0.6, 0.6, 0.6), [1.0, 1.0, 1.0]),
    }
}

fn rgb(r: f64, g: f64, b: f64) -> Color {
    Color { r, g, b, a: 1.0 }
}

/// `color` with opacity `a`.
pub(crate) fn with_alpha(color: Color, a: f64) -> Color {
    Color { a, ..color }
}

/// A pose at `(x, y, z)` turned by `yaw_rad` about the z axis.
pub(crate) fn pose(x: f64, y: f64, z: f64, yaw_rad: f64) -> Pose {
    Pose { position: Some(Vector3 { x, y, z }), orientation: Some(yaw_quaternion(yaw_rad)) }
}

/// The rotation by `yaw_rad` about the z axis.
pub(crate) fn yaw_quaternion(yaw_rad: f64) -> Quaternion {
    let half = 0.5 * yaw_rad;
    Quaternion { x: 0.0, y: 0.0, z: half.sin(), w: half.cos() }
}

/// A log time as a Foxglove timestamp.
pub(crate) fn timestamp(log_time_ns: u64) -> Timestamp {
    Timestamp::new(
        (log_time_ns / 1_000_000_000).min(u64::from(u32::MAX)) as u32,
        (log_time_ns % 1_000_000_000) as u32,
    )
}

/// A deletion of every entity of the topic: each update replaces the whole scene.
pub(crate) fn delete_all(log_time_ns: u64) -> SceneEntityDeletion {
    SceneEntityDeletion {
        timestamp: Some(timestamp(log_time_ns)),
        r#type: scene_entity_deletion::Type::All as i32,
        id: String::new(),
    }
}

/// The state a track is drawn with: the world frame's when valid, else the vehicle frame's.
struct DrawnState<'a> {
    frame_id: &'static str,
    position: [f64; 2],
    velocity: [f64; 2],
    covariance: [f64; 4],
    track: &'a WireTrack,
}

impl<'a> DrawnState<'a> {
    fn of(track: &'a WireTrack) -> Self {
        match track.world() {
            Some([x, y, vx, vy]) => {
                let c = &track.world_state_covariance;
                Self {
                    frame_id: WORLD_FRAME,
                    position: [x, y],
                    velocity: [vx, vy],
                    covariance: [c[0], c[1], c[4], c[5]],
                    track,
                }
            }
            None => Self {
                frame_id: VEHICLE_FRAME,
                position: [track.x_m, track.y_m],
                velocity: [track.vx_mps, track.vy_mps],
                covariance: track.position_covariance_m2(),
                track,
            },
        }
    }
}

/// Opacity by lifecycle status: confirmed tracks solid, coasting ones fainter, tentative faint.
fn status_alpha(status: u8) -> (&'static str, f64) {
    match status {
        1 => ("confirmed", 0.8),
        2 => ("coasting", 0.5),
        _ => ("tentative", 0.25),
    }
}

/// The scene of `frame`'s tracks at `log_time_ns`.
pub fn track_scene(frame: &TrackFrame, log_time_ns: u64) -> SceneUpdate {
    let entities = frame.valid_tracks().iter().map(|track| track_entity(track, log_time_ns)).collect();
    SceneUpdate { deletions: vec![delete_all(log_time_ns)], entities }
}

/// One track's entity.
fn track_entity(track: &WireTrack, log_time_ns: u64) -> SceneEntity {
    let state = DrawnState::of(track);
    let (class, color, [length, width, height]) = class_look(track.class_code);
    let (status, alpha) = status_alpha(track.status);
    let [x, y] = state.position;
    let [vx, vy] = state.velocity;
    let speed = vx.hypot(vy);
    let heading = if speed >= STILL_MPS { vy.atan2(vx) } else { 0.0 };
    let mut entity = SceneEntity {
        timestamp: Some(timestamp(log_time_ns)),
        frame_id: state.frame_id.to_owned(),
        id: format!("track/{}", track.id),
        cubes: vec![CubePrimitive {
            pose: Some(pose(x, y, 0.5 * height, heading)),
            size: Some(Vector3 { x: length, y: width, z: height }),
            color: Some(with_alpha(color, alpha)),
        }],
        texts: vec![TextPrimitive {
            pose: Some(pose(x, y, height + 0.8, 0.0)),
            billboard: true,
            font_size: 14.0,
            scale_invariant: true,
            color: Some(rgb(1.0, 1.0, 1.0)),
            text: format!("{} {class} {speed:.1} m/s", track.id),
        }],
        metadata: metadata(&state, class, status),
        ..Default::default()
    };
    if speed >= STILL_MPS {
        let head_length = 0.6_f64.min(speed);
        entity.arrows.push(ArrowPrimitive {
            pose: Some(pose(x, y, height + 0.2, heading)),
            shaft_length: (speed - head_length).max(0.05),
            shaft_diameter: 0.15,
            head_length,
            head_diameter: 0.45,
            color: Some(with_alpha(color, 1.0)),
        });
    }
    if let Some(outline) = two_sigma_ellipse(state.position, state.covariance) {
        entity.lines.push(LinePrimitive {
            r#type: line_primitive::Type::LineLoop as i32,
            pose: Some(pose(0.0, 0.0, 0.05, 0.0)),
            thickness: 2.0,
            scale_invariant: true,
            points: outline,
            color: Some(with_alpha(color, 1.0)),
            ..Default::default()
        });
    }
    entity
}

/// The track's fields a panel shows on selection.
fn metadata(state: &DrawnState<'_>, class: &str, status: &str) -> Vec<KeyValuePair> {
    let track = state.track;
    let pair = |key: &str, value: String| KeyValuePair { key: key.to_owned(), value };
    vec![
        pair("id", track.id.to_string()),
        pair("class", class.to_owned()),
        pair("status", status.to_owned()),
        pair("existence_probability", format!("{:.3}", track.existence_probability)),
        pair("age_s", format!("{:.2}", track.age_s)),
        pair("hits", track.hits.to_string()),
        pair("misses", track.misses.to_string()),
        pair("gt_id", track.gt_id.to_string()),
        pair("frame", state.frame_id.to_owned()),
    ]
}

/// The outline of the 2σ ellipse of a position with covariance `[xx, xy, yx, yy]` (m²); `None`
/// when the covariance is not finite.
pub(crate) fn two_sigma_ellipse(center: [f64; 2], covariance: [f64; 4]) -> Option<Vec<Point3>> {
    let [xx, xy, yx, yy] = covariance;
    let xy = 0.5 * (xy + yx);
    if ![xx, xy, yy].iter().all(|v| v.is_finite()) {
        return None;
    }
    let mean = 0.5 * (xx + yy);
    let spread = (0.25 * (xx - yy) * (xx - yy) + xy * xy).sqrt();
    let major = 2.0 * (mean + spread).max(0.0).sqrt();
    let minor = 2.0 * (mean - spread).max(0.0).sqrt();
    let angle = 0.5 * (2.0 * xy).atan2(xx - yy);
    let (sin, cos) = angle.sin_cos();
    Some(
        (0..ELLIPSE_POINTS)
            .map(|k| {
                let t = k as f64 * core::f64::consts::TAU / ELLIPSE_POINTS as f64;
                let (a, b) = (major * t.cos(), minor * t.sin());
                Point3 { x: center[0] + a * cos - b * sin, y: center[1] + a * sin + b * cos, z: 0.0 }
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ellipse_of_a_diagonal_covariance_reaches_two_standard_deviations_along_each_axis() {
        let points = two_sigma_ellipse([10.0, -2.0], [4.0, 0.0, 0.0, 1.0]).unwrap();
        let far_x = points.iter().map(|p| (p.x - 10.0).abs()).fold(0.0, f64::max);
        let far_y = points.iter().map(|p| (p.y + 2.0).abs()).fold(0.0, f64::max);
        assert!((far_x - 4.0).abs() < 1e-9 && (far_y - 2.0).abs() < 0.02, "{far_x} {far_y}");
        assert!(two_sigma_ellipse([0.0, 0.0], [f64::NAN, 0.0, 0.0, 1.0]).is_none());
    }

    #[test]
    fn a_moving_confirmed_track_gets_a_box_an_arrow_an_ellipse_and_its_label() {
        let mut frame = crate::raw::zeroed_box::<TrackFrame>();
        frame.count = 1;
        let track = &mut frame.tracks[0];
        (track.id, track.class_code, track.status) = (42, 1, 1);
        (track.x_m, track.y_m, track.vx_mps, track.vy_mps) = (5.0, 1.0, 0.0, 1.5);
        track.state_covariance[0] = 0.25;
        track.state_covariance[5] = 0.25;
        let scene = track_scene(&frame, 2_500_000_000);
        assert_eq!(scene.entities.len(), 1);
        let entity = &scene.entities[0];
        assert_eq!((entity.id.as_str(), entity.frame_id.as_str()), ("track/42", VEHICLE_FRAME));
        assert_eq!((entity.cubes.len(), entity.arrows.len(), entity.lines.len()), (1, 1, 1));
        assert!(entity.texts[0].text.starts_with("42 pedestrian 1.5"), "{}", entity.texts[0].text);
        let q = entity.arrows[0].pose.unwrap().orientation.unwrap();
        assert!((2.0 * q.z.atan2(q.w) - core::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(entity.timestamp, Some(Timestamp::new(2, 500_000_000)));
    }
}
