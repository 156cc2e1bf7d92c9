//! Named configurations: the reference one and its variants.

use serde::{Deserialize, Serialize};

use super::mount::RadarMount;
use super::types::{
    CarConfig, ClutterConfig, EgoPlacement, ExtendedObjectConfig, OutputConfig, PedestrianConfig,
    PointCloudConfig, RadarReport,
};
use super::ScenarioConfig;
use primm_core::pose::SensorMount;

/// Named configurations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Preset {
    /// The reference configuration ([`ScenarioConfig::default`]).
    Default,
    /// A harder configuration for robustness checks: faster and more aggressive cars, more
    /// erratic and faster pedestrians, denser traffic, noisier sensors with more misses, and
    /// more false detections than [`Preset::Clutter`].
    Robustness,
    /// The default scene seen from an ego vehicle that turns at most junctions of a denser
    /// road grid, at town speeds: ego yaw rates up to about 0.5 rad/s.
    Turning,
    /// The default scene with false detections ([`ClutterConfig::urban`]): about 1.5 per scan,
    /// mostly static, some moving-looking, a few multipath ghosts.
    Clutter,
    /// The [`Preset::Turning`] scene with the false detections of [`Preset::Clutter`].
    ClutterTurning,
    /// The default scene with vehicles measured as extended objects
    /// ([`ExtendedObjectConfig::vehicles`]): detections from the visible contour and corners of
    /// each vehicle's box, now and then several per vehicle and scan.
    Extended,
    /// The [`Preset::Turning`] scene with the extended vehicles of [`Preset::Extended`].
    ExtendedTurning,
    /// The [`Preset::Clutter`] scene with the extended vehicles of [`Preset::Extended`].
    ExtendedClutter,
    /// The [`Preset::ClutterTurning`] scene with the extended vehicles of [`Preset::Extended`].
    ExtendedClutterTurning,
    /// The default scene seen by object-list radars ([`RadarReport::Centre`]): every detected
    /// object, car or pedestrian, is reported at its true centre plus one point's range,
    /// azimuth and Doppler noise.
    Centroid,
    /// One static roadside radar beside a junction ([`EgoPlacement::Roadside`]) in dense
    /// traffic, 25 to 45 objects in view, scanning every 50 to 80 ms, with a little clutter;
    /// its frames carry no ego pose and no sensor id ([`OutputConfig`]). Cars are measured
    /// with the averaged echo of the default, which lies on the faces towards the sensor.
    DenseStatic,
    /// The [`Preset::ClutterTurning`] scene seen by detection-level radars
    /// ([`PointCloudConfig::detections`]): several detections per car over its visible faces
    /// and wheels (with wheel micro-Doppler), one or two per pedestrian, more pedestrians
    /// walking in groups side by side, multipath ghosts behind the walls along the roads, about
    /// three clutter points per scan, and a tenth of the class labels wrong.
    PointCloud,
    /// The [`Preset::PointCloud`] scene from radars that resolve range finer than azimuth
    /// ([`ReflectionConfig::range_extent_weight`] 3): a car's faces hold points by their depth
    /// in range as well as their apparent width, so a car ahead and aside shows its near side
    /// as densely as its rear.
    ///
    /// [`ReflectionConfig::range_extent_weight`]: super::types::ReflectionConfig::range_extent_weight
    PointCloudRange,
}

impl Preset {
    /// All presets.
    pub const ALL: [Preset; 13] = [
        Preset::Default,
        Preset::Robustness,
        Preset::Turning,
        Preset::Clutter,
        Preset::ClutterTurning,
        Preset::Extended,
        Preset::ExtendedTurning,
        Preset::ExtendedClutter,
        Preset::ExtendedClutterTurning,
        Preset::Centroid,
        Preset::DenseStatic,
        Preset::PointCloud,
        Preset::PointCloudRange,
    ];

    /// The preset's name (`default`, `robustness`, `turning`, `clutter`, `clutter_turning`,
    /// `extended`, `extended_turning`, `extended_clutter`, `extended_clutter_turning`, `centroid`,
    /// `dense_static`, `point_cloud`, `point_cloud_range`).
    pub fn name(self) -> &'static str {
        match self {
            Preset::Default => "default",
            Preset::Robustness => "robustness",
            Preset::Turning => "turning",
            Preset::Clutter => "clutter",
            Preset::ClutterTurning => "clutter_turning",
            Preset::Extended => "extended",
            Preset::ExtendedTurning => "extended_turning",
            Preset::ExtendedClutter => "extended_clutter",
            Preset::ExtendedClutterTurning => "extended_clutter_turning",
            Preset::Centroid => "centroid",
            Preset::DenseStatic => "dense_static",
            Preset::PointCloud => "point_cloud",
            Preset::PointCloudRange => "point_cloud_range",
        }
    }

    /// The preset called `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// The configuration of this preset.
    pub fn config(self) -> ScenarioConfig {
        match self {
            Preset::Default => ScenarioConfig::default(),
            Preset::Robustness => ScenarioConfig::robustness(),
            Preset::Turning => ScenarioConfig::turning(),
            Preset::Clutter => ScenarioConfig::clutter(),
            Preset::ClutterTurning => ScenarioConfig::clutter_turning(),
            Preset::Extended => ScenarioConfig::extended(Preset::Default),
            Preset::ExtendedTurning => ScenarioConfig::extended(Preset::Turning),
            Preset::ExtendedClutter => ScenarioConfig::extended(Preset::Clutter),
            Preset::ExtendedClutterTurning => ScenarioConfig::extended(Preset::ClutterTurning),
            Preset::Centroid => ScenarioConfig::centroid(),
            Preset::DenseStatic => ScenarioConfig::dense_static(),
            Preset::PointCloud => ScenarioConfig::point_cloud(),
            Preset::PointCloudRange => ScenarioConfig::point_cloud_range(),
        }
    }
}

impl std::fmt::Display for Preset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Preset {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_name(s).ok_or_else(|| {
            let names: Vec<String> = Self::ALL.iter().map(|p| format!("`{}`", p.name())).collect();
            format!("unknown preset `{s}` (expected one of {})", names.join(", "))
        })
    }
}

impl ScenarioConfig {
    /// The ego-turning preset: see [`Preset::Turning`].
    pub fn turning() -> Self {
        let mut config = Self::default();
        config.splits.seed_base = 0x5455_524e_494e;
        config.road.block_length_m = 90.0;
        config.ego.desired_speed_mps = [6.0, 10.0];
        config.ego.start_distance_to_junction_m = [15.0, 40.0];
        config.ego.turn_left_probability = Some(0.45);
        config.ego.turn_right_probability = Some(0.45);
        config
    }

    /// The clutter preset: see [`Preset::Clutter`].
    pub fn clutter() -> Self {
        let mut config = Self::default();
        config.splits.seed_base = 0x434c_5554_5452;
        config.clutter = ClutterConfig::urban();
        config
    }

    /// The ego-turning clutter preset: see [`Preset::ClutterTurning`].
    pub fn clutter_turning() -> Self {
        let mut config = Self::turning();
        config.splits.seed_base = 0x434c_5455_524e;
        config.clutter = ClutterConfig::urban();
        config
    }

    /// The `base` preset's scene with vehicles measured as extended objects
    /// ([`ExtendedObjectConfig::vehicles`]) and a seed base of its own (see
    /// [`Preset::Extended`]). With the same seed, traffic, scan timing and the ego vehicle are
    /// those of `base`; the clutter presets' false detections come from their own stream too.
    pub fn extended(base: Preset) -> Self {
        let mut config = base.config();
        // A seed base per extended preset: "EXT" and the base preset's own seed base.
        config.splits.seed_base = config.splits.seed_base.wrapping_add(0x4558_5400_0000_0000);
        config.extended_objects = ExtendedObjectConfig::vehicles();
        config
    }

    /// The object-list radar preset: see [`Preset::Centroid`].
    pub fn centroid() -> Self {
        let mut config = Self::default();
        config.splits.seed_base = 0x4345_4e54_5244;
        config.radar.report = RadarReport::Centre;
        config
    }

    /// The static-sensor preset: see [`Preset::DenseStatic`].
    pub fn dense_static() -> Self {
        let mut config = Self::default();
        config.splits.seed_base = 0x4453_5441_5449;
        config.sequence.duration_s = 10.0;
        config.sequence.warmup_s = 20.0;
        config.road.block_length_m = 90.0;
        config.ego.placement = EgoPlacement::Roadside;
        config.radar.sensors = vec![RadarMount {
            layout: static_sensor_layout(),
            azimuth_bias_deg: 0.0,
            azimuth_noise_scale: 1.0,
        }];
        // One scan every 65 ± 15 ms.
        config.radar.scan_period_s = 0.065;
        config.radar.phase_jitter_s = 0.0;
        config.radar.scan_jitter_s = 0.0075;
        config.traffic.car_count = DENSE_CAR_COUNT;
        config.traffic.pedestrian_count = DENSE_PEDESTRIAN_COUNT;
        config.traffic.population_radius_m = 85.0;
        config.traffic.despawn_radius_m = 100.0;
        config.clutter = ClutterConfig {
            mean_false_detections_per_scan: 0.3,
            ghost_probability: 0.01,
            ..ClutterConfig::urban()
        };
        config.output = OutputConfig { ego_pose: false, sensor_id: false };
        config
    }

    /// The detection-level preset: see [`Preset::PointCloud`].
    pub fn point_cloud() -> Self {
        let mut config = Self::clutter_turning();
        config.splits.seed_base = 0x504f_494e_5443;
        config.traffic.pedestrian_group_probability = 0.4;
        config.traffic.max_group_size = 3;
        config.traffic.group_spacing_m = [0.6, 1.2];
        // Car points lie on the faces; the wheels carry the micro-Doppler.
        config.car_reflection.interior_probability = 0.0;
        config.car_reflection.micro_doppler_fraction = 0.0;
        config.clutter = ClutterConfig {
            mean_false_detections_per_scan: 3.0,
            ghost_probability: 0.0,
            ..ClutterConfig::urban()
        };
        config.point_cloud = PointCloudConfig::detections();
        config
    }

    /// The range-resolving detection-level preset: see [`Preset::PointCloudRange`].
    pub fn point_cloud_range() -> Self {
        let mut config = Self::point_cloud();
        config.splits.seed_base = 0x5043_5241_4e47;
        config.car_reflection.range_extent_weight = 3.0;
        config
    }

    /// The robustness preset: see [`Preset::Robustness`].
    pub fn robustness() -> Self {
        let mut config = Self::default();
        config.splits.seed_base = 0x524f_4255_5354;
        config.road.block_length_m = 90.0;
        config.road.signal_green_s = 12.0;
        config.traffic.car_count = 20;
        config.traffic.pedestrian_count = 24;
        config.traffic.pedestrian_group_probability = 0.4;
        config.ego.desired_speed_mps = [10.0, 16.0];
        robust_cars(&mut config.car);
        robust_pedestrians(&mut config.pedestrian);
        robust_sensors(&mut config);
        config
    }
}

/// Cars kept around the sensor of [`Preset::DenseStatic`].
const DENSE_CAR_COUNT: u32 = 80;
/// Pedestrians kept around the sensor of [`Preset::DenseStatic`].
const DENSE_PEDESTRIAN_COUNT: u32 = 110;

/// The one sensor of [`Preset::DenseStatic`]: at the platform's reference point, looking along
/// its x axis, ±60° and 100 m.
fn static_sensor_layout() -> SensorMount {
    super::mount::layout_in_degrees(0, 0.0, 0.0, 0.0, 60.0, 100.0)
}

/// The faster and more aggressive cars of [`Preset::Robustness`].
fn robust_cars(car: &mut CarConfig) {
    car.desired_speed_mps = [11.0, 19.5];
    car.limits.max_speed_mps = 22.0;
    car.limits.max_acceleration_mps2 = 3.5;
    car.limits.max_deceleration_mps2 = 8.0;
    car.limits.max_jerk_mps3 = 9.0;
    car.limits.max_yaw_rate_radps = 0.8;
    car.limits.max_yaw_acceleration_radps2 = 1.6;
    car.limits.max_lateral_acceleration_mps2 = Some(4.5);
    car.comfortable_acceleration_mps2 = 2.4;
    car.comfortable_deceleration_mps2 = 3.5;
    car.curve_lateral_acceleration_mps2 = 3.5;
    car.time_headway_s = 0.9;
    car.turn_left_probability = 0.25;
    car.turn_right_probability = 0.3;
    car.lane_change_probability = 0.7;
    car.lane_change_duration_s = 2.5;
    car.speed_change_interval_s = [2.0, 6.0];
}

/// The faster and more erratic pedestrians of [`Preset::Robustness`].
fn robust_pedestrians(ped: &mut PedestrianConfig) {
    ped.desired_speed_mps = [1.0, 2.0];
    ped.hurry_probability = 0.25;
    ped.hurry_speed_mps = [2.2, 3.4];
    ped.limits.max_speed_mps = 3.5;
    ped.limits.max_acceleration_mps2 = 2.5;
    ped.limits.max_deceleration_mps2 = 3.0;
    ped.limits.max_jerk_mps3 = 10.0;
    ped.limits.max_yaw_rate_radps = 3.5;
    ped.limits.max_yaw_acceleration_radps2 = 12.0;
    ped.heading_wander_rad = 0.25;
    ped.heading_wander_time_s = 1.0;
    ped.leg_length_m = [3.0, 15.0];
    ped.stop_probability = 0.25;
    ped.stop_duration_s = [0.5, 4.0];
    ped.turn_around_probability = 0.25;
    ped.mid_block_crossing_probability = 0.3;
}

/// The noisier sensors, stronger RCS fluctuation and false detections of
/// [`Preset::Robustness`].
fn robust_sensors(config: &mut ScenarioConfig) {
    let radar = &mut config.radar;
    radar.phase_jitter_s = 0.003;
    radar.scan_jitter_s = 0.004;
    radar.range_noise_m = 0.25;
    radar.azimuth_noise_deg = 1.2;
    radar.doppler_noise_mps = 0.2;
    radar.scan_doppler_bias_mps = 0.08;
    radar.miss_probability = 0.08;
    radar.occluded_point_probability = 0.1;
    for sensor in &mut radar.sensors {
        sensor.azimuth_bias_deg *= 2.0;
    }
    config.car_reflection.rcs_fluctuation_db = 6.0;
    config.pedestrian_reflection.rcs_fluctuation_db = 5.0;
    config.pedestrian_reflection.micro_doppler_fraction = 0.5;
    config.clutter = ClutterConfig {
        mean_false_detections_per_scan: 2.0,
        moving_fraction: 0.2,
        ghost_probability: 0.05,
        ..ClutterConfig::urban()
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_is_valid_and_found_by_its_name() {
        for preset in Preset::ALL {
            preset.config().validate().unwrap_or_else(|error| panic!("{preset}: {error}"));
            assert_eq!(Preset::from_name(preset.name()), Some(preset));
            assert_eq!(preset.name().parse::<Preset>(), Ok(preset));
        }
        let error = "clutter-free".parse::<Preset>().unwrap_err();
        for preset in Preset::ALL {
            assert!(error.contains(&format!("`{}`", preset.name())), "{error}");
        }
    }

    #[test]
    fn every_preset_has_its_own_seed_base() {
        for (i, a) in Preset::ALL.into_iter().enumerate() {
            for b in &Preset::ALL[..i] {
                assert_ne!(a.config().splits.seed_base, b.config().splits.seed_base, "{a} and {b}");
            }
        }
    }

    #[test]
    fn only_the_clutter_robustness_and_dense_static_presets_add_false_detections() {
        for preset in Preset::ALL {
            let clutter = preset.config().clutter;
            let expected = matches!(
                preset,
                Preset::Clutter
                    | Preset::ClutterTurning
                    | Preset::Robustness
                    | Preset::ExtendedClutter
                    | Preset::ExtendedClutterTurning
                    | Preset::DenseStatic
                    | Preset::PointCloud
                    | Preset::PointCloudRange
            );
            assert_eq!(clutter.is_enabled(), expected, "{preset}");
        }
        assert_eq!(ScenarioConfig::default().clutter, ClutterConfig::default());
        let robust = Preset::Robustness.config().clutter.mean_false_detections_per_scan;
        assert!(robust > Preset::Clutter.config().clutter.mean_false_detections_per_scan);
    }

    #[test]
    fn the_extended_presets_are_their_base_presets_with_extended_vehicles() {
        let pairs = [
            (Preset::Extended, Preset::Default),
            (Preset::ExtendedTurning, Preset::Turning),
            (Preset::ExtendedClutter, Preset::Clutter),
            (Preset::ExtendedClutterTurning, Preset::ClutterTurning),
        ];
        for preset in Preset::ALL {
            let extended = pairs.iter().any(|(p, _)| *p == preset);
            assert_eq!(preset.config().extended_objects.enabled, extended, "{preset}");
        }
        for (extended, base) in pairs {
            let mut config = extended.config();
            assert_eq!(config.extended_objects, ExtendedObjectConfig::vehicles());
            assert_ne!(config.splits.seed_base, base.config().splits.seed_base);
            config.extended_objects = ExtendedObjectConfig::default();
            config.splits.seed_base = base.config().splits.seed_base;
            assert_eq!(config, base.config(), "{extended} against {base}");
        }
        assert!((ExtendedObjectConfig::vehicles().mean_detection_count() - 1.25).abs() < 1e-12);
    }

    #[test]
    fn the_centroid_preset_is_the_default_scene_reported_at_the_centres() {
        let mut config = Preset::Centroid.config();
        assert_eq!(config.radar.report, RadarReport::Centre);
        config.radar.report = RadarReport::Echo;
        config.splits.seed_base = ScenarioConfig::default().splits.seed_base;
        assert_eq!(config, ScenarioConfig::default());
        for preset in Preset::ALL {
            let centre = preset.config().radar.report == RadarReport::Centre;
            assert_eq!(centre, preset == Preset::Centroid, "{preset}");
        }
    }

    #[test]
    fn the_point_cloud_preset_is_the_turning_clutter_scene_with_detection_level_radars() {
        let config = Preset::PointCloud.config();
        assert_eq!(config.point_cloud, PointCloudConfig::detections());
        assert!((config.clutter.mean_false_detections_per_scan - 3.0).abs() < 1e-12);
        assert_eq!(config.clutter.ghost_probability, 0.0, "ghosts come from the walls");
        let mut base = config.clone();
        base.point_cloud = PointCloudConfig::default();
        base.clutter = ClutterConfig::urban();
        base.traffic = Preset::ClutterTurning.config().traffic;
        base.car_reflection = Preset::ClutterTurning.config().car_reflection;
        base.splits.seed_base = Preset::ClutterTurning.config().splits.seed_base;
        assert_eq!(base, Preset::ClutterTurning.config());
        let point_clouds = [Preset::PointCloud, Preset::PointCloudRange];
        for preset in Preset::ALL {
            assert_eq!(preset.config().point_cloud.enabled, point_clouds.contains(&preset), "{preset}");
        }
    }

    #[test]
    fn the_range_resolving_point_cloud_preset_differs_only_in_the_faces_weights_and_seeds() {
        let mut config = Preset::PointCloudRange.config();
        assert_eq!(config.car_reflection.range_extent_weight, 3.0);
        assert_eq!(Preset::PointCloud.config().car_reflection.range_extent_weight, 0.0);
        assert_ne!(config.splits.seed_base, Preset::PointCloud.config().splits.seed_base);
        config.car_reflection.range_extent_weight = 0.0;
        config.splits.seed_base = Preset::PointCloud.config().splits.seed_base;
        assert_eq!(config, Preset::PointCloud.config());
    }

    #[test]
    fn only_the_dense_static_preset_stands_still_and_leaves_out_poses_and_sensor_ids() {
        for preset in Preset::ALL {
            let config = preset.config();
            let dense = preset == Preset::DenseStatic;
            assert_eq!(config.ego.placement == EgoPlacement::Roadside, dense, "{preset}");
            assert_eq!(config.output == OutputConfig::default(), !dense, "{preset}");
            assert_eq!(config.radar.sensors.len() == 1, dense, "{preset}");
        }
        let output = Preset::DenseStatic.config().output;
        assert!(!output.ego_pose && !output.sensor_id);
    }
}
