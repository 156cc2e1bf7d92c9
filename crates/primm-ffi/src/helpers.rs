//! Entry points that need no tracker: messages, class names, number formatting.

use crate::status::{copy_thread_error, guard_value, PrimmStatus};
use crate::text::{copy_to_c_buffer, FixedText};
use crate::types::PrimmObjectClass;
use core::ffi::{c_char, CStr};
use primm_core::measurement::ObjectClass;

/// The fixed description of a status code (a static string; never free it); "unknown status"
/// for a code that is not a `PrimmStatus`.
#[no_mangle]
pub extern "C" fn primm_status_message(status: i32) -> *const c_char {
    guard_value(c"unknown status".as_ptr(), || {
        PrimmStatus::from_code(status).map_or(c"unknown status", PrimmStatus::message).as_ptr()
    })
}

/// Copies the message of the last failed call on the calling thread (any function, including
/// `primm_tracker_create`) into `buf` (`len` bytes, NUL-terminated, cut if too short; nothing
/// written when `buf` is NULL or `len` is 0) and returns the message's full length in bytes
/// without the NUL, like `snprintf`. Successful calls leave the message as it is.
///
/// # Safety
/// `buf` is NULL or points to `len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn primm_last_error_message(buf: *mut c_char, len: usize) -> usize {
    // SAFETY: forwarded caller contract.
    guard_value(0, || unsafe { copy_thread_error(buf, len) })
}

/// The name of an object class code as the CSV files write it (`car`, `pedestrian`,
/// `two_wheeler`; a static string), or NULL for an unknown code.
#[no_mangle]
pub extern "C" fn primm_object_class_name(class_code: PrimmObjectClass) -> *const c_char {
    guard_value(core::ptr::null(), || match ObjectClass::from_code(class_code) {
        Some(ObjectClass::Car) => c"car".as_ptr(),
        Some(ObjectClass::Pedestrian) => c"pedestrian".as_ptr(),
        Some(ObjectClass::TwoWheeler) => c"two_wheeler".as_ptr(),
        None => core::ptr::null(),
    })
}

/// The class code of a class label (NUL-terminated), or -1 for NULL or a label that names no
/// class. Accepts what `primm track` accepts in a measurement file: the class names (`car`,
/// `pedestrian`, `two_wheeler`) and other data sets' names of the same objects (`truck`, `bus`,
/// `person`, `bicycle`, `motorcycle`, ...), in any letter case, with `-` or a space for `_`,
/// surrounding white space ignored (`ObjectClass::from_label` of primm-core, one mapping for
/// both).
///
/// # Safety
/// `name` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn primm_object_class_from_name(name: *const c_char) -> i32 {
    guard_value(-1, || {
        if name.is_null() {
            return -1;
        }
        // SAFETY: NUL-terminated (caller contract).
        let name = unsafe { CStr::from_ptr(name) };
        name.to_str().ok().and_then(ObjectClass::from_label).map_or(-1, |class| i32::from(class.code()))
    })
}

/// Longest text of an `f64` in Rust's display form: 17 significant digits with up to 307 zeros
/// before them (subnormals), or 309 digits before the point (the largest values), a sign and a
/// point.
const F64_TEXT_CAPACITY: usize = 400;

/// Writes `value` as Rust's `{}` formatting does (the form of every number in primm's CSV
/// files: the shortest decimal that reads back to the same double, never in exponent notation;
/// `1` for 1.0, `0.0000001` for 1e-7, `-0` for negative zero, `NaN`, `inf`, `-inf`) into `buf`
/// (`len` bytes, NUL-terminated, cut if too short; nothing written when `buf` is NULL or `len`
/// is 0). Returns the text's full length in bytes without the NUL, like `snprintf`. Allocates
/// nothing.
///
/// # Safety
/// `buf` is NULL or points to `len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn primm_format_f64(value: f64, buf: *mut c_char, len: usize) -> usize {
    guard_value(0, || {
        let mut text = FixedText::<F64_TEXT_CAPACITY>::new();
        text.set(&value);
        // SAFETY: forwarded caller contract.
        unsafe { copy_to_c_buffer(text.as_str(), buf, len) }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn formatted(value: f64) -> String {
        let mut buf = [0 as c_char; F64_TEXT_CAPACITY + 1];
        // SAFETY: `buf` is writable.
        let len = unsafe { primm_format_f64(value, buf.as_mut_ptr(), buf.len()) };
        // SAFETY: NUL-terminated by the call.
        let text = unsafe { CStr::from_ptr(buf.as_ptr()) }.to_str().unwrap().to_owned();
        assert_eq!(len, text.len());
        text
    }

    #[test]
    fn doubles_are_formatted_exactly_as_rust_displays_them() {
        let values = [
            0.0,
            -0.0,
            1.0,
            -2.5,
            0.1,
            1.0 / 3.0,
            1e-7,
            1.5e300,
            f64::MAX,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE / 3.0,
            5e-324,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for value in values {
            assert_eq!(formatted(value), value.to_string(), "{value:?}");
        }
        assert_eq!(formatted(1.0), "1");
        assert_eq!(formatted(1e-7), "0.0000001");
    }

    #[test]
    fn class_names_and_codes_map_both_ways() {
        for class in ObjectClass::ALL {
            let name = primm_object_class_name(class.code());
            // SAFETY: a static NUL-terminated string.
            assert_eq!(unsafe { CStr::from_ptr(name) }.to_str().unwrap(), class.name());
            // SAFETY: as above.
            assert_eq!(unsafe { primm_object_class_from_name(name) }, i32::from(class.code()));
        }
        assert!(primm_object_class_name(3).is_null());
        // SAFETY: a NUL-terminated literal, and NULL.
        unsafe {
            assert_eq!(primm_object_class_from_name(c"truck".as_ptr()), i32::from(ObjectClass::Car.code()));
            assert_eq!(
                primm_object_class_from_name(c" Person ".as_ptr()),
                i32::from(ObjectClass::Pedestrian.code())
            );
            assert_eq!(primm_object_class_from_name(c"tram".as_ptr()), -1);
            assert_eq!(primm_object_class_from_name(core::ptr::null()), -1);
        }
    }

    #[test]
    fn every_status_has_a_static_message_and_unknown_codes_are_named_so() {
        for status in PrimmStatus::ALL {
            // SAFETY: a static NUL-terminated string.
            let text = unsafe { CStr::from_ptr(primm_status_message(status as i32)) };
            assert_eq!(text, status.message());
        }
        // SAFETY: as above.
        let text = unsafe { CStr::from_ptr(primm_status_message(99)) };
        assert_eq!(text, c"unknown status");
    }
}
