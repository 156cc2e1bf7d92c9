//! The staged association (confirmed tracks first, then tentative ones over what is left) and
//! the likelihood cost find, stage by stage, the same optimum as one dense solve.

use glam::{DMat2, DVec2};
use primm_core::association::assignment::AssignmentSolver;
use primm_core::association::associator::Associator;
use primm_core::association::cost::{association_cost, LikelihoodPrior};
use primm_core::config::{AssociationCost, AssociationStages, Config};
use primm_core::coordinates::CoordinatesConfig;
use primm_core::extent::ExpectedReflection;
use primm_core::imm::{Imm, ImmPrior};
use primm_core::measurement::{Frame, Measurement, ObjectClass};
use primm_core::motion::{ModeModels, PredictContext};
use primm_core::pose::SensorMount;
use primm_core::sensor_noise::{MeasurementSensor, SensorNoise};
use primm_core::track::{Track, TrackStatus};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

struct Scene {
    tracks: Vec<Track>,
    priors: Vec<ImmPrior>,
    frame: Frame,
    accepted: Vec<bool>,
    /// Each measurement's radar: every other one with a polar noise of its own.
    sensors: Vec<MeasurementSensor>,
}

fn measurement(rng: &mut ChaCha8Rng, centre: DVec2, spread: f64, class: ObjectClass) -> Measurement {
    Measurement {
        x_m: centre.x + rng.random_range(-spread..spread),
        y_m: centre.y + rng.random_range(-spread..spread),
        radial_velocity_mps: rng.random_range(-3.0..3.0),
        rcs_dbsm: 0.0,
        class,
        sensor_id: None,
        ground_truth_id: None,
    }
}

/// Crowded spots of tracks (a third of them tentative) and measurements, with priors whose
/// covariances differ from track to track.
fn scene(rng: &mut ChaCha8Rng, config: &Config) -> Scene {
    let imm = Imm::new(&config.imm);
    let spots: Vec<DVec2> = (0..rng.random_range(1..5))
        .map(|_| DVec2::new(rng.random_range(-40.0..40.0), rng.random_range(-40.0..40.0)))
        .collect();
    let spread = rng.random_range(0.5..4.0);
    let class_of = |i: usize| if i.is_multiple_of(3) { ObjectClass::Pedestrian } else { ObjectClass::Car };
    let (track_count, measurement_count) = (rng.random_range(0..30), rng.random_range(0..30));
    let mut scene = Scene {
        tracks: Vec::new(),
        priors: Vec::new(),
        frame: Frame::new(0.05),
        accepted: Vec::new(),
        sensors: Vec::new(),
    };
    for i in 0..track_count {
        let class = class_of(i);
        let first = measurement(rng, spots[i % spots.len()], spread, class);
        let models = ModeModels::from_config(config.classes.get(class));
        let state = imm.initiate(&models, &first);
        let dt_s = rng.random_range(0.01..0.3);
        let mut prior = imm.predict(
            &models,
            &state,
            &PredictContext { dt_s, displacement_m: None, displacement_covariance_m2: None },
        );
        prior.fused.mean = measurement(rng, spots[i % spots.len()], spread, class).position();
        let mut track = Track::new(i as u64, &first, glam::DVec2::ZERO, 0.0, state, 0.5);
        if rng.random_bool(0.65) {
            track.status = if rng.random_bool(0.8) { TrackStatus::Confirmed } else { TrackStatus::Coasting };
        }
        scene.tracks.push(track);
        scene.priors.push(prior);
    }
    for j in 0..measurement_count {
        scene.frame.measurements.push(measurement(
            rng,
            spots[(j * 7) % spots.len()],
            spread,
            class_of(j + 1),
        ));
        scene.accepted.push(rng.random_bool(0.9));
    }
    // A radar at (-50, 0) looking along x with a coarse azimuth: across its line of sight its
    // detections are metres wide at these ranges, so pairs gated out without it get in.
    let mount = SensorMount {
        x_m: -50.0,
        y_m: 0.0,
        yaw_rad: 0.0,
        range_std_m: 0.2,
        azimuth_std_rad: 0.03,
        azimuth_std_max_factor: 2.0,
        reflection: primm_core::sensor::ReflectionModel::Outline,
        detections: Default::default(),
        ..CoordinatesConfig::default().sensors[0]
    };
    let noise = SensorNoise::of(&mount, None);
    scene.sensors = (0..measurement_count)
        .map(|j| match j % 2 {
            0 => MeasurementSensor::unknown(DVec2::ZERO, 0.5),
            _ => MeasurementSensor {
                position_m: mount.position(),
                mounted: true,
                noise_m2: noise.covariance_m2(scene.frame.measurements[j].position() - mount.position()),
                slot: 0,
                reflection_scale: 0.5,
            },
        })
        .collect();
    scene
}

/// The cost of a pair under `config`'s cost, `None` beyond its gate.
fn pair_cost(scene: &Scene, config: &Config, track: usize, measurement: usize) -> Option<f64> {
    let prior = &scene.priors[track].fused;
    let m = &scene.frame.measurements[measurement];
    let section = config.classes.get(m.class);
    match config.association.cost {
        AssociationCost::Paper => {
            let cost = association_cost(
                prior.mean,
                scene.tracks[track].last_radial_velocity_mps,
                m,
                &config.association,
            );
            (cost <= section.paper_gate_m).then_some(cost)
        }
        AssociationCost::Likelihood => {
            let [[xx, xy], [yx, yy]] = section.measurement_noise_covariance_m2;
            let noise = DMat2::from_cols(DVec2::new(xx, yx), DVec2::new(xy, yy))
                + scene.sensors[measurement].noise_m2;
            // Computed here from first principles, not through LikelihoodPrior's own arithmetic.
            let s = prior.covariance + noise;
            let nu = m.position() - prior.mean;
            let dv = m.radial_velocity_mps - scene.tracks[track].last_radial_velocity_mps;
            let distance =
                nu.dot(s.inverse() * nu) + (dv / section.likelihood_radial_velocity_std_mps).powi(2);
            // Point objects: the gate in metres has no reflection offset to add.
            let within = distance <= config.association.likelihood_gate_chi2
                && nu.length() <= config.association.likelihood_gate_distance_m;
            within.then(|| distance + s.determinant().ln())
        }
    }
}

/// The dense optimum (pairs, total cost, row → column) of the given rows and columns.
fn dense(
    scene: &Scene,
    config: &Config,
    rows: &[usize],
    columns: &[usize],
) -> (usize, f64, Vec<Option<usize>>) {
    if rows.is_empty() || columns.is_empty() {
        return (0, 0.0, vec![None; rows.len()]);
    }
    let mut costs = vec![f64::INFINITY; rows.len() * columns.len()];
    for (r, &i) in rows.iter().enumerate() {
        for (c, &j) in columns.iter().enumerate() {
            if let Some(cost) = pair_cost(scene, config, i, j) {
                costs[r * columns.len() + c] = cost;
            }
        }
    }
    let mut solver = AssignmentSolver::with_capacity(rows.len(), columns.len());
    let mut row_to_column = vec![None; rows.len()];
    let summary = solver.solve(rows.len(), columns.len(), &costs, &mut row_to_column).unwrap();
    (summary.pairs, summary.total_cost, row_to_column.iter().map(|c| c.map(|c| columns[c])).collect())
}

/// Pairs and total cost of the associator's answer over `rows`.
fn achieved(scene: &Scene, config: &Config, answer: &[Option<u16>], rows: &[usize]) -> (usize, f64) {
    let mut pairs = 0;
    let mut total = 0.0;
    for &i in rows {
        if let Some(j) = answer[i] {
            let j = usize::from(j);
            assert_eq!(scene.frame.measurements[j].class, scene.tracks[i].class, "a pair across classes");
            assert!(scene.accepted[j], "a rejected measurement was assigned");
            total += pair_cost(scene, config, i, j).expect("an assigned pair lies beyond the gate");
            pairs += 1;
        }
    }
    (pairs, total)
}

fn check_optimum(
    label: &str,
    (pairs, total): (usize, f64),
    (reference_pairs, reference_total): (usize, f64),
) {
    assert_eq!(pairs, reference_pairs, "{label}: number of pairs differs from the dense optimum");
    assert!(
        (total - reference_total).abs() <= 1e-9 * reference_total.abs().max(1.0),
        "{label}: total cost {total} differs from the dense optimum {reference_total}"
    );
}

fn run_scenes(config: &Config, seed: u64) -> usize {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut associator = Associator::new();
    let mut tentative_pairs = 0;
    for _ in 0..300 {
        let scene = scene(&mut rng, config);
        let mut answer = vec![Some(u16::MAX); scene.tracks.len()];
        associator
            .associate(
                &scene.tracks,
                &scene.priors,
                &scene.frame,
                &scene.accepted,
                &scene.sensors,
                config,
                &mut answer,
            )
            .unwrap();
        let mut used = vec![false; scene.frame.measurements.len()];
        for j in answer.iter().flatten() {
            assert!(!std::mem::replace(&mut used[usize::from(*j)], true), "a measurement was assigned twice");
        }
        for class in ObjectClass::ALL {
            let of_class = |i: &usize| scene.tracks[*i].class == class;
            let columns: Vec<usize> = (0..scene.frame.measurements.len())
                .filter(|&j| scene.accepted[j] && scene.frame.measurements[j].class == class)
                .collect();
            match config.association.stages {
                AssociationStages::Joint => {
                    let rows: Vec<usize> = (0..scene.tracks.len()).filter(of_class).collect();
                    let reference = dense(&scene, config, &rows, &columns);
                    check_optimum(
                        "joint",
                        achieved(&scene, config, &answer, &rows),
                        (reference.0, reference.1),
                    );
                }
                AssociationStages::ConfirmedFirst => {
                    let confirmed: Vec<usize> = (0..scene.tracks.len())
                        .filter(|i| of_class(i) && scene.tracks[*i].status.is_confirmed())
                        .collect();
                    let first = dense(&scene, config, &confirmed, &columns);
                    check_optimum(
                        "confirmed stage",
                        achieved(&scene, config, &answer, &confirmed),
                        (first.0, first.1),
                    );
                    // The tentative stage sees only what the confirmed stage left.
                    let taken: Vec<usize> =
                        confirmed.iter().filter_map(|&i| answer[i].map(usize::from)).collect();
                    let left: Vec<usize> = columns.iter().copied().filter(|j| !taken.contains(j)).collect();
                    let tentative: Vec<usize> = (0..scene.tracks.len())
                        .filter(|i| of_class(i) && !scene.tracks[*i].status.is_confirmed())
                        .collect();
                    let second = dense(&scene, config, &tentative, &left);
                    let got = achieved(&scene, config, &answer, &tentative);
                    check_optimum("tentative stage", got, (second.0, second.1));
                    tentative_pairs += got.0;
                }
            }
        }
    }
    tentative_pairs
}

#[test]
fn the_confirmed_stage_is_optimal_and_the_tentative_stage_is_optimal_over_what_it_left() {
    let mut config = Config::default().with_point_objects();
    config.association.stages = AssociationStages::ConfirmedFirst;
    let tentative_pairs = run_scenes(&config, 11);
    assert!(tentative_pairs > 100, "the scenes must pair tentative tracks too, got {tentative_pairs}");
    config.association.cost = AssociationCost::Likelihood;
    run_scenes(&config, 12);
}

#[test]
fn the_likelihood_cost_association_matches_a_dense_solve() {
    let mut config = Config::default().with_point_objects();
    config.association.cost = AssociationCost::Likelihood;
    config.association.stages = AssociationStages::Joint;
    run_scenes(&config, 13);
}

#[test]
fn a_tentative_track_cannot_take_the_measurement_a_confirmed_track_needs() {
    // A confirmed track at the origin and a tentative one 0.3 m away; one measurement between
    // them, nearer the tentative track. Jointly the tentative track wins it (lower cost, same
    // number of pairs); in stages the confirmed track keeps it.
    let config = Config::default().with_point_objects();
    let imm = Imm::new(&config.imm);
    let models = ModeModels::from_config(&config.classes.car);
    let context = PredictContext { dt_s: 0.05, displacement_m: None, displacement_covariance_m2: None };
    let mut tracks = Vec::new();
    let mut priors = Vec::new();
    for (id, x, status) in [(1, 20.0, TrackStatus::Confirmed), (2, 20.3, TrackStatus::Tentative)] {
        let first = Measurement { x_m: x, ..common_measurement() };
        let state = imm.initiate(&models, &first);
        let mut prior = imm.predict(&models, &state, &context);
        prior.fused.mean = DVec2::new(x, 0.0);
        let mut track = Track::new(id, &first, glam::DVec2::ZERO, 0.0, state, 0.5);
        track.status = status;
        tracks.push(track);
        priors.push(prior);
    }
    let mut frame = Frame::new(0.05);
    frame.measurements.push(Measurement { x_m: 20.2, ..common_measurement() });
    let accepted = [true];
    let mut associator = Associator::new();
    for (stages, winner) in [(AssociationStages::Joint, 1), (AssociationStages::ConfirmedFirst, 0)] {
        let mut staged = config.clone();
        staged.association.stages = stages;
        let mut answer = [None; 2];
        associator
            .associate(&tracks, &priors, &frame, &accepted, &sensors(&accepted), &staged, &mut answer)
            .unwrap();
        assert_eq!(answer[winner], Some(0), "{stages:?}: {answer:?}");
        assert_eq!(answer[1 - winner], None, "{stages:?}: {answer:?}");
    }
}

fn common_measurement() -> Measurement {
    Measurement {
        x_m: 0.0,
        y_m: 0.0,
        radial_velocity_mps: 2.0,
        rcs_dbsm: 5.0,
        class: ObjectClass::Car,
        sensor_id: None,
        ground_truth_id: None,
    }
}

#[test]
fn the_prepared_likelihood_prior_agrees_with_the_dense_reference_cost() {
    let config = Config::default().with_point_objects();
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    let mut likelihood = config.clone();
    likelihood.association.cost = AssociationCost::Likelihood;
    // The prepared prior holds the χ² gate; the gate in metres is the associator's.
    likelihood.association.likelihood_gate_distance_m = f64::INFINITY;
    for _ in 0..50 {
        let scene = scene(&mut rng, &config);
        for (i, track) in scene.tracks.iter().enumerate() {
            let section = config.classes.get(track.class);
            let [[xx, xy], [yx, yy]] = section.measurement_noise_covariance_m2;
            let prepared = LikelihoodPrior::new(
                &scene.priors[i].fused,
                DMat2::from_cols(DVec2::new(xx, yx), DVec2::new(xy, yy)),
                track.last_radial_velocity_mps,
                section.likelihood_radial_velocity_std_mps,
                likelihood.association.likelihood_gate_chi2,
            )
            .unwrap();
            for (j, m) in scene.frame.measurements.iter().enumerate().filter(|(_, m)| m.class == track.class)
            {
                let reference = pair_cost(&scene, &likelihood, i, j);
                // The radar's own noise spreads the pair's innovation as a reflection's would.
                let cost = match scene.sensors[j].noise_m2 == DMat2::ZERO {
                    true => prepared.cost(m),
                    false => prepared.cost_of_reflection(
                        m,
                        &ExpectedReflection {
                            offset_m: DVec2::ZERO,
                            covariance_m2: scene.sensors[j].noise_m2,
                        },
                    ),
                };
                match (cost, reference) {
                    (Some(a), Some(b)) => assert!((a - b).abs() < 1e-9 * b.abs().max(1.0), "{a} vs {b}"),
                    (None, None) => {}
                    other => panic!("gate disagrees: {other:?}"),
                }
            }
        }
    }
}

/// Sensors at the reference point, without mounts (the costs here treat every class as a point).
fn sensors(accepted: &[bool]) -> Vec<MeasurementSensor> {
    vec![MeasurementSensor::unknown(glam::DVec2::ZERO, 0.5); accepted.len()]
}
