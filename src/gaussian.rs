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

use glam::{DMat2, DVec2};
use nalgebra::{Matrix2, SMatrix, SVector, Vector2};

/// `ln(2π)`, used by the bivariate Gaussian log-density.
const LN_TWO_PI: f64 = 1.837_877_066_409_345_5;

/// Relative threshold under which singular values of a position covariance are treated as zero
/// by the pseudo-inverse in [`replace_position`].
pub const PSEUDO_INVERSE_RELATIVE_TOLERANCE: f64 = 1e-12;

/// A mode's estimate: mean and covariance, position first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gaussian<const N: usize> {
    /// State mean; elements 0 and 1 are the x and y position in metres.
    pub mean: SVector<f64, N>,
    /// State covariance (units: squares of the state's units).
    pub covariance: SMatrix<f64, N, N>,
}

/// The position marginal of an estimate: what the IMM mixes and fuses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionEstimate {
    /// Position, metres.
    pub mean: DVec2,
    /// Position covariance, m².
    pub covariance: DMat2,
}

impl<const N: usize> Gaussian<N> {
    /// A Gaussian from its parts.
    pub fn new(mean: SVector<f64, N>, covariance: SMatrix<f64, N, N>) -> Self {
        Self { mean, covariance }
    }

    /// The position marginal `(Hx, HPHᵀ)` with `H = [I₂ 0]`.
    pub fn position(&self) -> PositionEstimate {
        PositionEstimate {
            mean: DVec2::new(self.mean[0], self.mean[1]),
            covariance: to_glam(&self.position_covariance()),
        }
    }

    /// The 2×2 position block `P_pp` of the covariance.
    pub fn position_covariance(&self) -> Matrix2<f64> {
        self.covariance.fixed_view::<2, 2>(0, 0).into_owned()
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
pub fn replace_position<const N: usize>(gaussian: &mut Gaussian<N>, mixed: &PositionEstimate) {
    let p = &gaussian.covariance;
    let p_pp = gaussian.position_covariance();
    let p_pp_pinv = symmetric_pseudo_inverse(&p_pp);
    let p_bar = to_nalgebra(&mixed.covariance);

    // Rows 2.. of `gain` hold B; rows 0..2 are set to I₂ so that `gain P̄ gainᵀ` yields all
    // three blocks of eq:reconstructed_cov at once.
    let mut gain = SMatrix::<f64, N, 2>::zeros();
    for r in 2..N {
        for c in 0..2 {
            gain[(r, c)] = p[(r, 0)] * p_pp_pinv[(0, c)] + p[(r, 1)] * p_pp_pinv[(1, c)];
        }
    }
    let explained_old = gain * p_pp * gain.transpose(); // B P_pp Bᵀ in the h block
    gain[(0, 0)] = 1.0;
    gain[(1, 1)] = 1.0;
    let mut reconstructed = gain * p_bar * gain.transpose();
    for r in 2..N {
        for c in 2..N {
            // C = P_hh − B P_pp Bᵀ, added to B P̄ Bᵀ.
            reconstructed[(r, c)] += p[(r, c)] - explained_old[(r, c)];
        }
    }
    symmetrize(&mut reconstructed);
    gaussian.covariance = reconstructed;
    gaussian.mean[0] = mixed.mean.x;
    gaussian.mean[1] = mixed.mean.y;
}

/// Makes a covariance exactly symmetric by averaging it with its transpose.
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
    let innovation = Vector2::new(z.x - prior.mean[0], z.y - prior.mean[1]);
    let s = prior.position_covariance() + r;
    let cholesky = nalgebra::Cholesky::new(s).ok_or(UpdateError)?;
    let s_inverse = cholesky.inverse();
    let ph_t: SMatrix<f64, N, 2> = prior.covariance.fixed_columns::<2>(0).into_owned();
    let gain = ph_t * s_inverse;

    // Joseph form (I − KH)P(I − KH)ᵀ + KRKᵀ, evaluated with H = [I₂ 0] in O(N²):
    // A = (I − KH)P = P − K·P[0..2, :], then A(I − KH)ᵀ = A − A[:, 0..2]·Kᵀ.
    let p_top: SMatrix<f64, 2, N> = prior.covariance.fixed_rows::<2>(0).into_owned();
    let a = prior.covariance - gain * p_top;
    let a_left: SMatrix<f64, N, 2> = a.fixed_columns::<2>(0).into_owned();
    let mut covariance = a - a_left * gain.transpose() + gain * r * gain.transpose();
    symmetrize(&mut covariance);
    let mean = prior.mean + gain * innovation;

    let mahalanobis_squared = (innovation.transpose() * s_inverse * innovation)[(0, 0)];
    let log_determinant = 2.0 * (cholesky.l()[(0, 0)].ln() + cholesky.l()[(1, 1)].ln());
    let log_likelihood = -0.5 * mahalanobis_squared - LN_TWO_PI - 0.5 * log_determinant;

    if !log_likelihood.is_finite() || mean.iter().any(|v| !v.is_finite()) {
        return Err(UpdateError);
    }
    Ok(KalmanUpdate {
        posterior: Gaussian { mean, covariance },
        innovation,
        innovation_covariance: s,
        log_likelihood,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix4, Vector4};

    fn spd4() -> Matrix4<f64> {
        let a = Matrix4::new(
            1.0, 0.2, 0.1, 0.0, 0.3, 2.0, 0.0, 0.4, 0.0, 0.1, 1.5, 0.2, 0.1, 0.0, 0.3, 0.8,
        );
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
        let mut cases = vec![Matrix2::zeros(), Matrix2::new(4.0, 0.0, 0.0, 0.0), Matrix2::new(0.0, 0.0, 0.0, 2.5)];
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
            / (2.0 * std::f64::consts::PI * s.determinant().sqrt());
        assert!((update.log_likelihood - density.ln()).abs() < 1e-12);
    }
}
