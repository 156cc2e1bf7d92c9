//! Numbers in messages for people: [`ReadableNumber`] shows an `f64` as a plain decimal when
//! its magnitude is ordinary and in scientific notation when it is huge or tiny, so that an
//! error about an absurd input (a frame interval of 1e300 s) prints `1.0e300` instead of a
//! number 301 digits long.
//!
//! Both forms are Rust's shortest representation that reads back as the same `f64`, so two
//! different values never print alike (a message such as "timestamp … does not advance past
//! …" stays meaningful). A precision (`{:.1}`) applies to either form: digits after the point,
//! or of the mantissa. Formatting needs neither `std` nor an allocator.
//!
//! ```
//! use primm_core::readable_number::readable;
//!
//! assert_eq!(readable(1.0e300).to_string(), "1.0e300");
//! assert_eq!(readable(-2.5e-9).to_string(), "-2.5e-9");
//! assert_eq!(readable(0.05).to_string(), "0.05");
//! assert_eq!(readable(1_733_030_400.25).to_string(), "1733030400.25");
//! assert_eq!(readable(f64::NAN).to_string(), "NaN");
//! ```

use core::borrow::Borrow;
use core::fmt;

/// Smallest magnitude shown as a plain decimal (below it: scientific notation, except zero).
pub const PLAIN_MIN_MAGNITUDE: f64 = 1.0e-5;
/// Magnitude from which a number is shown in scientific notation. Below it a plain decimal has
/// at most 16 digits before the point.
pub const PLAIN_MAX_MAGNITUDE: f64 = 1.0e16;

/// An `f64` formatted for people (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReadableNumber(pub f64);

/// `value` formatted for people. Takes a value or a reference, so that it applies directly to
/// the fields of an error in a `#[error(...)]` format.
pub fn readable(value: impl Borrow<f64>) -> ReadableNumber {
    ReadableNumber(*value.borrow())
}

impl fmt::Display for ReadableNumber {
    fn fmt(&self, formatter: &mut fmt::Formatter<'_>) -> fmt::Result {
        let value = self.0;
        let magnitude = value.abs();
        let plain = !value.is_finite()
            || value == 0.0
            || (PLAIN_MIN_MAGNITUDE..PLAIN_MAX_MAGNITUDE).contains(&magnitude);
        match (plain, formatter.precision()) {
            (true, None) => return write!(formatter, "{value}"),
            (true, Some(precision)) => return write!(formatter, "{value:.precision$}"),
            (false, _) => {}
        }
        // Scientific notation; `{:e}` writes a whole mantissa without its ".0" (1e300), which
        // reads as a typo in a message, so the mantissa always gets a fractional part.
        let mut buffer = StackText::default();
        match formatter.precision() {
            None => fmt::Write::write_fmt(&mut buffer, format_args!("{value:e}"))?,
            Some(precision) => fmt::Write::write_fmt(&mut buffer, format_args!("{value:.precision$e}"))?,
        }
        let text = buffer.as_str();
        match text.split_once('e') {
            Some((mantissa, exponent)) if !mantissa.contains('.') => {
                write!(formatter, "{mantissa}.0e{exponent}")
            }
            _ => formatter.write_str(text),
        }
    }
}

/// Capacity of [`StackText`]: the longest `{:e}` form of an `f64` is 24 bytes
/// (`-2.2250738585072014e-308`); with a precision, the digits asked for are added.
const STACK_TEXT_CAPACITY: usize = 64;

/// A fixed buffer to format into without allocating.
struct StackText {
    bytes: [u8; STACK_TEXT_CAPACITY],
    length: usize,
}

impl Default for StackText {
    fn default() -> Self {
        Self { bytes: [0; STACK_TEXT_CAPACITY], length: 0 }
    }
}

impl StackText {
    fn as_str(&self) -> &str {
        // Only whole `&str`s are ever appended, so the bytes are valid UTF-8.
        core::str::from_utf8(&self.bytes[..self.length]).unwrap_or("")
    }
}

impl fmt::Write for StackText {
    fn write_str(&mut self, text: &str) -> fmt::Result {
        let end = self.length + text.len();
        let slot = self.bytes.get_mut(self.length..end).ok_or(fmt::Error)?;
        slot.copy_from_slice(text.as_bytes());
        self.length = end;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::format;
    use alloc::string::ToString;

    #[test]
    fn huge_and_tiny_magnitudes_are_shown_in_scientific_notation_with_a_fractional_mantissa() {
        assert_eq!(readable(1.0e300).to_string(), "1.0e300");
        assert_eq!(readable(-1.0e300).to_string(), "-1.0e300");
        assert_eq!(readable(1.5e20).to_string(), "1.5e20");
        assert_eq!(readable(3.0e-7).to_string(), "3.0e-7");
        assert_eq!(readable(f64::MAX).to_string(), "1.7976931348623157e308");
        assert_eq!(readable(-f64::MIN_POSITIVE).to_string(), "-2.2250738585072014e-308");
        assert_eq!(readable(5.0e-324).to_string(), "5.0e-324");
    }

    #[test]
    fn ordinary_magnitudes_are_shown_as_plain_decimals() {
        assert_eq!(readable(0.0).to_string(), "0");
        assert_eq!(readable(-0.05).to_string(), "-0.05");
        assert_eq!(readable(2.0).to_string(), "2");
        assert_eq!(readable(0.1 + 0.2).to_string(), "0.30000000000000004");
        assert_eq!(readable(PLAIN_MIN_MAGNITUDE).to_string(), "0.00001");
        assert_eq!(readable(9.0e15).to_string(), "9000000000000000");
    }

    #[test]
    fn a_precision_applies_to_both_forms() {
        assert_eq!(format!("{:.1}", readable(123.456)), "123.5");
        assert_eq!(format!("{:.1}", readable(1.0e300)), "1.0e300");
        assert_eq!(format!("{:.2}", readable(-4.567e-9)), "-4.57e-9");
    }

    #[test]
    fn non_finite_values_are_named() {
        assert_eq!(readable(f64::NAN).to_string(), "NaN");
        assert_eq!(readable(f64::INFINITY).to_string(), "inf");
        assert_eq!(readable(f64::NEG_INFINITY).to_string(), "-inf");
    }

    #[test]
    fn every_shown_number_reads_back_as_the_same_value() {
        let mut value = 1.0e-320_f64;
        while value < 1.0e300 {
            for sign in [1.0, -1.0] {
                let text = readable(sign * value).to_string();
                assert!(text.len() <= 25, "{text}");
                assert_eq!(text.parse::<f64>().unwrap(), sign * value, "{text}");
            }
            value *= 7.3;
        }
    }

    #[test]
    fn a_frame_interval_error_shows_an_absurd_interval_in_scientific_notation() {
        let error = crate::validation::FrameError::IntervalTooLong { interval_s: 1.0e300, max_s: 5.0 };
        assert_eq!(error.to_string(), "frame interval 1.0e300 s exceeds the maximum of 5 s");
    }

    #[test]
    fn a_reference_formats_like_the_value() {
        let interval_s = 1.0e300;
        let field: &f64 = &interval_s;
        assert_eq!(readable(field), readable(interval_s));
    }
}
