//! The per-track loops of `primm_core::track_loops` (compiled for baseline x86-64 and for AVX2 +
//! FMA, chosen at run time) compute exactly what the plain IMM calls compute, bit for bit, on
//! tracks taken from a running tracker. On a CPU with AVX2 the dispatched loops run their AVX2
//! version while the reference loops below are compiled for the baseline, so the comparison
//! covers both.

use crate::common;

use common::{lanes, measurement, scene_frames};
use glam::DVec2;
use primm_core::config::Config;
use primm_core::gaussian::UpdateError;
use primm_core::imm::{Imm, ImmPrior};
use primm_core::measurement::{Measurement, ObjectClass};
use primm_core::mode::Method;
use primm_core::motion::ModeModels;
use primm_core::track::Track;
use primm_core::track_loops::{self, ClassModels};
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

#[test]
fn dispatched_loops_equal_the_plain_imm_calls_bit_for_bit() {
    for method in [Method::Imm, Method::PrImm] {
        let (config, tracks) = running_tracks(method, 40);
        assert!(tracks.len() >= 20, "{method}: only {} tracks", tracks.len());
        let imm = Imm::new(&config.imm);
        let models = models(&config);
        let dt_s = 0.05;

        let mut dispatched = vec![ImmPrior::default(); tracks.len()];
        track_loops::predict_physics(&imm, &models, &tracks, dt_s, &mut dispatched);
        let mut plain = vec![ImmPrior::default(); tracks.len()];
        for (track, prior) in tracks.iter().zip(plain.iter_mut()) {
            imm.predict_physics_into(&models[track.class.index()], &track.estimate, dt_s, prior);
        }
        assert_eq!(bits(&dispatched), bits(&plain), "{method}: predict_physics");

        // Every third track without a learned displacement.
        let displacements: Vec<Option<DVec2>> = (0..tracks.len())
            .map(|i| (i % 3 != 0).then(|| DVec2::new(0.4 + 0.01 * i as f64, -0.05)))
            .collect();
        track_loops::complete_priors(&imm, &models, &tracks, dt_s, &displacements, &mut dispatched);
        for ((track, prior), displacement) in tracks.iter().zip(plain.iter_mut()).zip(&displacements) {
            imm.complete_prior_in_place(&models[track.class.index()], prior, dt_s, *displacement);
        }
        assert_eq!(bits(&dispatched), bits(&plain), "{method}: complete_priors");

        // Every fourth track without a measurement; the others measured 0.3 m off their prior.
        let measurements: Vec<Option<Measurement>> = plain
            .iter()
            .enumerate()
            .map(|(i, prior)| {
                (i % 4 != 0).then(|| measurement(prior.fused.mean.x + 0.3, prior.fused.mean.y - 0.2, 1.0))
            })
            .collect();
        let mut dispatched_tracks = tracks.clone();
        let mut outcomes = vec![Err(UpdateError); tracks.len()];
        track_loops::update(&imm, &models, &mut dispatched_tracks, &dispatched, &measurements, &mut outcomes);
        let mut plain_tracks = tracks.clone();
        for (i, track) in plain_tracks.iter_mut().enumerate() {
            let expected = match measurements[i] {
                Some(z) => imm.update_into(
                    &models[track.class.index()],
                    &plain[i],
                    z.position(),
                    &mut track.estimate,
                ),
                None => Ok(()),
            };
            assert_eq!(outcomes[i], expected, "{method}: outcome of track {i}");
        }
        let estimates = |tracks: &[Track]| bits(&tracks.iter().map(|t| t.estimate).collect::<Vec<_>>());
        assert_eq!(estimates(&dispatched_tracks), estimates(&plain_tracks), "{method}: update");
        assert_ne!(estimates(&dispatched_tracks), estimates(&tracks), "{method}: the update changed nothing");
    }
}
