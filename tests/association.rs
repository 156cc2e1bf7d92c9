//! The sparse, cluster-by-cluster association finds the same optimum as one dense solve per
//! class.

use glam::DVec2;
use primm_core::association::assignment::AssignmentSolver;
use primm_core::association::associator::Associator;
use primm_core::association::cost::association_cost;
use primm_core::config::Config;
use primm_core::imm::{Imm, ImmPrior};
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::motion::{ModeModels, PredictContext};
use primm_core::sensor_noise::MeasurementSensor;
use primm_core::track::Track;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

struct Scene {
    tracks: Vec<Track>,
    priors: Vec<ImmPrior>,
    frame: Frame,
    accepted: Vec<bool>,
}

fn measurement(rng: &mut ChaCha8Rng, centre: DVec2, spread: f64, class: ObjectClass) -> Measurement {
    Measurement {
        x_m: centre.x + rng.random_range(-spread..spread),
        y_m: centre.y + rng.random_range(-spread..spread),
        radial_velocity_mps: rng.random_range(-15.0..15.0),
        rcs_dbsm: 0.0,
        class,
        sensor_id: None,
        ground_truth_id: None,
    }
}

/// Tracks and measurements in a few crowded spots, so that clusters of several tracks and
/// measurements form, plus scattered ones; some measurements are marked as rejected.
fn scene(rng: &mut ChaCha8Rng, config: &Config) -> Scene {
    let imm = Imm::new(&config.imm);
    let spots: Vec<DVec2> = (0..rng.random_range(1..6))
        .map(|_| DVec2::new(rng.random_range(-60.0..60.0), rng.random_range(-60.0..60.0)))
        .collect();
    let spread = rng.random_range(1.0..12.0);
    let class_of = |i: usize| if i.is_multiple_of(3) { ObjectClass::Pedestrian } else { ObjectClass::Car };
    let (track_count, measurement_count) = (rng.random_range(0..40), rng.random_range(0..40));
    let mut tracks = Vec::new();
    let mut priors = Vec::new();
    for i in 0..track_count {
        let class = class_of(i);
        let first = measurement(rng, spots[i % spots.len()], spread, class);
        let models = ModeModels::from_config(config.classes.get(class));
        let state = imm.initiate(&models, &first);
        let mut prior = imm.predict(
            &models,
            &state,
            &PredictContext { dt_s: 0.05, displacement_m: None, displacement_covariance_m2: None },
        );
        prior.fused.mean = measurement(rng, spots[i % spots.len()], spread, class).position();
        tracks.push(Track::new(i as u64, &first, glam::DVec2::ZERO, 0.0, state, 0.5));
        priors.push(prior);
    }
    let mut frame = Frame::new(0.05);
    let mut accepted = Vec::new();
    for j in 0..measurement_count {
        frame.measurements.push(measurement(rng, spots[(j * 7) % spots.len()], spread, class_of(j + 1)));
        accepted.push(rng.random_bool(0.9));
    }
    Scene { tracks, priors, frame, accepted }
}

/// Number of pairs and total cost of an assignment.
fn score(
    scene: &Scene,
    config: &Config,
    track_to_measurement: &[Option<u16>],
    class: ObjectClass,
) -> (usize, f64) {
    let mut pairs = 0;
    let mut total = 0.0;
    for (i, assigned) in track_to_measurement.iter().enumerate() {
        let Some(j) = assigned else { continue };
        let track = &scene.tracks[i];
        if track.class != class {
            continue;
        }
        let measurement = scene.frame.measurements[usize::from(*j)];
        assert_eq!(measurement.class, track.class, "a track got a measurement of another class");
        assert!(scene.accepted[usize::from(*j)], "a rejected measurement was assigned");
        let cost = association_cost(
            scene.priors[i].fused.mean,
            track.last_radial_velocity_mps,
            &measurement,
            &config.association,
        );
        assert!(cost <= config.classes.get(class).paper_gate_m, "an assigned pair lies outside the gate");
        pairs += 1;
        total += cost;
    }
    (pairs, total)
}

/// The reference: one dense gated matrix per class, solved at once.
fn dense_optimum(scene: &Scene, config: &Config, class: ObjectClass) -> (usize, f64) {
    let rows: Vec<usize> = (0..scene.tracks.len()).filter(|&i| scene.tracks[i].class == class).collect();
    let columns: Vec<usize> = (0..scene.frame.measurements.len())
        .filter(|&j| scene.accepted[j] && scene.frame.measurements[j].class == class)
        .collect();
    if rows.is_empty() || columns.is_empty() {
        return (0, 0.0);
    }
    let gate = config.classes.get(class).paper_gate_m;
    let mut costs = vec![f64::INFINITY; rows.len() * columns.len()];
    for (r, &i) in rows.iter().enumerate() {
        for (c, &j) in columns.iter().enumerate() {
            let cost = association_cost(
                scene.priors[i].fused.mean,
                scene.tracks[i].last_radial_velocity_mps,
                &scene.frame.measurements[j],
                &config.association,
            );
            if cost <= gate {
                costs[r * columns.len() + c] = cost;
            }
        }
    }
    let mut solver = AssignmentSolver::with_capacity(rows.len(), columns.len());
    let mut row_to_column = vec![None; rows.len()];
    let summary = solver.solve(rows.len(), columns.len(), &costs, &mut row_to_column).unwrap();
    (summary.pairs, summary.total_cost)
}

#[test]
fn clustered_association_matches_a_dense_solve_per_class_on_random_scenes() {
    // The paper's cost in one stage (tests/staged_association.rs covers the other settings).
    let mut config = Config::default().with_point_objects();
    config.association.cost = primm_core::config::AssociationCost::Paper;
    config.association.stages = primm_core::config::AssociationStages::Joint;
    let mut rng = ChaCha8Rng::seed_from_u64(2024);
    let mut associator = Associator::new();
    let mut solved_clusters = 0;
    for _ in 0..400 {
        let scene = scene(&mut rng, &config);
        let mut track_to_measurement = vec![Some(u16::MAX); scene.tracks.len()];
        associator
            .associate(
                &scene.tracks,
                &scene.priors,
                &scene.frame,
                &scene.accepted,
                &vec![MeasurementSensor::unknown(glam::DVec2::ZERO, 0.5); scene.accepted.len()],
                &config,
                &mut track_to_measurement,
            )
            .unwrap();
        let mut used = vec![false; scene.frame.measurements.len()];
        for j in track_to_measurement.iter().flatten() {
            assert!(!std::mem::replace(&mut used[usize::from(*j)], true), "a measurement was assigned twice");
        }
        for class in ObjectClass::ALL {
            let (pairs, total) = score(&scene, &config, &track_to_measurement, class);
            let (reference_pairs, reference_total) = dense_optimum(&scene, &config, class);
            assert_eq!(pairs, reference_pairs, "{class:?}: number of pairs differs from the dense optimum");
            assert!(
                (total - reference_total).abs() <= 1e-9 * reference_total.max(1.0),
                "{class:?}: total cost {total} differs from the dense optimum {reference_total}"
            );
        }
        solved_clusters += associator.stats().solved_clusters;
    }
    // The scenes must exercise the solver path, not only lone pairs.
    assert!(solved_clusters > 100, "only {solved_clusters} clusters needed the solver");
}

#[test]
fn tracks_far_apart_are_paired_without_the_solver() {
    let config = Config::default().with_point_objects();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let imm = Imm::new(&config.imm);
    let models = ModeModels::from_config(&config.classes.car);
    let mut tracks = Vec::new();
    let mut priors = Vec::new();
    let mut frame = Frame::new(0.05);
    for i in 0..50 {
        let position = DVec2::new(-500.0 + 20.0 * i as f64, 3.0);
        let mut first = measurement(&mut rng, position, 0.1, ObjectClass::Car);
        first.radial_velocity_mps = 1.0;
        let state = imm.initiate(&models, &first);
        let mut prior = imm.predict(
            &models,
            &state,
            &PredictContext { dt_s: 0.05, displacement_m: None, displacement_covariance_m2: None },
        );
        prior.fused.mean = position;
        tracks.push(Track::new(i, &first, glam::DVec2::ZERO, 0.0, state, 0.5));
        priors.push(prior);
        frame.measurements.push(Measurement {
            radial_velocity_mps: 1.0,
            ..measurement(&mut rng, position, 0.5, ObjectClass::Car)
        });
    }
    // Reverse the measurement order so that index order does not line up with track order.
    frame.measurements.reverse();
    let accepted = vec![true; 50];
    let mut associator = Associator::new();
    let mut track_to_measurement = vec![None; 50];
    let sensors = vec![MeasurementSensor::unknown(glam::DVec2::ZERO, 0.5); accepted.len()];
    associator
        .associate(&tracks, &priors, &frame, &accepted, &sensors, &config, &mut track_to_measurement)
        .unwrap();
    for (i, assigned) in track_to_measurement.iter().enumerate() {
        assert_eq!(*assigned, Some(49 - i as u16), "track {i}");
    }
    assert_eq!(associator.stats().single_pairs, 50);
    assert_eq!(associator.stats().solved_clusters, 0);
    assert_eq!(associator.stats().allowed_pairs, 50);
}

#[test]
fn each_assigned_car_gets_the_reflection_of_its_measurements_sensor_exactly_as_the_model_computes_it() {
    use primm_core::config::AssociationCost;
    use primm_core::extent::expected_reflection;
    for cost in [AssociationCost::Likelihood, AssociationCost::Paper] {
        let mut config = Config::default();
        config.association.cost = cost;
        assert!(config.classes.car.extent.enabled && !config.classes.pedestrian.extent.enabled);
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut associator = Associator::new();
        let (mut cars, mut pedestrians) = (0, 0);
        for _ in 0..40 {
            let scene = scene(&mut rng, &config);
            // Six radar positions, so that a track's memo (four) overflows now and then.
            let radars: Vec<DVec2> =
                (0..6).map(|k| DVec2::new(3.0 * k as f64 - 6.0, [0.9, -0.9][k % 2])).collect();
            let sensors: Vec<MeasurementSensor> = (0..scene.accepted.len())
                .map(|_| MeasurementSensor {
                    position_m: radars[rng.random_range(0..radars.len())],
                    mounted: true,
                    noise_m2: glam::DMat2::ZERO,
                    slot: 0,
                    reflection_scale: config.classes.car.extent.offset_scale,
                })
                .collect();
            let mut track_to_measurement = vec![None; scene.tracks.len()];
            associator
                .associate(
                    &scene.tracks,
                    &scene.priors,
                    &scene.frame,
                    &scene.accepted,
                    &sensors,
                    &config,
                    &mut track_to_measurement,
                )
                .unwrap();
            for (i, assigned) in track_to_measurement.iter().enumerate() {
                let shared = associator.assigned_reflection(i);
                let Some(index) = assigned else {
                    assert_eq!(shared, None, "an unassigned track has none");
                    continue;
                };
                if scene.tracks[i].class == ObjectClass::Pedestrian {
                    assert_eq!(shared, None, "pedestrians are points");
                    pedestrians += 1;
                    continue;
                }
                let expected = expected_reflection(
                    &config.classes.car.extent,
                    &scene.priors[i].object_prior(),
                    sensors[usize::from(*index)].position_m,
                    sensors[usize::from(*index)].reflection_scale,
                );
                // The memo may not hold it (more sensors than it keeps); if it does, exactly.
                if let Some(shared) = shared {
                    assert_eq!(shared, expected, "track {i}");
                    cars += 1;
                }
            }
        }
        assert!(cars > 100 && pedestrians > 20, "{cost:?}: {cars} cars, {pedestrians} pedestrians checked");
    }
}
