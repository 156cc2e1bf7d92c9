//! The per-track loops of `primm_core::track_loops` (compiled for baseline x86-64 and for AVX2 +
//! FMA, chosen at run time) compute exactly what the baseline build of the same loops and the
//! plain IMM calls compute, bit for bit, on tracks taken from a running tracker.
//!
//! The test names the two versions it compared and refuses to compare a version with itself:
//! on a CPU with AVX, AVX2 and FMA the dispatch must have picked the wide version, and the
//! baseline reference must not have been compiled with AVX2 (as `-C target-cpu=native` would).
//! On a CPU without them only the baseline can run: there is no second version to compare, the
//! test checks that the dispatch picked the baseline, says so and stops. That is not a gap in
//! what ships: on such a CPU the program runs the baseline too, which is the reference here.

use crate::common;

use common::{lanes, measurement, scene_frames};
use glam::DVec2;
use primm_core::config::Config;
use primm_core::extent::ExpectedReflection;
use primm_core::gaussian::{RadialVelocityOutcome, UpdateError};
use primm_core::imm::ImmPrior;
use primm_core::measurement::{Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::motion::ModeModels;
use primm_core::predictor::Displacement;
use primm_core::sensor_noise::MeasurementSensor;
use primm_core::track::Track;
use primm_core::track_loops::{self, ClassModels, LoopVersion};
use primm_core::tracker::Tracker;

/// The tracks of a tracker running `method` on 24 lanes after `frames` frames.
fn running_tracks(method: Method, frames: usize) -> (Config, Vec<Track>) {
    let config = Config::default().with_modes(method.modes());
    let mut tracker = Tracker::new(config.clone()).unwrap();
    for frame in scene_frames(&lanes(24), frames, 0.05, 0.2, 7).iter() {
        tracker.step(frame).unwrap();
    }
    (config, tracker.tracks().to_vec())
}

fn models(config: &Config) -> ClassModels {
    ObjectClass::ALL.map(|class| ModeModels::from_config(config.classes.get(class)))
}

/// Every number of `value` as text: Rust prints the shortest decimal that reads back to the same
/// bits, so two values print alike exactly when their bits agree (and `-0.0` differs from `0.0`,
/// which `==` would not tell apart).
fn bits<T: std::fmt::Debug>(value: &T) -> String {
    format!("{value:?}")
}

/// Whether this CPU can run the wide version (AVX, AVX2 and FMA).
fn cpu_runs_the_wide_loops() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        is_x86_feature_detected!("avx") && is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

#[test]
fn dispatched_loops_equal_the_baseline_loops_and_the_plain_imm_calls_bit_for_bit() {
    let selected = track_loops::selected_version();
    assert!(
        !track_loops::baseline_built_with_avx2(),
        "primm-core's baseline was compiled with AVX2: the comparison would compare a build with itself"
    );
    if !cpu_runs_the_wide_loops() {
        assert_eq!(selected, LoopVersion::Baseline, "the dispatch picked a version this CPU cannot run");
        println!(
            "track loops: this CPU lacks AVX/AVX2/FMA, only the baseline runs; no second version to compare"
        );
        return;
    }
    assert_eq!(selected, LoopVersion::Wide, "the CPU has AVX2 but the dispatch picked {selected:?}");
    println!(
        "track loops: compared the dispatched {selected:?} (AVX+AVX2+FMA) version with the Baseline build"
    );
    for method in [Method::Imm, Method::PrImm] {
        let (mut config, tracks) = running_tracks(method, 40);
        assert!(tracks.len() >= 20, "{method}: only {} tracks", tracks.len());
        // The updates below take the radial-velocity row as well, and cars are extended objects.
        for class in ObjectClass::ALL {
            config.classes.get_mut(class).radial_velocity_update.enabled = true;
        }
        config.classes.car.extent.enabled = true;
        let imms = track_loops::class_imms(&config);
        let models = models(&config);
        let dt_s = 0.05;

        let mut dispatched = vec![ImmPrior::default(); tracks.len()];
        track_loops::predict_physics(&imms, &models, &tracks, dt_s, &mut dispatched);
        let mut plain = vec![ImmPrior::default(); tracks.len()];
        for (track, prior) in tracks.iter().zip(plain.iter_mut()) {
            imms[track.class.index()].predict_physics_into(
                &models[track.class.index()],
                &track.estimate,
                dt_s,
                prior,
            );
        }
        assert_eq!(bits(&dispatched), bits(&plain), "{method}: predict_physics");
        let mut baseline = vec![ImmPrior::default(); tracks.len()];
        track_loops::baseline::predict_physics(&imms, &models, &tracks, dt_s, &mut baseline);
        assert_eq!(bits(&dispatched), bits(&baseline), "{method}: predict_physics, wide vs baseline");

        // Every third track without a learned displacement.
        let displacements: Vec<Option<Displacement>> = (0..tracks.len())
            .map(|i| (i % 3 != 0).then(|| DVec2::new(0.4 + 0.01 * i as f64, -0.05).into()))
            .collect();
        track_loops::complete_priors(&imms, &models, &tracks, dt_s, &displacements, &mut dispatched);
        for ((track, prior), displacement) in tracks.iter().zip(plain.iter_mut()).zip(&displacements) {
            imms[track.class.index()].complete_prior_in_place(
                &models[track.class.index()],
                prior,
                dt_s,
                *displacement,
            );
        }
        assert_eq!(bits(&dispatched), bits(&plain), "{method}: complete_priors");
        track_loops::baseline::complete_priors(&imms, &models, &tracks, dt_s, &displacements, &mut baseline);
        assert_eq!(bits(&dispatched), bits(&baseline), "{method}: complete_priors, wide vs baseline");

        // Every fourth track without a measurement; the others measured 0.3 m off their prior.
        let measurements: Vec<Option<Measurement>> = plain
            .iter()
            .enumerate()
            .map(|(i, prior)| {
                (i % 4 != 0).then(|| measurement(prior.fused.mean.x + 0.3, prior.fused.mean.y - 0.2, 1.0))
            })
            .collect();
        let sensor_positions: Vec<DVec2> =
            (0..tracks.len()).map(|i| DVec2::new(3.7, -0.9 + 0.6 * (i % 4) as f64)).collect();
        // Every other measurement with a radar noise of its own.
        let sensors: Vec<MeasurementSensor> = sensor_positions
            .iter()
            .enumerate()
            .map(|(i, &position_m)| MeasurementSensor {
                position_m,
                mounted: true,
                noise_m2: glam::DMat2::from_diagonal(DVec2::new(0.01, 0.2 * (i % 2) as f64)),
                slot: 0,
                reflection_scale: 0.5,
            })
            .collect();
        // The reflections the tracker computes once per frame and hands to the loop.
        let reflections: Vec<ExpectedReflection> = tracks
            .iter()
            .enumerate()
            .map(|(i, track)| {
                models[track.class.index()].expected_reflection(
                    &plain[i].object_prior(),
                    sensor_positions[i],
                    0.5,
                )
            })
            .collect();
        let mut dispatched_tracks = tracks.clone();
        let mut outcomes = vec![Err(UpdateError); tracks.len()];
        track_loops::update(
            &imms,
            &models,
            &mut dispatched_tracks,
            &dispatched,
            &measurements,
            &sensors,
            &reflections,
            true,
            &mut outcomes,
        );
        let mut plain_tracks = tracks.clone();
        for (i, track) in plain_tracks.iter_mut().enumerate() {
            let expected = match measurements[i] {
                Some(z) => {
                    let models = &models[track.class.index()];
                    let reflection =
                        models.expected_reflection(&plain[i].object_prior(), sensor_positions[i], 0.5);
                    let radial_velocity =
                        models.radial_velocity_observation(&z, &sensors[i], reflection.offset_m);
                    assert!(radial_velocity.is_some());
                    assert_eq!(reflection.offset_m == DVec2::ZERO, track.class != ObjectClass::Car);
                    imms[track.class.index()].update_with_radial_velocity_into(
                        models,
                        &plain[i],
                        z.position() - reflection.offset_m,
                        &primm_core::gaussian::to_nalgebra(&(reflection.covariance_m2 + sensors[i].noise_m2)),
                        radial_velocity.as_ref(),
                        &mut track.estimate,
                    )
                }
                None => Ok(None),
            };
            assert_eq!(outcomes[i], expected, "{method}: outcome of track {i}");
        }
        let estimates = |tracks: &[Track]| bits(&tracks.iter().map(|t| t.estimate).collect::<Vec<_>>());
        assert_eq!(estimates(&dispatched_tracks), estimates(&plain_tracks), "{method}: update");
        let mut baseline_tracks = tracks.clone();
        let mut baseline_outcomes = vec![Err(UpdateError); tracks.len()];
        track_loops::baseline::update(
            &imms,
            &models,
            &mut baseline_tracks,
            &baseline,
            &measurements,
            &sensors,
            &reflections,
            true,
            &mut baseline_outcomes,
        );
        assert_eq!(baseline_outcomes, outcomes, "{method}: update outcomes, wide vs baseline");
        assert_eq!(
            estimates(&dispatched_tracks),
            estimates(&baseline_tracks),
            "{method}: update, wide vs baseline"
        );
        assert_ne!(estimates(&dispatched_tracks), estimates(&tracks), "{method}: the update changed nothing");
        assert!(
            outcomes.contains(&Ok(Some(RadialVelocityOutcome::Applied))),
            "{method}: no radial-velocity row was applied"
        );
    }
}
