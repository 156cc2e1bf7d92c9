//! The tracker's per-track loops: the arithmetic of a frame (mixing and prediction, prior
//! fusion, Kalman and mode-probability updates).
//!
//! Each loop is compiled twice, for baseline x86-64 and for x86-64 with AVX, AVX2 and FMA, and
//! the version the CPU supports is chosen once, on the first call (the
//! [`multiversion`](mod@multiversion) crate). The released binary therefore runs on any x86-64
//! and still uses the wider registers where they exist. Both versions compute bit-identical results: Rust never contracts a multiply and an
//! add into a fused multiply-add on its own, so the extra instructions change how values move
//! between registers, not what is computed. Other architectures get the baseline loop, and so
//! does a build without the `std` feature (run-time detection needs the standard library).
//!
//! [`selected_version`] says which version the dispatch picks on this CPU, and [`baseline`]
//! holds the same loops compiled for the baseline only, never dispatched, so that a test can
//! compare the two versions and know that it compared two different builds.

use crate::extent::ExpectedReflection;
use crate::gaussian::{to_nalgebra, RadialVelocityOutcome, UpdateError};
use crate::imm::{Imm, ImmPrior};
use crate::measurement::{Measurement, ObjectClass};
use crate::motion::ModeModels;
use crate::predictor::Displacement;
use crate::sensor_noise::MeasurementSensor;
use crate::track::Track;
#[cfg(feature = "std")]
use multiversion::multiversion;

/// Per-class mode models, indexed by [`ObjectClass::index`].
pub type ClassModels = [ModeModels; ObjectClass::COUNT];

/// Per-class IMMs (transition matrix and initial probabilities of `classes.<class>.imm`, else
/// of `imm`), indexed by [`ObjectClass::index`].
pub type ClassImms = [Imm; ObjectClass::COUNT];

/// Each class's IMM prepared from validated configuration.
pub fn class_imms(config: &crate::config::Config) -> ClassImms {
    ObjectClass::ALL.map(|class| Imm::new(&config.imm_for(class)))
}

/// Each class's IMM for steps whose ego motion is compensated
/// ([`Config::compensated_imm_for`](crate::config::Config::compensated_imm_for)).
pub fn class_compensated_imms(config: &crate::config::Config) -> ClassImms {
    ObjectClass::ALL.map(|class| Imm::new(&config.compensated_imm_for(class)))
}

/// Mixing and the CV, CA and CT predictions of every track into `priors` (same order, at
/// least as long as `tracks`).
#[cfg_attr(feature = "std", multiversion(targets("x86_64+avx+avx2+fma")))]
pub fn predict_physics(
    imms: &ClassImms,
    models: &ClassModels,
    tracks: &[Track],
    dt_s: f64,
    priors: &mut [ImmPrior],
) {
    predict_physics_loop(imms, models, tracks, dt_s, priors);
}

#[inline(always)]
fn predict_physics_loop(
    imms: &ClassImms,
    models: &ClassModels,
    tracks: &[Track],
    dt_s: f64,
    priors: &mut [ImmPrior],
) {
    for (track, prior) in tracks.iter().zip(priors.iter_mut()) {
        let class = track.class.index();
        imms[class].predict_physics_into(&models[class], &track.estimate, dt_s, prior);
    }
}

/// The PR prior from each track's learned displacement and the fused prior of every track.
#[cfg_attr(feature = "std", multiversion(targets("x86_64+avx+avx2+fma")))]
pub fn complete_priors(
    imms: &ClassImms,
    models: &ClassModels,
    tracks: &[Track],
    dt_s: f64,
    displacements: &[Option<Displacement>],
    priors: &mut [ImmPrior],
) {
    complete_priors_loop(imms, models, tracks, dt_s, displacements, priors);
}

#[inline(always)]
fn complete_priors_loop(
    imms: &ClassImms,
    models: &ClassModels,
    tracks: &[Track],
    dt_s: f64,
    displacements: &[Option<Displacement>],
    priors: &mut [ImmPrior],
) {
    for ((track, prior), displacement) in tracks.iter().zip(priors.iter_mut()).zip(displacements) {
        let class = track.class.index();
        imms[class].complete_prior_in_place(&models[class], prior, dt_s, *displacement);
    }
}

/// What the update of one track did: `Err` when it was refused for numerical reasons, else
/// what the radial-velocity row did (`None`: no row, or no measurement).
pub type UpdateOutcome = Result<Option<RadialVelocityOutcome>, UpdateError>;

/// The IMM update of every track that has a measurement in `measurements` (same order as
/// `tracks`), of the centre through the expected reflection for a class tracked as an extended
/// object (`crate::extent`; `reflections[i]` is track `i`'s expected reflection for its
/// measurement, computed by the caller once per frame, [`ExpectedReflection::POINT`] for a point
/// class, its spread added to the detection's own noise `sensors[i].noise_m2`), with the
/// radial-velocity row where the class asks for it, seen from `sensors[i].position_m` (the
/// tracking frame) and only with `radial_velocity_rows` (the
/// tracker passes whether the step tracks in the world frame); `outcomes[i]` is the result for track `i`
/// (`Ok(None)` for tracks without measurement, which are left untouched). A failed update
/// leaves the track at its prior.
#[cfg_attr(feature = "std", multiversion(targets("x86_64+avx+avx2+fma")))]
pub fn update(
    imms: &ClassImms,
    models: &ClassModels,
    tracks: &mut [Track],
    priors: &[ImmPrior],
    measurements: &[Option<Measurement>],
    sensors: &[MeasurementSensor],
    reflections: &[ExpectedReflection],
    radial_velocity_rows: bool,
    outcomes: &mut [UpdateOutcome],
) {
    update_loop(
        imms,
        models,
        tracks,
        priors,
        measurements,
        sensors,
        reflections,
        radial_velocity_rows,
        outcomes,
    );
}

#[inline(always)]
fn update_loop(
    imms: &ClassImms,
    models: &ClassModels,
    tracks: &mut [Track],
    priors: &[ImmPrior],
    measurements: &[Option<Measurement>],
    sensors: &[MeasurementSensor],
    reflections: &[ExpectedReflection],
    radial_velocity_rows: bool,
    outcomes: &mut [UpdateOutcome],
) {
    let per_track = tracks.iter_mut().zip(priors).zip(measurements).zip(sensors).zip(reflections);
    for (((((track, prior), measurement), sensor), reflection), outcome) in per_track.zip(outcomes.iter_mut())
    {
        *outcome = match measurement {
            Some(z) => {
                let class = track.class.index();
                let models = &models[class];
                let radial_velocity = models
                    .radial_velocity_observation(z, sensor, reflection.offset_m)
                    .filter(|_| radial_velocity_rows);
                imms[class].update_with_radial_velocity_into(
                    models,
                    prior,
                    z.position() - reflection.offset_m,
                    &to_nalgebra(&(reflection.covariance_m2 + sensor.noise_m2)),
                    radial_velocity.as_ref(),
                    &mut track.estimate,
                )
            }
            None => Ok(None),
        };
    }
}

/// A compiled version of the per-track loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopVersion {
    /// Baseline x86-64 (or the only version, on other architectures and without `std`).
    Baseline,
    /// x86-64 with AVX, AVX2 and FMA.
    Wide,
}

/// Whether the crate's baseline code was itself compiled with AVX2 (a build with
/// `-C target-cpu=native` or `-C target-feature=+avx2`): then [`baseline`] is not the baseline
/// and comparing it with the dispatched loops compares a build with itself.
pub fn baseline_built_with_avx2() -> bool {
    cfg!(target_feature = "avx2")
}

/// The version of the loops the run-time dispatch picks on this CPU. It is dispatched over the
/// same targets as the loops, so it picks what they pick.
#[cfg(feature = "std")]
#[multiversion(targets("x86_64+avx+avx2+fma"))]
pub fn selected_version() -> LoopVersion {
    if multiversion::target::selected_target!().supports_feature_str("avx2") {
        LoopVersion::Wide
    } else {
        LoopVersion::Baseline
    }
}

/// The version of the loops in use: without `std` there is no run-time dispatch, only the
/// baseline.
#[cfg(not(feature = "std"))]
pub fn selected_version() -> LoopVersion {
    LoopVersion::Baseline
}

/// The loops compiled for the baseline only, never dispatched: the reference against which the
/// wide version is compared.
pub mod baseline {
    use super::*;

    /// [`predict_physics`](super::predict_physics), baseline build.
    pub fn predict_physics(
        imms: &ClassImms,
        models: &ClassModels,
        tracks: &[Track],
        dt_s: f64,
        priors: &mut [ImmPrior],
    ) {
        predict_physics_loop(imms, models, tracks, dt_s, priors);
    }

    /// [`complete_priors`](super::complete_priors), baseline build.
    pub fn complete_priors(
        imms: &ClassImms,
        models: &ClassModels,
        tracks: &[Track],
        dt_s: f64,
        displacements: &[Option<Displacement>],
        priors: &mut [ImmPrior],
    ) {
        complete_priors_loop(imms, models, tracks, dt_s, displacements, priors);
    }

    /// [`update`](super::update), baseline build.
    pub fn update(
        imms: &ClassImms,
        models: &ClassModels,
        tracks: &mut [Track],
        priors: &[ImmPrior],
        measurements: &[Option<Measurement>],
        sensors: &[MeasurementSensor],
        reflections: &[ExpectedReflection],
        radial_velocity_rows: bool,
        outcomes: &mut [UpdateOutcome],
    ) {
        update_loop(
            imms,
            models,
            tracks,
            priors,
            measurements,
            sensors,
            reflections,
            radial_velocity_rows,
            outcomes,
        );
    }
}
