//! Gaussian mode estimates on the stack and the shared position-space machinery.
//!
//! Every mode's state puts the 2-D position first, so the observation matrix is `H = [I₂ 0]`
//! for all of them (`eq:observation`) and the functions here are written once for every state
//! size `N`:
//!
//! * [`Gaussian::position`] projects a mode onto the shared position space (`Hx`, `HPHᵀ`);
//! * [`replace_position`] puts a mixed position back into a mode while keeping the mode's own
//!   non-position states and their conditional distribution (`eq:cov_partition` … `eq:reconstructed_cov`);
//! * [`kalman_update`] is the measurement update with the Joseph-form covariance and the
//!   Gaussian log-likelihood (`eq:innovation` … `eq:posterior_cov`, `eq:likelihood`).
//!
//! Nothing here allocates: all matrices are `nalgebra` static matrices.

use crate::pose::RigidTransform;
use glam::{DMat2, DVec2};
use index::{OTHERS, X, Y};
use nalgebra::{Matrix2, SMatrix, SVector, Vector2};

/// Named indices shared by every mode's state: the position comes first, then the mode's other
/// states. Each motion model's `index` module names the rest of its layout.
pub mod index {
    /// x position, m.
    pub const X: usize = 0;
    /// y position, m.
    pub const Y: usize = 1;
    /// The first of the mode's other states `h` (`eq:cov_partition`): elements `OTHERS..N`.
    pub const OTHERS: usize = 2;
}

/// `ln(2π)`, used by the bivariate Gaussian log-density.
const LN_TWO_PI: f64 = 1.837_877_066_409_345_5;

/// Relative threshold under which singular values of a position covariance are treated as zero
/// by the pseudo-inverse in [`replace_position`].
pub const PSEUDO_INVERSE_RELATIVE_TOLERANCE: f64 = 1e-12;

/// A mode's estimate: mean and covariance, position first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gaussian<const N: usize> {
    /// State mean; elements [`X`] and [`Y`] are the position in metres.
    pub mean: SVector<f64, N>,
    /// State covariance (units: squares of the state's units).
    pub covariance: SMatrix<f64, N, N>,
}

/// The position marginal of an estimate: what the IMM mixes and fuses.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PositionEstimate {
    /// Position, metres.
    pub mean: DVec2,
    /// Position covariance, m².
    pub covariance: DMat2,
}

impl<const N: usize> Default for Gaussian<N> {
    /// Zero mean and zero covariance (a placeholder for preallocated storage).
    fn default() -> Self {
        Self { mean: SVector::zeros(), covariance: SMatrix::zeros() }
    }
}

impl<const N: usize> Gaussian<N> {
    /// A Gaussian from its parts.
    pub fn new(mean: SVector<f64, N>, covariance: SMatrix<f64, N, N>) -> Self {
        Self { mean, covariance }
    }

    /// The position marginal `(Hx, HPHᵀ)` with `H = [I₂ 0]`.
    pub fn position(&self) -> PositionEstimate {
        PositionEstimate {
            mean: DVec2::new(self.mean[X], self.mean[Y]),
            covariance: to_glam(&self.position_covariance()),
        }
    }

    /// The 2×2 position block `P_pp` of the covariance.
    pub fn position_covariance(&self) -> Matrix2<f64> {
        self.covariance.fixed_view::<2, 2>(X, X).into_owned()
    }

    /// This estimate in another frame: the position (elements [`X`], [`Y`]) mapped by
    /// `transform`, every planar vector that starts at an index of `vectors` (a velocity at
    /// 2, an acceleration at 4) rotated with it, other elements unchanged; the covariance
    /// `J P Jᵀ` with `J` the block-diagonal Jacobian of that map.
    pub fn transformed(&self, transform: &RigidTransform, vectors: &[usize]) -> Self {
        let rotation = Matrix2::new(
            transform.rotation.x_axis.x,
            transform.rotation.y_axis.x,
            transform.rotation.x_axis.y,
            transform.rotation.y_axis.y,
        );
        let mut jacobian = SMatrix::<f64, N, N>::identity();
        for &start in core::iter::once(&X).chain(vectors) {
            jacobian.fixed_view_mut::<2, 2>(start, start).copy_from(&rotation);
        }
        let mut mean = jacobian * self.mean;
        mean[X] += transform.translation_m.x;
        mean[Y] += transform.translation_m.y;
        let mut covariance = jacobian * self.covariance * jacobian.transpose();
        symmetrize(&mut covariance);
        Gaussian { mean, covariance }
    }
}

/// Converts a nalgebra 2×2 matrix to glam.
pub fn to_glam(m: &Matrix2<f64>) -> DMat2 {
    DMat2::from_cols(DVec2::new(m[(0, 0)], m[(1, 0)]), DVec2::new(m[(0, 1)], m[(1, 1)]))
}

/// Converts a glam 2×2 matrix to nalgebra.
pub fn to_nalgebra(m: &DMat2) -> Matrix2<f64> {
    Matrix2::new(m.x_axis.x, m.y_axis.x, m.x_axis.y, m.y_axis.y)
}

/// Moore–Penrose pseudo-inverse of a symmetric positive semi-definite 2×2 matrix, in closed
/// form. Full rank (the determinant above `PSEUDO_INVERSE_RELATIVE_TOLERANCE` × trace²): the
/// ordinary inverse. Rank one (`M = λvvᵀ`, `λ` = trace): `M / λ²`. Zero: zero.
#[inline]
pub fn symmetric_pseudo_inverse(m: &Matrix2<f64>) -> Matrix2<f64> {
    let (a, b, d) = (m[(0, 0)], 0.5 * (m[(0, 1)] + m[(1, 0)]), m[(1, 1)]);
    let trace = a + d;
    let determinant = a * d - b * b;
    if determinant > PSEUDO_INVERSE_RELATIVE_TOLERANCE * trace * trace {
        Matrix2::new(d, -b, -b, a) / determinant
    } else if trace > 0.0 {
        Matrix2::new(a, b, b, d) / (trace * trace)
    } else {
        Matrix2::zeros()
    }
}

/// Replaces a mode's position marginal by a mixed one (`eq:mixed_state`, `eq:B`, `eq:C`,
/// `eq:reconstructed_cov`).
///
/// With the covariance partitioned into position `p` and the mode's other states `h`
/// (`eq:cov_partition`), `B = P_hp P_pp^†` and `C = P_hh − B P_pp Bᵀ`; the new covariance is
/// `[[P̄, P̄Bᵀ], [BP̄, C + BP̄Bᵀ]]`. The mean's position becomes `p̄` and the non-position mean
/// keeps the mode's own value, exactly as the paper writes it. The conditional distribution of
/// `h` given the position (gain `B`, covariance `C`) is therefore unchanged.
#[inline(always)]
pub fn replace_position<const N: usize>(gaussian: &mut Gaussian<N>, mixed: &PositionEstimate) {
    let p_pp = gaussian.position_covariance();
    let p_pp_pinv = symmetric_pseudo_inverse(&p_pp);
    let p_bar = to_nalgebra(&mixed.covariance);
    let p = &mut gaussian.covariance;
    // The blocks of eq:reconstructed_cov, written out so that only O(N²) products remain:
    // top-left P̄; off-diagonal B P̄; bottom-right C + B P̄ Bᵀ = P_hh + B (P̄ − P_pp) Bᵀ,
    // with B = P_hp P_pp^† in rows OTHERS.. of `b`.
    let mut b = SMatrix::<f64, N, 2>::zeros();
    for r in OTHERS..N {
        for c in 0..2 {
            b[(r, c)] = p[(r, X)] * p_pp_pinv[(0, c)] + p[(r, Y)] * p_pp_pinv[(1, c)];
        }
    }
    let p_bar_01 = 0.5 * (p_bar[(0, 1)] + p_bar[(1, 0)]);
    let delta = [
        [p_bar[(0, 0)] - p_pp[(0, 0)], p_bar_01 - 0.5 * (p_pp[(0, 1)] + p_pp[(1, 0)])],
        [0.0, p_bar[(1, 1)] - p_pp[(1, 1)]],
    ];
    // Written in place: row r's pass reads the position columns only through `b` (computed
    // above) and reads P_hh entries (r, c) and (c, r) with c ≥ r, none of which an earlier
    // row's pass has written.
    p[(X, X)] = p_bar[(0, 0)];
    p[(Y, Y)] = p_bar[(1, 1)];
    p[(X, Y)] = p_bar_01;
    p[(Y, X)] = p_bar_01;
    for r in OTHERS..N {
        let (b0, b1) = (b[(r, 0)], b[(r, 1)]);
        // Row r of B P̄ (P̄ symmetric).
        let cross0 = b0 * p_bar[(0, 0)] + b1 * p_bar_01;
        let cross1 = b0 * p_bar_01 + b1 * p_bar[(1, 1)];
        p[(r, X)] = cross0;
        p[(X, r)] = cross0;
        p[(r, Y)] = cross1;
        p[(Y, r)] = cross1;
        // Row r of B Δ (Δ symmetric).
        let (d0, d1) = (b0 * delta[0][0] + b1 * delta[0][1], b0 * delta[0][1] + b1 * delta[1][1]);
        for c in r..N {
            let value = 0.5 * (p[(r, c)] + p[(c, r)]) + d0 * b[(c, 0)] + d1 * b[(c, 1)];
            p[(r, c)] = value;
            p[(c, r)] = value;
        }
    }
    gaussian.mean[X] = mixed.mean.x;
    gaussian.mean[Y] = mixed.mean.y;
}

/// Makes a covariance exactly symmetric by averaging it with its transpose.
#[inline]
pub fn symmetrize<const N: usize>(m: &mut SMatrix<f64, N, N>) {
    for r in 0..N {
        for c in (r + 1)..N {
            let mean = 0.5 * (m[(r, c)] + m[(c, r)]);
            m[(r, c)] = mean;
            m[(c, r)] = mean;
        }
    }
}

/// The result of one Kalman measurement update of a mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KalmanUpdate<const N: usize> {
    /// Posterior estimate (`eq:posterior_state`, `eq:posterior_cov`).
    pub posterior: Gaussian<N>,
    /// Innovation `ν = z − Hx⁻` (`eq:innovation`), metres.
    pub innovation: Vector2<f64>,
    /// Innovation covariance `S = HP⁻Hᵀ + R` (`eq:innovation_cov`), m².
    pub innovation_covariance: Matrix2<f64>,
    /// Natural log of the Gaussian likelihood `Λ` (`eq:likelihood`).
    pub log_likelihood: f64,
}

/// A Kalman update failed because the innovation covariance is not positive definite or a
/// result is not finite; the prior is left untouched.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("innovation covariance is not positive definite or the update is not finite")]
pub struct UpdateError;

/// Kalman update of a mode with a position measurement `z` and measurement covariance `r`
/// (`eq:innovation` … `eq:posterior_cov`): gain `K = P⁻Hᵀ S⁻¹`, mean `x⁻ + Kν`, Joseph-form
/// covariance `(I − KH)P⁻(I − KH)ᵀ + KRKᵀ`, and `ln Λ = −½ νᵀS⁻¹ν − ln 2π − ½ ln|S|`.
pub fn kalman_update<const N: usize>(
    prior: &Gaussian<N>,
    z: DVec2,
    r: &Matrix2<f64>,
) -> Result<KalmanUpdate<N>, UpdateError> {
    let mut posterior = *prior;
    let terms = kalman_update_into(prior, z, r, &mut posterior)?;
    Ok(KalmanUpdate {
        posterior,
        innovation: terms.innovation,
        innovation_covariance: terms.innovation_covariance,
        log_likelihood: terms.log_likelihood,
    })
}

/// The by-products of [`kalman_update_into`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UpdateTerms {
    /// `ν = z − H x⁻`, m.
    pub innovation: Vector2<f64>,
    /// `S = H P⁻ Hᵀ + R`, m².
    pub innovation_covariance: Matrix2<f64>,
    /// `ln N(ν; 0, S)`.
    pub log_likelihood: f64,
}

/// [`kalman_update`] written straight into `posterior` (no temporary copies of the state), for
/// the hot path. On error `posterior` holds unspecified values and must be discarded.
#[inline(always)]
pub fn kalman_update_into<const N: usize>(
    prior: &Gaussian<N>,
    z: DVec2,
    r: &Matrix2<f64>,
    posterior: &mut Gaussian<N>,
) -> Result<UpdateTerms, UpdateError> {
    let p = &prior.covariance;
    let innovation = Vector2::new(z.x - prior.mean[X], z.y - prior.mean[Y]);
    // S = H P Hᵀ + R is the top-left block plus R, symmetrised.
    let (s00, s11) = (p[(X, X)] + r[(0, 0)], p[(Y, Y)] + r[(1, 1)]);
    let s01 = 0.5 * (p[(X, Y)] + p[(Y, X)] + r[(0, 1)] + r[(1, 0)]);
    let determinant = s00 * s11 - s01 * s01;
    // Positive definite exactly when both leading minors are positive (Sylvester).
    if !(s00 > 0.0 && determinant > 0.0) {
        return Err(UpdateError);
    }
    let (i00, i01, i11) = (s11 / determinant, -s01 / determinant, s00 / determinant);
    let mahalanobis_squared = innovation.x * (i00 * innovation.x + i01 * innovation.y)
        + innovation.y * (i01 * innovation.x + i11 * innovation.y);
    let log_likelihood = -0.5 * mahalanobis_squared - LN_TWO_PI - 0.5 * crate::math::ln(determinant);
    if !log_likelihood.is_finite() {
        return Err(UpdateError);
    }

    // K = P Hᵀ S⁻¹ (P Hᵀ is P's first two columns), and the first two columns of
    // A = (I − KH)P = P − K·P[0..2, :].
    let mut gain = [[0.0; 2]; N];
    let mut a_left = [[0.0; 2]; N];
    for row in 0..N {
        let (p0, p1) = (p[(row, X)], p[(row, Y)]);
        let k = [p0 * i00 + p1 * i01, p0 * i01 + p1 * i11];
        gain[row] = k;
        a_left[row] =
            [p0 - (k[0] * p[(X, X)] + k[1] * p[(Y, X)]), p1 - (k[0] * p[(X, Y)] + k[1] * p[(Y, Y)])];
    }
    // Joseph form (I − KH)P(I − KH)ᵀ + KRKᵀ with H = [I₂ 0], element by element in O(N²):
    // A − A[:, 0..2]·Kᵀ + K R Kᵀ, where A = P − K·P[0..2, :]. Upper triangle, mirrored.
    let (r00, r01, r10, r11) = (r[(0, 0)], r[(0, 1)], r[(1, 0)], r[(1, 1)]);
    for column in 0..N {
        let k = gain[column];
        let (top0, top1) = (p[(X, column)], p[(Y, column)]);
        // Column `column` of R Kᵀ.
        let (rk0, rk1) = (r00 * k[0] + r01 * k[1], r10 * k[0] + r11 * k[1]);
        for row in 0..=column {
            let g = gain[row];
            let a = p[(row, column)] - (g[0] * top0 + g[1] * top1);
            let value = a - (a_left[row][0] * k[0] + a_left[row][1] * k[1]) + (g[0] * rk0 + g[1] * rk1);
            posterior.covariance[(row, column)] = value;
            posterior.covariance[(column, row)] = value;
        }
    }
    for row in 0..N {
        let value = prior.mean[row] + gain[row][0] * innovation.x + gain[row][1] * innovation.y;
        if !value.is_finite() {
            return Err(UpdateError);
        }
        posterior.mean[row] = value;
    }
    Ok(UpdateTerms { innovation, innovation_covariance: Matrix2::new(s00, s01, s01, s11), log_likelihood })
}

/// A radial velocity measured along the line of sight from a sensor, for the extended Kalman
/// row `h(x) = û·v` of [`radial_velocity_update_in_place`] (ARCHITECTURE.md, "Radial velocity
/// in the update").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadialVelocityObservation {
    /// The measured radial velocity over ground (ego-motion compensated), m/s; positive away
    /// from the sensor.
    pub radial_velocity_mps: f64,
    /// Where the sensor that measured it is, in the frame of the state, m.
    pub sensor_position_m: DVec2,
    /// Variance of the radial velocity as a measurement of the object's velocity, (m/s)².
    pub variance_mps2: f64,
    /// Largest normalised residual `|ν|/√S` for which the row is applied; larger ones are
    /// skipped (a radial velocity that the track cannot explain), dimensionless.
    pub gate_std: f64,
    /// A fixed unit line of sight `û` (from the sensor to the detection, whose azimuth the
    /// radar measured): the row is then linear, `h(x) = û·v`. `None`: `û` runs from the sensor
    /// to the state's position (an extended Kalman row).
    pub measured_line_of_sight: Option<DVec2>,
    /// Without a fixed line of sight: the offset of the reflection from the state's position,
    /// m, so that `û` runs from the sensor to the state's position plus this offset (held fixed
    /// in the Jacobian). Zero: to the state's position.
    pub reflection_offset_m: DVec2,
    /// Variance of the direction of `measured_line_of_sight`, rad²: the detection's position
    /// noise across the line of sight over its range squared. A direction off by `δ` misreads
    /// the velocity across the line of sight `v⊥` by `|v⊥|·δ`, so the row's variance grows by
    /// `|v⊥|²` times this (at the state's velocity). Zero without a measured line of sight.
    pub line_of_sight_variance_rad2: f64,
}

/// What [`radial_velocity_update_in_place`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RadialVelocityOutcome {
    /// The row was applied.
    Applied,
    /// The residual lay beyond the gate; the estimate is unchanged.
    Gated,
    /// The predicted position is (almost) at the sensor, where the line of sight is undefined;
    /// the estimate is unchanged.
    NoLineOfSight,
}

/// Ranges below this leave the line of sight undefined, m.
pub const MIN_LINE_OF_SIGHT_RANGE_M: f64 = 0.1;

/// The predicted radial velocity `h(x) = û·v` of a state whose velocity sits at elements
/// `velocity..velocity + 2`, with `û = (p − s)/‖p − s‖`, and its Jacobian with respect to
/// `[x, y, vx, vy]`: `∂h/∂p = (v − (û·v)û)/‖p − s‖`, `∂h/∂v = û`. `None` within
/// [`MIN_LINE_OF_SIGHT_RANGE_M`] of the sensor.
pub fn radial_velocity_and_jacobian<const N: usize>(
    mean: &SVector<f64, N>,
    velocity: usize,
    sensor_position_m: DVec2,
) -> Option<(f64, [f64; 4])> {
    let offset = DVec2::new(mean[X] - sensor_position_m.x, mean[Y] - sensor_position_m.y);
    let range = offset.length();
    if !(range >= MIN_LINE_OF_SIGHT_RANGE_M) {
        return None;
    }
    let along = offset / range;
    let v = DVec2::new(mean[velocity], mean[velocity + 1]);
    let radial = along.dot(v);
    let across = (v - radial * along) / range;
    Some((radial, [across.x, across.y, along.x, along.y]))
}

/// One extended Kalman row of a radial velocity (`h(x) = û·v`, linearised at the current
/// estimate) applied to `gaussian` in place, with the Joseph-form covariance
/// `(I − kh)P(I − kh)ᵀ + k σ² kᵀ`, in `O(N²)` and without allocation. The velocity sits at
/// elements `velocity..velocity + 2`. Gated and degenerate rows leave the estimate as it was;
/// on [`UpdateError`] (a non-positive `S` or a non-finite result) it is unchanged as well.
pub fn radial_velocity_update_in_place<const N: usize>(
    gaussian: &mut Gaussian<N>,
    velocity: usize,
    observation: &RadialVelocityObservation,
) -> Result<RadialVelocityOutcome, UpdateError> {
    let v = DVec2::new(gaussian.mean[velocity], gaussian.mean[velocity + 1]);
    let mut variance = observation.variance_mps2;
    let row = match observation.measured_line_of_sight {
        Some(along) => {
            let radial = along.dot(v);
            variance += (v - radial * along).length_squared() * observation.line_of_sight_variance_rad2;
            Some((radial, [0.0, 0.0, along.x, along.y]))
        }
        // `p + o − s = p − (s − o)`: the reflection seen from the sensor is the state's position
        // seen from the sensor moved back by the offset, with the same Jacobian in `p`.
        None => radial_velocity_and_jacobian(
            &gaussian.mean,
            velocity,
            observation.sensor_position_m - observation.reflection_offset_m,
        ),
    };
    let Some((predicted, jacobian)) = row else {
        return Ok(RadialVelocityOutcome::NoLineOfSight);
    };
    let columns = [X, Y, velocity, velocity + 1];
    let p = &gaussian.covariance;
    // c = P hᵀ, S = h c + σ².
    let mut c = [0.0; N];
    for (row, value) in c.iter_mut().enumerate() {
        *value = columns.iter().zip(&jacobian).map(|(&column, h)| p[(row, column)] * h).sum();
    }
    let s = columns.iter().zip(&jacobian).map(|(&column, h)| c[column] * h).sum::<f64>() + variance;
    if !(s > 0.0 && s.is_finite()) {
        return Err(UpdateError);
    }
    let residual = observation.radial_velocity_mps - predicted;
    if !(residual * residual <= observation.gate_std * observation.gate_std * s) {
        return Ok(RadialVelocityOutcome::Gated);
    }
    let mut gain = [0.0; N];
    for (k, c) in gain.iter_mut().zip(&c) {
        *k = c / s;
    }
    // A = (I − k h) P = P − k cᵀ; a = A hᵀ; P' = A(I − k h)ᵀ + σ² k kᵀ = A − a kᵀ + σ² k kᵀ.
    let mut a_h = [0.0; N];
    for row in 0..N {
        a_h[row] = columns
            .iter()
            .zip(&jacobian)
            .map(|(&column, h)| (p[(row, column)] - gain[row] * c[column]) * h)
            .sum();
    }
    let mut updated = *gaussian;
    for row in 0..N {
        for column in row..N {
            let a = p[(row, column)] - gain[row] * c[column];
            let value = a - a_h[row] * gain[column] + variance * gain[row] * gain[column];
            // Upper triangle of A − a kᵀ + σ² k kᵀ, mirrored (the Joseph product is symmetric).
            updated.covariance[(row, column)] = value;
            updated.covariance[(column, row)] = value;
        }
        updated.mean[row] += gain[row] * residual;
    }
    if !(updated.mean.iter().all(|v| v.is_finite()) && updated.covariance.iter().all(|v| v.is_finite())) {
        return Err(UpdateError);
    }
    *gaussian = updated;
    Ok(RadialVelocityOutcome::Applied)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix4, Vector4};

    fn spd4() -> Matrix4<f64> {
        let a = Matrix4::new(1.0, 0.2, 0.1, 0.0, 0.3, 2.0, 0.0, 0.4, 0.0, 0.1, 1.5, 0.2, 0.1, 0.0, 0.3, 0.8);
        a * a.transpose() + Matrix4::identity() * 0.1
    }

    #[test]
    fn pseudo_inverse_equals_inverse_for_invertible_matrices() {
        let m = Matrix2::new(2.0, 0.3, 0.3, 1.0);
        let difference = symmetric_pseudo_inverse(&m) - m.try_inverse().unwrap();
        assert!(difference.abs().max() < 1e-12);
    }

    #[test]
    fn pseudo_inverse_of_a_rank_one_matrix_satisfies_the_penrose_conditions() {
        let v = Vector2::new(1.0, 2.0);
        let m = v * v.transpose();
        let pinv = symmetric_pseudo_inverse(&m);
        assert!((m * pinv * m - m).abs().max() < 1e-12);
        assert!((pinv * m * pinv - pinv).abs().max() < 1e-12);
    }

    #[test]
    fn closed_form_pseudo_inverse_matches_nalgebra_svd_on_full_rank_rank_one_and_zero_matrices() {
        let mut cases =
            vec![Matrix2::zeros(), Matrix2::new(4.0, 0.0, 0.0, 0.0), Matrix2::new(0.0, 0.0, 0.0, 2.5)];
        for i in 0..200 {
            let angle = f64::from(i) * 0.37;
            let v = Vector2::new(angle.cos(), angle.sin());
            let w = Vector2::new(-angle.sin(), angle.cos());
            let (large, small) = (0.1 + f64::from(i % 7), [0.0, 1e-3, 0.5][i as usize % 3]);
            cases.push(v * v.transpose() * large + w * w.transpose() * small);
        }
        for m in cases {
            let reference = m.pseudo_inverse(1e-12).unwrap();
            let ours = symmetric_pseudo_inverse(&m);
            let scale = reference.abs().max().max(1.0);
            assert!((ours - reference).abs().max() < 1e-9 * scale, "{m} -> {ours} vs {reference}");
        }
    }

    #[test]
    fn replacing_the_position_by_itself_changes_nothing() {
        let mut g = Gaussian::new(Vector4::new(1.0, 2.0, 3.0, 4.0), spd4());
        let before = g;
        let own = g.position();
        replace_position(&mut g, &own);
        assert!((g.covariance - before.covariance).abs().max() < 1e-12);
        assert_eq!(g.mean, before.mean);
    }

    #[test]
    fn kalman_update_likelihood_matches_the_bivariate_normal_density() {
        let prior = Gaussian::new(Vector4::new(0.0, 0.0, 1.0, 0.0), spd4());
        let r = Matrix2::new(0.5, 0.1, 0.1, 0.4);
        let z = DVec2::new(0.7, -0.3);
        let update = kalman_update(&prior, z, &r).unwrap();
        let s = prior.position_covariance() + r;
        let nu = Vector2::new(0.7, -0.3);
        let density = (-0.5 * (nu.transpose() * s.try_inverse().unwrap() * nu)[(0, 0)]).exp()
            / (2.0 * core::f64::consts::PI * s.determinant().sqrt());
        assert!((update.log_likelihood - density.ln()).abs() < 1e-12);
    }

    /// The textbook update with explicit `H`, `K = P Hᵀ S⁻¹` and the full Joseph product, in
    /// nalgebra's general matrix arithmetic.
    fn reference_update(
        prior: &Gaussian<4>,
        z: DVec2,
        r: &Matrix2<f64>,
    ) -> (Vector4<f64>, Matrix4<f64>, f64) {
        let h = nalgebra::Matrix2x4::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
        let s = h * prior.covariance * h.transpose() + r;
        let s_inverse = s.try_inverse().unwrap();
        let k = prior.covariance * h.transpose() * s_inverse;
        let nu = Vector2::new(z.x, z.y) - h * prior.mean;
        let i_kh = Matrix4::identity() - k * h;
        let covariance = i_kh * prior.covariance * i_kh.transpose() + k * r * k.transpose();
        let log_likelihood = -0.5 * (nu.transpose() * s_inverse * nu)[(0, 0)]
            - (2.0 * core::f64::consts::PI).ln()
            - 0.5 * s.determinant().ln();
        (prior.mean + k * nu, covariance, log_likelihood)
    }

    #[test]
    fn kalman_update_matches_the_textbook_joseph_form_computed_with_full_matrices() {
        for i in 0..50 {
            let angle = f64::from(i) * 0.41;
            let mut covariance = spd4() * (0.5 + f64::from(i % 5));
            covariance[(X, Y)] += 0.1 * angle.sin();
            covariance[(Y, X)] = covariance[(X, Y)];
            let prior = Gaussian::new(Vector4::new(angle.cos(), angle.sin(), 2.0, -1.0), covariance);
            let r = Matrix2::new(0.3 + 0.1 * f64::from(i % 3), 0.05, 0.05, 0.2);
            let z = DVec2::new(1.0 + angle.sin(), -0.5 + angle.cos());
            let ours = kalman_update(&prior, z, &r).unwrap();
            let (mean, covariance, log_likelihood) = reference_update(&prior, z, &r);
            assert!((ours.posterior.mean - mean).abs().max() < 1e-12);
            assert!(
                (ours.posterior.covariance - covariance).abs().max()
                    < 1e-12 * covariance.abs().max().max(1.0)
            );
            assert!((ours.log_likelihood - log_likelihood).abs() < 1e-12);
        }
    }

    #[test]
    fn kalman_update_refuses_an_innovation_covariance_that_is_not_positive_definite() {
        let mut prior = Gaussian::new(Vector4::zeros(), spd4());
        prior.covariance[(X, X)] = -5.0;
        assert_eq!(kalman_update(&prior, DVec2::ZERO, &Matrix2::identity()), Err(UpdateError));
        let prior = Gaussian::new(Vector4::zeros(), Matrix4::zeros());
        assert_eq!(kalman_update(&prior, DVec2::ZERO, &Matrix2::zeros()), Err(UpdateError));
    }

    /// eq:reconstructed_cov assembled block by block with general nalgebra products.
    fn reference_replace(g: &Gaussian<4>, mixed: &PositionEstimate) -> Matrix4<f64> {
        let p = g.covariance;
        let p_pp = p.fixed_view::<2, 2>(X, X).into_owned();
        let p_hp = p.fixed_view::<2, 2>(OTHERS, X).into_owned();
        let p_hh = p.fixed_view::<2, 2>(OTHERS, OTHERS).into_owned();
        let b = p_hp * p_pp.pseudo_inverse(1e-12).unwrap();
        let p_bar = to_nalgebra(&mixed.covariance);
        let c = p_hh - b * p_pp * b.transpose();
        let mut out = Matrix4::zeros();
        out.fixed_view_mut::<2, 2>(X, X).copy_from(&p_bar);
        out.fixed_view_mut::<2, 2>(OTHERS, X).copy_from(&(b * p_bar));
        out.fixed_view_mut::<2, 2>(X, OTHERS).copy_from(&(b * p_bar).transpose());
        out.fixed_view_mut::<2, 2>(OTHERS, OTHERS).copy_from(&(c + b * p_bar * b.transpose()));
        out
    }

    #[test]
    fn replace_position_matches_the_block_formula_computed_with_general_products() {
        for i in 0..40 {
            let angle = f64::from(i) * 0.3;
            let mut g = Gaussian::new(Vector4::new(1.0, 2.0, 3.0, 4.0), spd4() * (1.0 + f64::from(i % 4)));
            if i % 5 == 0 {
                // A singular position block (rank one), where B comes from the pseudo-inverse.
                let v = Vector2::new(angle.cos(), angle.sin());
                g.covariance.fixed_view_mut::<2, 2>(X, X).copy_from(&(v * v.transpose() * 2.0));
            }
            let mixed = PositionEstimate {
                mean: DVec2::new(angle.sin(), 0.5),
                covariance: DMat2::from_cols(DVec2::new(1.0 + 0.2 * angle.cos(), 0.1), DVec2::new(0.1, 0.7)),
            };
            let reference = reference_replace(&g, &mixed);
            replace_position(&mut g, &mixed);
            assert!((g.covariance - reference).abs().max() < 1e-9 * reference.abs().max(), "case {i}");
            assert_eq!((g.mean[X], g.mean[Y], g.mean[OTHERS]), (mixed.mean.x, mixed.mean.y, 3.0));
        }
    }

    fn observation(radial_velocity_mps: f64, sensor: DVec2) -> RadialVelocityObservation {
        RadialVelocityObservation {
            radial_velocity_mps,
            sensor_position_m: sensor,
            variance_mps2: 0.09,
            gate_std: 1e9,
            measured_line_of_sight: None,
            reflection_offset_m: DVec2::ZERO,
            line_of_sight_variance_rad2: 0.0,
        }
    }

    #[test]
    fn the_radial_velocity_jacobian_matches_central_finite_differences() {
        for i in 0..60 {
            let angle = f64::from(i) * 0.53;
            let mean = nalgebra::Vector5::new(
                12.0 * angle.cos(),
                7.0 * angle.sin() + 1.0,
                3.0 * (1.3 * angle).sin(),
                -2.0 + (0.7 * angle).cos(),
                0.2,
            );
            let sensor = DVec2::new(3.7, -0.8 + 0.1 * f64::from(i % 3));
            let (_, jacobian) = radial_velocity_and_jacobian(&mean, 2, sensor).unwrap();
            for (element, analytic) in jacobian.iter().enumerate() {
                let step = 1e-6;
                let (mut plus, mut minus) = (mean, mean);
                plus[element] += step;
                minus[element] -= step;
                let numeric = (radial_velocity_and_jacobian(&plus, 2, sensor).unwrap().0
                    - radial_velocity_and_jacobian(&minus, 2, sensor).unwrap().0)
                    / (2.0 * step);
                assert!(
                    (numeric - analytic).abs() < 1e-7,
                    "case {i}, element {element}: {numeric} vs {analytic}"
                );
            }
        }
    }

    #[test]
    fn the_radial_velocity_row_matches_the_textbook_joseph_update_with_full_matrices() {
        for i in 0..40 {
            let angle = f64::from(i) * 0.37;
            let prior = Gaussian::new(
                Vector4::new(10.0 * angle.cos(), 10.0 * angle.sin(), 2.0 * angle.sin(), -1.0),
                spd4() * (0.5 + f64::from(i % 4)),
            );
            let sensor = DVec2::new(1.0, -0.5);
            let z = 1.5 * angle.cos();
            let (predicted, jacobian) = radial_velocity_and_jacobian(&prior.mean, 2, sensor).unwrap();
            let h = nalgebra::RowVector4::new(jacobian[0], jacobian[1], jacobian[2], jacobian[3]);
            let s = (h * prior.covariance * h.transpose())[(0, 0)] + 0.09;
            let k = prior.covariance * h.transpose() / s;
            let i_kh = Matrix4::identity() - k * h;
            let covariance = i_kh * prior.covariance * i_kh.transpose() + k * 0.09 * k.transpose();
            let mean = prior.mean + k * (z - predicted);
            let mut ours = prior;
            let outcome = radial_velocity_update_in_place(&mut ours, 2, &observation(z, sensor)).unwrap();
            assert_eq!(outcome, RadialVelocityOutcome::Applied);
            assert!((ours.mean - mean).abs().max() < 1e-12, "case {i}");
            assert!((ours.covariance - covariance).abs().max() < 1e-12 * covariance.abs().max(), "case {i}");
            assert_eq!(ours.covariance, ours.covariance.transpose());
        }
    }

    #[test]
    fn a_radial_velocity_row_narrows_the_velocity_along_the_line_of_sight_only() {
        // An object 10 m ahead of the sensor on the x axis: the row observes vx, not vy.
        let prior = Gaussian::new(Vector4::new(10.0, 0.0, 0.0, 0.0), Matrix4::identity() * 4.0);
        let mut posterior = prior;
        radial_velocity_update_in_place(&mut posterior, 2, &observation(2.0, DVec2::ZERO)).unwrap();
        assert!(posterior.covariance[(2, 2)] < 0.1, "vx variance {}", posterior.covariance[(2, 2)]);
        assert!((posterior.mean[2] - 2.0 * 4.0 / 4.09).abs() < 1e-12);
        assert!((posterior.covariance[(3, 3)] - 4.0).abs() < 1e-12, "vy is not observed here");
        assert_eq!(posterior.mean[3], 0.0);
    }

    #[test]
    fn a_row_along_the_measured_line_of_sight_is_the_linear_joseph_update_with_no_position_jacobian() {
        for i in 0..40 {
            let angle = f64::from(i) * 0.41;
            let prior = Gaussian::new(
                Vector4::new(10.0 * angle.cos(), 10.0 * angle.sin(), 2.0 * angle.sin(), -1.0),
                spd4() * (0.5 + f64::from(i % 4)),
            );
            let along = DVec2::new((angle + 0.2).cos(), (angle + 0.2).sin());
            let z = 1.5 * angle.cos();
            let h = nalgebra::RowVector4::new(0.0, 0.0, along.x, along.y);
            let predicted = (h * prior.mean)[(0, 0)];
            let s = (h * prior.covariance * h.transpose())[(0, 0)] + 0.09;
            let k = prior.covariance * h.transpose() / s;
            let i_kh = Matrix4::identity() - k * h;
            let covariance = i_kh * prior.covariance * i_kh.transpose() + k * 0.09 * k.transpose();
            let mean = prior.mean + k * (z - predicted);
            let mut ours = prior;
            let observation = RadialVelocityObservation {
                measured_line_of_sight: Some(along),
                ..observation(z, DVec2::new(1.0, -0.5))
            };
            assert_eq!(
                radial_velocity_update_in_place(&mut ours, 2, &observation),
                Ok(RadialVelocityOutcome::Applied)
            );
            assert!((ours.mean - mean).abs().max() < 1e-12, "case {i}");
            assert!((ours.covariance - covariance).abs().max() < 1e-12 * covariance.abs().max(), "case {i}");
        }
    }

    #[test]
    fn off_the_centre_the_measured_line_of_sight_explains_a_reflection_that_the_predicted_one_does_not() {
        // A body crossing at 8 m/s, 10 m ahead of the sensor, measured at a reflection 1.5 m to
        // the side of its centre: the radial velocity there is the velocity along that direction.
        let velocity = DVec2::new(0.0, 8.0);
        let reflection = DVec2::new(10.0, -1.5);
        let along = reflection.normalize();
        let measured = along.dot(velocity);
        let prior = Gaussian::new(Vector4::new(10.0, 0.0, velocity.x, velocity.y), Matrix4::identity() * 4.0);
        let mut exact = prior;
        let row = RadialVelocityObservation {
            measured_line_of_sight: Some(along),
            ..observation(measured, DVec2::ZERO)
        };
        radial_velocity_update_in_place(&mut exact, 2, &row).unwrap();
        assert!(
            (exact.mean - prior.mean).abs().max() < 1e-12,
            "the true state predicts the measurement exactly"
        );
        let mut towards_centre = prior;
        radial_velocity_update_in_place(&mut towards_centre, 2, &observation(measured, DVec2::ZERO)).unwrap();
        let pulled = (towards_centre.mean.fixed_rows::<2>(2) - prior.mean.fixed_rows::<2>(2)).norm();
        assert!(
            pulled > 0.5,
            "along the centre's line of sight the same reading moves the velocity by {pulled} m/s"
        );
    }

    #[test]
    fn a_noisy_measured_direction_weighs_the_row_by_the_velocity_across_it() {
        // The variance grows by |v⊥|² δ²: with no velocity across the line of sight the row is
        // as without direction noise; with 4 m/s across it and δ² = 0.01 rad², S grows by 0.16.
        let along = DVec2::X;
        let row = |vy: f64, direction_variance: f64| {
            let prior = Gaussian::new(Vector4::new(10.0, 0.0, 1.0, vy), Matrix4::identity());
            let mut posterior = prior;
            let observation = RadialVelocityObservation {
                measured_line_of_sight: Some(along),
                line_of_sight_variance_rad2: direction_variance,
                ..observation(2.0, DVec2::ZERO)
            };
            radial_velocity_update_in_place(&mut posterior, 2, &observation).unwrap();
            posterior
        };
        assert_eq!(row(0.0, 0.01), row(0.0, 0.0));
        let (noisy, exact) = (row(4.0, 0.01), row(4.0, 0.0));
        // Gain on vx: 1/(1 + 0.09 + extra).
        assert!((exact.mean[2] - (1.0 + 1.0 / 1.09)).abs() < 1e-12);
        assert!((noisy.mean[2] - (1.0 + 1.0 / 1.25)).abs() < 1e-12);
        assert!(noisy.covariance[(2, 2)] > exact.covariance[(2, 2)]);
    }

    #[test]
    fn a_reflection_offset_moves_the_line_of_sight_as_a_shifted_sensor_would() {
        let prior = Gaussian::new(Vector4::new(10.0, 3.0, -2.0, 5.0), spd4());
        let offset = DVec2::new(-1.0, 0.8);
        let sensor = DVec2::new(1.0, -0.5);
        let mut with_offset = prior;
        let row = RadialVelocityObservation { reflection_offset_m: offset, ..observation(1.0, sensor) };
        radial_velocity_update_in_place(&mut with_offset, 2, &row).unwrap();
        let mut shifted = prior;
        radial_velocity_update_in_place(&mut shifted, 2, &observation(1.0, sensor - offset)).unwrap();
        assert_eq!(with_offset, shifted);
        let mut centre = prior;
        radial_velocity_update_in_place(&mut centre, 2, &observation(1.0, sensor)).unwrap();
        assert!((centre.mean - with_offset.mean).abs().max() > 1e-3, "the offset changes the row");
    }

    #[test]
    fn gated_and_degenerate_radial_velocity_rows_leave_the_estimate_unchanged() {
        let prior = Gaussian::new(Vector4::new(10.0, 0.0, 0.0, 0.0), Matrix4::identity());
        let mut gated = prior;
        let tight = RadialVelocityObservation { gate_std: 3.0, ..observation(30.0, DVec2::ZERO) };
        assert_eq!(radial_velocity_update_in_place(&mut gated, 2, &tight), Ok(RadialVelocityOutcome::Gated));
        assert_eq!(gated, prior);
        let mut at_sensor = prior;
        let on_top = observation(1.0, DVec2::new(10.0, 0.0));
        assert_eq!(
            radial_velocity_update_in_place(&mut at_sensor, 2, &on_top),
            Ok(RadialVelocityOutcome::NoLineOfSight)
        );
        assert_eq!(at_sensor, prior);
        let mut broken = prior;
        let negative = RadialVelocityObservation { variance_mps2: -10.0, ..observation(1.0, DVec2::ZERO) };
        assert_eq!(radial_velocity_update_in_place(&mut broken, 2, &negative), Err(UpdateError));
        assert_eq!(broken, prior);
    }
}
