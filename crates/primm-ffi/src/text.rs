//! Fixed-capacity text and copying text into C buffers, without allocating.

use core::ffi::c_char;
use core::fmt;

/// UTF-8 text of at most `N` bytes, written with `write!`; what does not fit is cut at a
/// character boundary.
#[derive(Clone)]
pub(crate) struct FixedText<const N: usize> {
    bytes: [u8; N],
    len: usize,
}

impl<const N: usize> FixedText<N> {
    /// Empty text.
    pub(crate) const fn new() -> Self {
        Self { bytes: [0; N], len: 0 }
    }

    /// Replaces the text with the display form of `value`.
    pub(crate) fn set(&mut self, value: &dyn fmt::Display) {
        self.len = 0;
        let _ = fmt::write(self, format_args!("{value}"));
    }

    /// The text.
    pub(crate) fn as_str(&self) -> &str {
        // `write_str` only ever appends whole characters.
        core::str::from_utf8(&self.bytes[..self.len]).unwrap_or("")
    }
}

impl<const N: usize> fmt::Write for FixedText<N> {
    fn write_str(&mut self, text: &str) -> fmt::Result {
        let mut take = text.len().min(N - self.len);
        while !text.is_char_boundary(take) {
            take -= 1;
        }
        self.bytes[self.len..self.len + take].copy_from_slice(&text.as_bytes()[..take]);
        self.len += take;
        Ok(())
    }
}

impl<const N: usize> fmt::Debug for FixedText<N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.as_str(), f)
    }
}

/// Copies `text` into the C buffer `buf` of `len` bytes, NUL-terminated, cut at a character
/// boundary if it does not fit; writes nothing when `buf` is NULL or `len` is 0. Returns the
/// length of the whole text in bytes (without the NUL), as `snprintf` does: the text was cut
/// when the result is `len` or more.
///
/// # Safety
/// `buf` is NULL or points to `len` writable bytes.
pub(crate) unsafe fn copy_to_c_buffer(text: &str, buf: *mut c_char, len: usize) -> usize {
    if !buf.is_null() && len > 0 {
        let mut take = text.len().min(len - 1);
        while !text.is_char_boundary(take) {
            take -= 1;
        }
        // SAFETY: `take < len` bytes plus the NUL fit in the caller's `len` bytes; `text` does
        // not overlap a buffer the caller owns.
        unsafe {
            core::ptr::copy_nonoverlapping(text.as_ptr(), buf.cast::<u8>(), take);
            *buf.add(take) = 0;
        }
    }
    text.len()
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::fmt::Write as _;

    #[test]
    fn fixed_text_cuts_at_a_character_boundary() {
        let mut text = FixedText::<5>::new();
        write!(text, "ab").unwrap();
        write!(text, "cdé").unwrap();
        assert_eq!(text.as_str(), "abcd");
        text.set(&"xy");
        assert_eq!(text.as_str(), "xy");
    }

    #[test]
    fn copying_into_a_short_c_buffer_cuts_the_text_and_reports_the_full_length() {
        let mut buf = [1 as c_char; 4];
        // SAFETY: `buf` holds 4 writable bytes.
        let len = unsafe { copy_to_c_buffer("hello", buf.as_mut_ptr(), buf.len()) };
        assert_eq!(len, 5);
        assert_eq!(buf.map(|c| c as u8), *b"hel\0");
        // SAFETY: NULL is allowed.
        assert_eq!(unsafe { copy_to_c_buffer("hello", core::ptr::null_mut(), 0) }, 5);
    }
}
