//! Per-class IMM overrides (`classes.<class>.imm`): a class's transition matrix and initial mode
//! probabilities reach that class's tracks only, a bad override is refused with its key, a
//! configuration without overrides (or with overrides equal to `imm`) tracks exactly as before,
//! the shipped overrides leave the physics modes' switching (the `imm` method) as `imm` has it, and
//! the `compensated_*` keys govern the steps with an ego pose, and only those.

use crate::common::{invalid_key, scene_frames, SceneObject};
use primm_core::config::{Config, ConfigError, ImmConfig};
use primm_core::imm::Imm;
use primm_core::measurement::ObjectClass;
use primm_core::track::TrackOutput;
use primm_core::tracker::Tracker;

/// Three cars and three pedestrians, each class in its own region 200 m from the other, so that
/// no track of one class ever meets a measurement of the other.
fn scene() -> Vec<SceneObject> {
    (0..6)
        .map(|i| {
            let car = i < 3;
            SceneObject {
                id: i as u64 + 1,
                class: if car { ObjectClass::Car } else { ObjectClass::Pedestrian },
                start: [10.0 + 3.0 * i as f64, if car { -100.0 } else { 100.0 } + 20.0 * (i % 3) as f64],
                velocity: if car { [9.0, 1.0] } else { [1.3, -0.2] },
                visible: (0.0, f64::INFINITY),
            }
        })
        .collect()
}

/// The shipped configuration without its per-class overrides.
fn without_overrides() -> Config {
    let mut config = Config::default();
    for class in ObjectClass::ALL {
        config.classes.get_mut(class).imm = Default::default();
    }
    config
}

/// Every frame's outputs of a tracker with `config` on the scene.
fn outputs(config: Config) -> Vec<Vec<TrackOutput>> {
    let mut tracker = Tracker::new(config).unwrap();
    scene_frames(&scene(), 60, 0.05, 0.2, 11)
        .iter()
        .map(|frame| tracker.step(frame).unwrap().to_vec())
        .collect()
}

/// The outputs of one class, as text (equal exactly when every bit agrees).
fn of_class(outputs: &[Vec<TrackOutput>], class: ObjectClass) -> String {
    format!(
        "{:?}",
        outputs
            .iter()
            .map(|frame| frame.iter().filter(|o| o.class == class).collect::<Vec<_>>())
            .collect::<Vec<_>>()
    )
}

/// A transition matrix in which PR is left quickly and rarely entered.
fn leaky_pr(config: &Config) -> [[f64; 4]; 4] {
    let mut transition = config.imm.transition;
    transition[0] = [0.7, 0.1, 0.1, 0.1];
    for row in transition.iter_mut().skip(1) {
        row[0] = 0.0;
        row[1..].iter_mut().for_each(|p| *p /= 0.99);
        let sum: f64 = row.iter().sum();
        row[1] += 1.0 - sum;
    }
    transition
}

#[test]
fn an_override_reaches_its_class_only() {
    let default = outputs(without_overrides());
    let mut config = without_overrides();
    config.classes.car.imm.initial_mode_probabilities = Some([0.4, 0.2, 0.2, 0.2]);
    config.classes.car.imm.transition = Some(leaky_pr(&config));
    let overridden = outputs(config.clone());

    // A new car track starts with the car's initial probabilities, a pedestrian with imm's.
    let first = &overridden[0];
    let car = first.iter().find(|o| o.class == ObjectClass::Car).unwrap();
    let pedestrian = first.iter().find(|o| o.class == ObjectClass::Pedestrian).unwrap();
    assert_eq!(car.mode_probabilities, [0.4, 0.2, 0.2, 0.2]);
    let expected = Imm::new(&without_overrides().imm).initiate(
        &primm_core::motion::ModeModels::from_config(&config.classes.pedestrian),
        &crate::common::measurement(1.0, 2.0, 0.0),
    );
    assert_eq!(pedestrian.mode_probabilities, expected.probabilities);

    // Pedestrians track bit for bit as without the override; cars do not.
    assert_eq!(of_class(&overridden, ObjectClass::Pedestrian), of_class(&default, ObjectClass::Pedestrian));
    assert_ne!(of_class(&overridden, ObjectClass::Car), of_class(&default, ObjectClass::Car));
    // PR (which never gets a displacement here and sits every step out) keeps far less weight.
    let last_car = overridden.last().unwrap().iter().find(|o| o.class == ObjectClass::Car).unwrap();
    let last_car_default = default.last().unwrap().iter().find(|o| o.class == ObjectClass::Car).unwrap();
    assert!(
        last_car.mode_probabilities[0] < 0.5 * last_car_default.mode_probabilities[0],
        "PR {} vs {}",
        last_car.mode_probabilities[0],
        last_car_default.mode_probabilities[0]
    );
}

#[test]
fn overrides_equal_to_imm_or_absent_change_nothing() {
    let default = outputs(without_overrides());
    let mut config = without_overrides();
    for class in ObjectClass::ALL {
        let imm = config.imm.clone();
        let section = &mut config.classes.get_mut(class).imm;
        section.transition = Some(imm.transition);
        section.initial_mode_probabilities = Some(imm.initial_mode_probabilities);
    }
    assert_eq!(format!("{:?}", outputs(config)), format!("{default:?}"));
    // The shipped file reads back as the defaults, overrides included.
    let shipped = primm_config::from_toml_str(primm_config::DEFAULT_CONFIG_TOML).unwrap();
    assert_eq!(shipped, Config::default());
}

#[test]
fn the_shipped_overrides_change_pr_only_and_leave_the_imm_method_as_it_was() {
    let shipped = Config::default();
    let mut changed = 0;
    for class in ObjectClass::ALL {
        let overridden = shipped.imm_for(class);
        changed += usize::from(overridden != shipped.imm);
        // Without PR (the `imm` method) the renormalised switching of the physics modes and
        // their initial probabilities are those of `imm`.
        let imm_method = primm_core::mode::Method::Imm.modes();
        let with_class = Imm::new(&ImmConfig { modes: imm_method, ..overridden.clone() });
        let without = Imm::new(&ImmConfig { modes: imm_method, ..shipped.imm.clone() });
        for (row, row_without) in with_class.transition().iter().zip(without.transition()) {
            for (p, q) in row.iter().zip(row_without) {
                assert!((p - q).abs() < 1e-6, "{class:?}: {p} vs {q}");
            }
        }
        let models = primm_core::motion::ModeModels::from_config(shipped.classes.get(class));
        let z = crate::common::measurement(1.0, 2.0, 0.0);
        let (a, b) =
            (with_class.initiate(&models, &z).probabilities, without.initiate(&models, &z).probabilities);
        for (p, q) in a.iter().zip(b.iter()) {
            assert!((p - q).abs() < 1e-6, "{class:?}: {a:?} vs {b:?}");
        }
        // With PR, the class's own settings are used.
        let full = Imm::new(&overridden);
        for (row, row_class) in full.transition().iter().zip(&overridden.transition) {
            for (p, q) in row.iter().zip(row_class) {
                assert!((p - q).abs() < 1e-9, "{class:?}: {p} vs {q}");
            }
        }
    }
    assert_eq!(changed, 2, "cars and pedestrians carry overrides, two-wheelers none");
}

#[test]
fn a_bad_override_is_refused_naming_its_key() {
    let mut config = Config::default();
    let mut transition = config.imm.transition;
    transition[2] = [0.1, 0.1, 0.7, 0.2];
    config.classes.car.imm.transition = Some(transition);
    assert_eq!(invalid_key(Tracker::new(config)), "classes.car.imm.transition[2]");

    let mut config = Config::default();
    config.classes.pedestrian.imm.initial_mode_probabilities = Some([0.1, 1.5, 0.0, 0.0]);
    assert_eq!(invalid_key(Tracker::new(config)), "classes.pedestrian.imm.initial_mode_probabilities[1]");

    // No mass on the active modes: PR only, with the override putting none on it.
    let mut config = Config::default().with_modes(primm_core::mode::Method::Learned.modes());
    config.classes.two_wheeler.imm.initial_mode_probabilities = Some([0.0, 0.5, 0.5, 0.0]);
    assert_eq!(invalid_key(Tracker::new(config)), "classes.two_wheeler.imm.initial_mode_probabilities");

    // From TOML: an unknown key of the section is refused, a good section read.
    let text = primm_config::DEFAULT_CONFIG_TOML;
    let with = |section: &str| format!("{text}\n{section}\n");
    // (two-wheelers: the shipped file has no section of theirs to collide with)
    assert!(primm_config::from_toml_str(&with("[classes.two_wheeler.imm]\npr_leave = 0.1")).is_err());
    let read = primm_config::from_toml_str(&with(
        "[classes.two_wheeler.imm]\ninitial_mode_probabilities = [0.4, 0.2, 0.2, 0.2]",
    ))
    .unwrap();
    assert_eq!(read.classes.two_wheeler.imm.initial_mode_probabilities, Some([0.4, 0.2, 0.2, 0.2]));
    assert_eq!(read.classes.two_wheeler.imm.transition, None);
    match primm_config::from_toml_str(&with("[classes.two_wheeler.imm]\ntransition = [[0.5, 0.5, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.3, 0.0, 0.0, 0.6]]")) {
        Err(primm_config::ConfigError::Invalid(ConfigError::Invalid { key, .. })) => {
            assert_eq!(key, "classes.two_wheeler.imm.transition[3]")
        }
        other => panic!("expected an invalid key, got {other:?}"),
    }
}

#[test]
fn the_compensated_keys_govern_the_steps_with_an_ego_pose_and_only_those() {
    // Cars: CA never entered nor started in steps whose ego motion is compensated.
    let mut config = without_overrides();
    let mut without_ca = config.imm.transition;
    for (i, row) in without_ca.iter_mut().enumerate() {
        if i != 2 {
            row[1] += row[2];
            row[2] = 0.0;
        }
    }
    config.classes.car.imm.compensated_transition = Some(without_ca);
    config.classes.car.imm.compensated_initial_mode_probabilities = Some([0.1, 0.45, 0.0, 0.45]);
    let frames = scene_frames(&scene(), 60, 0.05, 0.2, 11);
    let posed: Vec<_> = frames
        .iter()
        .cloned()
        .map(|mut frame| {
            frame.ego_pose = Some(primm_core::pose::EgoPose { x_m: 0.0, y_m: 0.0, yaw_rad: 0.0 });
            frame
        })
        .collect();
    let run = |config: &Config, frames: &[primm_core::measurement::Frame]| {
        let mut tracker = Tracker::new(config.clone()).unwrap();
        frames.iter().map(|frame| tracker.step(frame).unwrap().to_vec()).collect::<Vec<_>>()
    };
    // Without poses (and sensors that may move: vehicle-frame steps) the keys change nothing.
    let moving = |config: &Config| {
        let mut config = config.clone();
        config.frame.platform = primm_core::sensor::platform::PlatformModel::Moving;
        config
    };
    assert_eq!(
        format!("{:?}", run(&moving(&config), &frames)),
        format!("{:?}", run(&moving(&without_overrides()), &frames))
    );
    // With poses they reach the cars only: CA stays at the floor, from the first step on.
    let (with_keys, without_keys) = (run(&config, &posed), run(&without_overrides(), &posed));
    assert_eq!(
        of_class(&with_keys, ObjectClass::Pedestrian),
        of_class(&without_keys, ObjectClass::Pedestrian)
    );
    let floor = config.imm.mode_probability_floor;
    let ca = |outputs: &[Vec<TrackOutput>]| {
        outputs
            .iter()
            .flatten()
            .filter(|o| o.class == ObjectClass::Car)
            .map(|o| o.mode_probabilities[2])
            .fold(0.0f64, f64::max)
    };
    assert!(ca(&with_keys) < 1.01 * floor, "CA {} with the keys", ca(&with_keys));
    assert!(ca(&without_keys) > 0.1, "CA {} without them", ca(&without_keys));
}

#[test]
fn a_bad_compensated_key_is_refused_naming_it() {
    let mut config = Config::default();
    let mut transition = config.imm.transition;
    transition[1] = [0.0, 0.5, 0.0, 0.0];
    config.classes.pedestrian.imm.compensated_transition = Some(transition);
    assert_eq!(invalid_key(Tracker::new(config)), "classes.pedestrian.imm.compensated_transition[1]");
    let mut config = Config::default();
    config.classes.car.imm.compensated_initial_mode_probabilities = Some([0.1, -0.5, 0.0, 0.0]);
    assert_eq!(
        invalid_key(Tracker::new(config)),
        "classes.car.imm.compensated_initial_mode_probabilities[1]"
    );
}
