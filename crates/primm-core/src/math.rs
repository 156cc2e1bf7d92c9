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

/// Square root.
#[inline(always)]
pub fn sqrt(x: f64) -> f64 {
    #[cfg(feature = "std")]
    return x.sqrt();
    #[cfg(not(feature = "std"))]
    return libm::sqrt(x);
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
