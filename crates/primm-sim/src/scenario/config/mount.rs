//! Radar mounts: where each simulated sensor sits and what it covers, in the tracker's own
//! layout type ([`SensorMount`]), plus the simulation-only errors of the sensor.
//!
//! A scenario file gives the boresight and the field of view in degrees (`yaw_deg`,
//! `half_fov_deg`) or, like the tracker's configuration, in radians (`yaw_rad`,
//! `half_fov_rad`); a mount is written out in radians, so that it reads back bit for bit.

use primm_core::coordinates::CoordinatesConfig;
use primm_core::pose::SensorMount;
use serde::{Deserialize, Serialize};

use super::RadarConfig;

/// Mounting of one radar on the ego vehicle, in the car frame (origin at the rear axle).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RadarMountFields", into = "RadarMountFields")]
pub struct RadarMount {
    /// Id, position, boresight, half field of view and range of the sensor, in the layout
    /// type of the tracker's `frame.sensors`. Its `detection_probability_factor`,
    /// `clutter_density_factor` and noise keys (`range_std_m`, `azimuth_std_rad`,
    /// `azimuth_std_max_factor`) describe the tracker's model, not the sensor; the generator
    /// leaves them neutral (1, 1, 0, 0, 1) and does not read them: its noise is `radar.*`.
    pub layout: SensorMount,
    /// Residual azimuth misalignment of this sensor, degrees.
    pub azimuth_bias_deg: f64,
    /// Factor on the azimuth noise of this sensor.
    pub azimuth_noise_scale: f64,
}

/// A [`RadarMount`] as a scenario file writes it.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RadarMountFields {
    /// Sensor id written to every frame of this sensor.
    id: u16,
    /// Longitudinal mounting position, metres.
    x_m: f64,
    /// Lateral mounting position (left positive), metres.
    y_m: f64,
    /// Boresight direction, degrees, counter-clockwise from the car's x axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    yaw_deg: Option<f64>,
    /// The same in radians.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    yaw_rad: Option<f64>,
    /// Half opening angle of the field of view, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    half_fov_deg: Option<f64>,
    /// The same in radians.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    half_fov_rad: Option<f64>,
    /// Largest detection range, metres.
    max_range_m: f64,
    /// Residual azimuth misalignment of this sensor, degrees.
    azimuth_bias_deg: f64,
    /// Factor on the azimuth noise of this sensor.
    azimuth_noise_scale: f64,
}

/// The angle given in degrees or in radians, in radians; an error unless exactly one is given.
fn one_angle(degrees: Option<f64>, radians: Option<f64>, name: &str) -> Result<f64, String> {
    match (degrees, radians) {
        (Some(degrees), None) => Ok(degrees.to_radians()),
        (None, Some(radians)) => Ok(radians),
        (None, None) => Err(format!("missing field `{name}_deg` (or `{name}_rad`)")),
        (Some(_), Some(_)) => Err(format!("give either `{name}_deg` or `{name}_rad`, not both")),
    }
}

impl TryFrom<RadarMountFields> for RadarMount {
    type Error = String;

    fn try_from(fields: RadarMountFields) -> Result<Self, Self::Error> {
        let layout = SensorMount {
            id: fields.id,
            x_m: fields.x_m,
            y_m: fields.y_m,
            yaw_rad: one_angle(fields.yaw_deg, fields.yaw_rad, "yaw")?,
            half_fov_rad: one_angle(fields.half_fov_deg, fields.half_fov_rad, "half_fov")?,
            max_range_m: fields.max_range_m,
            detection_probability_factor: 1.0,
            clutter_density_factor: 1.0,
            range_std_m: 0.0,
            azimuth_std_rad: 0.0,
            azimuth_std_max_factor: 1.0,
            reflection: primm_core::sensor::ReflectionModel::Outline,
            detections: Default::default(),
        };
        Ok(RadarMount {
            layout,
            azimuth_bias_deg: fields.azimuth_bias_deg,
            azimuth_noise_scale: fields.azimuth_noise_scale,
        })
    }
}

impl From<RadarMount> for RadarMountFields {
    fn from(mount: RadarMount) -> Self {
        let layout = mount.layout;
        RadarMountFields {
            id: layout.id,
            x_m: layout.x_m,
            y_m: layout.y_m,
            yaw_deg: None,
            yaw_rad: Some(layout.yaw_rad),
            half_fov_deg: None,
            half_fov_rad: Some(layout.half_fov_rad),
            max_range_m: layout.max_range_m,
            azimuth_bias_deg: mount.azimuth_bias_deg,
            azimuth_noise_scale: mount.azimuth_noise_scale,
        }
    }
}

/// The layout of a sensor whose boresight and half field of view are given in degrees,
/// converted as a scenario file's `yaw_deg` and `half_fov_deg` are, with the tracker's noise
/// and measurement-model keys neutral, as a scenario file's mounts have them.
pub(super) fn layout_in_degrees(
    id: u16,
    x_m: f64,
    y_m: f64,
    yaw_deg: f64,
    half_fov_deg: f64,
    max_range_m: f64,
) -> SensorMount {
    SensorMount {
        id,
        x_m,
        y_m,
        yaw_rad: yaw_deg.to_radians(),
        half_fov_rad: half_fov_deg.to_radians(),
        max_range_m,
        detection_probability_factor: 1.0,
        clutter_density_factor: 1.0,
        range_std_m: 0.0,
        azimuth_std_rad: 0.0,
        azimuth_std_max_factor: 1.0,
        reflection: primm_core::sensor::ReflectionModel::Outline,
        detections: Default::default(),
    }
}

impl RadarMount {
    /// The four-sensor layout used by default, modelled on RadarScenes: two front sensors
    /// turned 25° outwards and two side sensors turned 85° outwards, all on the front bumper,
    /// each with ±60° field of view and 100 m range: the tracker's default `frame.sensors`
    /// (`CoordinatesConfig::default`), with each sensor's azimuth errors.
    pub fn default_layout() -> Vec<RadarMount> {
        // The sensors are the tracker's default layout (one copy of it); the generator adds
        // each sensor's own errors.
        let errors = [(0.25, 1.2), (-0.1, 1.0), (0.15, 0.9), (-0.3, 1.3)];
        CoordinatesConfig::default()
            .sensors
            .iter()
            .zip(errors)
            .map(|(&layout, (azimuth_bias_deg, azimuth_noise_scale))| RadarMount {
                // The tracker's model of the sensor's noise is not the generator's: neutral
                // here, as a scenario file's mounts have it.
                layout: SensorMount {
                    range_std_m: 0.0,
                    azimuth_std_rad: 0.0,
                    azimuth_std_max_factor: 1.0,
                    reflection: primm_core::sensor::ReflectionModel::Outline,
                    detections: Default::default(),
                    ..layout
                },
                azimuth_bias_deg,
                azimuth_noise_scale,
            })
            .collect()
    }
}

impl RadarConfig {
    /// The layout of the sensors, in order: what the tracker's `frame.sensors` should list
    /// to track these sensors' measurements.
    pub fn sensor_layout(&self) -> Vec<SensorMount> {
        self.sensors.iter().map(|sensor| sensor.layout).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::layout_in_degrees;
    use crate::scenario::{RadarMount, ScenarioConfig};

    const DEGREES: &str = "[[radar.sensors]]\nid = 7\nx_m = 1.0\ny_m = -0.5\nyaw_deg = -25.0\n\
                           half_fov_deg = 60.0\nmax_range_m = 90.0\nazimuth_bias_deg = 0.2\n\
                           azimuth_noise_scale = 1.1\n";

    #[test]
    fn a_mount_in_degrees_reads_as_the_same_angles_in_radians() {
        let config = ScenarioConfig::from_toml_str(DEGREES).expect("a mount in degrees");
        let layout = layout_in_degrees(7, 1.0, -0.5, -25.0, 60.0, 90.0);
        let expected = RadarMount { layout, azimuth_bias_deg: 0.2, azimuth_noise_scale: 1.1 };
        assert_eq!(config.radar.sensors, vec![expected.clone()]);
        assert_eq!(config.radar.sensors[0].layout.yaw_rad, (-25f64).to_radians());
        let radians = DEGREES
            .replace("yaw_deg = -25.0", &format!("yaw_rad = {:?}", (-25f64).to_radians()))
            .replace("half_fov_deg = 60.0", &format!("half_fov_rad = {:?}", 60f64.to_radians()));
        let config = ScenarioConfig::from_toml_str(&radians).expect("a mount in radians");
        assert_eq!(config.radar.sensors, vec![expected]);
    }

    #[test]
    fn a_mount_needs_exactly_one_unit_per_angle_and_reads_back_bit_for_bit() {
        let both = DEGREES.replace("yaw_deg = -25.0", "yaw_deg = -25.0\nyaw_rad = -0.4");
        let error = ScenarioConfig::from_toml_str(&both).unwrap_err().to_string();
        assert!(error.contains("not both"), "{error}");
        let neither = DEGREES.replace("half_fov_deg = 60.0\n", "");
        let error = ScenarioConfig::from_toml_str(&neither).unwrap_err().to_string();
        assert!(error.contains("half_fov_deg"), "{error}");
        let config = ScenarioConfig::from_toml_str(DEGREES).expect("a mount in degrees");
        let text = toml::to_string(&config).expect("serialise");
        assert_eq!(ScenarioConfig::from_toml_str(&text).expect("parse"), config);
    }
}
