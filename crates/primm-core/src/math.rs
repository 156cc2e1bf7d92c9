//! The few float functions the tracker needs, for both builds: std's with the `std` feature,
//! libm's without it. `core` alone has no transcendental functions.

/// Natural logarithm.
#[inline(always)]
pub fn ln(x: f64) -> f64 {
    #[cfg(feature = "std")]
    return x.ln();
    #[cfg(not(feature = "std"))]
    return libm::log(x);
}

/// `e^x`.
#[inline(always)]
pub fn exp(x: f64) -> f64 {
    #[cfg(feature = "std")]
    return x.exp();
    #[cfg(not(feature = "std"))]
    return libm::exp(x);
}

/// Sine and cosine of `x` (radians), in this order.
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    #[cfg(feature = "std")]
    return x.sin_cos();
    #[cfg(not(feature = "std"))]
    return libm::sincos(x);
}

/// Arc cosine, radians in [0, π] (NaN outside [−1, 1]).
#[inline(always)]
pub fn acos(x: f64) -> f64 {
    #[cfg(feature = "std")]
    return x.acos();
    #[cfg(not(feature = "std"))]
    return libm::acos(x);
}

/// Square root.
#[inline(always)]
pub fn sqrt(x: f64) -> f64 {
    #[cfg(feature = "std")]
    return x.sqrt();
    #[cfg(not(feature = "std"))]
    return libm::sqrt(x);
}

/// Arc tangent of `y / x` in the quadrant of `(x, y)`, radians in [−π, π].
#[inline(always)]
pub fn atan2(y: f64, x: f64) -> f64 {
    #[cfg(feature = "std")]
    return y.atan2(x);
    #[cfg(not(feature = "std"))]
    return libm::atan2(y, x);
}

/// `angle` wrapped into [−π, π], radians.
#[inline]
pub fn wrap_angle(angle: f64) -> f64 {
    let (sin, cos) = sin_cos(angle);
    atan2(sin, cos)
}

/// `x²`.
#[inline(always)]
pub fn square(x: f64) -> f64 {
    x * x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrapped_angles_lie_within_plus_minus_pi_and_keep_their_direction() {
        for angle in [0.0, 3.0, -3.0, 3.2, -3.2, 7.0, -13.0, 100.0] {
            let wrapped = wrap_angle(angle);
            assert!(wrapped.abs() <= core::f64::consts::PI + 1e-12, "{angle} -> {wrapped}");
            assert!((wrapped.sin() - angle.sin()).abs() < 1e-9 && (wrapped.cos() - angle.cos()).abs() < 1e-9);
        }
        assert!((wrap_angle(2.0 * core::f64::consts::PI - 0.1) + 0.1).abs() < 1e-12);
    }

    #[test]
    fn the_functions_agree_with_libm_to_the_last_bits() {
        for i in 0..1000 {
            let x = -20.0 + 0.04 * i as f64;
            assert!((exp(x) - libm::exp(x)).abs() <= 4.0 * f64::EPSILON * libm::exp(x));
            let (s, c) = sin_cos(x);
            let (ls, lc) = libm::sincos(x);
            assert!((s - ls).abs() <= 4.0 * f64::EPSILON && (c - lc).abs() <= 4.0 * f64::EPSILON);
            let y = x.abs() + 1e-3;
            assert!((ln(y) - libm::log(y)).abs() <= 4.0 * f64::EPSILON * libm::log(y).abs().max(1.0));
            assert_eq!(square(x), x * x);
        }
    }
}
