//! The radar layout is written down three times: in the tracker's configuration file
//! (`config/primm.toml`, `frame.sensors`), in the tracker core's default frame configuration,
//! and in the scenario generator's default radars, which produce the data the tracker is tuned
//! and evaluated on. All three must describe the same sensors, with the same type for a mount.

use primm_core::coordinates::CoordinatesConfig;
use primm_core::pose::SensorMount;
use primm_sim::scenario::Preset;

/// Largest difference allowed between two angles, positions or ranges written in different
/// ways (a decimal in a file, a conversion from degrees in code).
const TOLERANCE: f64 = 1e-12;

/// The geometry of a mount: what the three layouts must agree on.
fn geometry(mount: &SensorMount) -> [f64; 5] {
    [mount.x_m, mount.y_m, mount.yaw_rad, mount.half_fov_rad, mount.max_range_m]
}

/// Asserts that `layout` mounts the sensors of `expected`, in the same order.
fn assert_same_radars(name: &str, layout: &[SensorMount], expected: &[SensorMount]) {
    let ids = |mounts: &[SensorMount]| mounts.iter().map(|mount| mount.id).collect::<Vec<_>>();
    assert_eq!(ids(layout), ids(expected), "{name}: sensor ids");
    for (mount, reference) in layout.iter().zip(expected) {
        let differences = geometry(mount).into_iter().zip(geometry(reference));
        for (field, (value, wanted)) in
            ["x_m", "y_m", "yaw_rad", "half_fov_rad", "max_range_m"].iter().zip(differences)
        {
            assert!(
                (value - wanted).abs() <= TOLERANCE,
                "{name}: sensor {} {field} is {value}, expected {wanted}",
                mount.id
            );
        }
    }
}

#[test]
fn the_config_file_the_core_default_and_the_generator_mount_the_same_radars() {
    let file =
        primm_config::from_toml_str(primm_config::DEFAULT_CONFIG_TOML).expect("the default configuration");
    let core = CoordinatesConfig::default().sensors;
    let generator = Preset::Default.config().radar.sensor_layout();
    assert!(!generator.is_empty(), "the generator mounts radars");
    assert_same_radars("config/primm.toml", &file.frame.sensors, &generator);
    assert_same_radars("CoordinatesConfig::default", &core, &generator);
}

#[test]
fn every_preset_with_sensor_ids_mounts_the_default_radars() {
    let reference = Preset::Default.config().radar.sensor_layout();
    // A preset without sensor ids (a static sensor) gives the tracker no mount to look up.
    for preset in Preset::ALL.into_iter().filter(|preset| preset.config().output.sensor_id) {
        assert_same_radars(preset.name(), &preset.config().radar.sensor_layout(), &reference);
    }
}
