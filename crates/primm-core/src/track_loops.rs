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

use crate::gaussian::UpdateError;
use crate::imm::{Imm, ImmPrior};
use crate::measurement::{Measurement, ObjectClass};
use crate::motion::ModeModels;
use crate::track::Track;
use glam::DVec2;
#[cfg(feature = "std")]
use multiversion::multiversion;

/// Per-class mode models, indexed by [`ObjectClass::index`].
pub type ClassModels = [ModeModels; ObjectClass::COUNT];

/// Mixing and the CV, CA and CT predictions of every track into `priors` (same order, at
/// least as long as `tracks`).
#[cfg_attr(feature = "std", multiversion(targets("x86_64+avx+avx2+fma")))]
pub fn predict_physics(
    imm: &Imm,
    models: &ClassModels,
    tracks: &[Track],
    dt_s: f64,
    priors: &mut [ImmPrior],
) {
    for (track, prior) in tracks.iter().zip(priors.iter_mut()) {
        imm.predict_physics_into(&models[track.class.index()], &track.estimate, dt_s, prior);
    }
}

/// The PR prior from each track's learned displacement and the fused prior of every track.
#[cfg_attr(feature = "std", multiversion(targets("x86_64+avx+avx2+fma")))]
pub fn complete_priors(
    imm: &Imm,
    models: &ClassModels,
    tracks: &[Track],
    dt_s: f64,
    displacements_m: &[Option<DVec2>],
    priors: &mut [ImmPrior],
) {
    for ((track, prior), displacement) in tracks.iter().zip(priors.iter_mut()).zip(displacements_m) {
        imm.complete_prior_in_place(&models[track.class.index()], prior, dt_s, *displacement);
    }
}

/// The IMM update of every track that has a measurement in `measurements` (same order as
/// `tracks`); `outcomes[i]` is the result for track `i` (`Ok` for tracks without measurement,
/// which are left untouched). A failed update leaves the track at its prior.
#[cfg_attr(feature = "std", multiversion(targets("x86_64+avx+avx2+fma")))]
pub fn update(
    imm: &Imm,
    models: &ClassModels,
    tracks: &mut [Track],
    priors: &[ImmPrior],
    measurements: &[Option<Measurement>],
    outcomes: &mut [Result<(), UpdateError>],
) {
    for (((track, prior), measurement), outcome) in
        tracks.iter_mut().zip(priors).zip(measurements).zip(outcomes.iter_mut())
    {
        *outcome = match measurement {
            Some(z) => {
                imm.update_into(&models[track.class.index()], prior, z.position(), &mut track.estimate)
            }
            None => Ok(()),
        };
    }
}
