//! The library's version and ABI version, queried at run time.
//!
//! The versioning policy is part of the crate documentation (`src/lib.rs`).

use core::ffi::{c_char, CStr};

/// The ABI version of this header (see the crate documentation of primm-ffi for the policy):
/// compare it with `primm_abi_version()`, the ABI version of the linked library.
pub const PRIMM_ABI_VERSION: u32 = 3;

/// The release version of the library, e.g. `0.1.0`.
const VERSION: &CStr = match CStr::from_bytes_with_nul(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes()) {
    Ok(version) => version,
    Err(_) => panic!("the package version holds no NUL byte"),
};

/// The release version of the linked library as `MAJOR.MINOR.PATCH` (a static string; never
/// free it).
#[no_mangle]
pub extern "C" fn primm_version() -> *const c_char {
    VERSION.as_ptr()
}

/// The ABI version the linked library was built with. A program compares it with the
/// `PRIMM_ABI_VERSION` of the header it was compiled against; they differ when the library
/// and the header do not belong together.
#[no_mangle]
pub extern "C" fn primm_abi_version() -> u32 {
    PRIMM_ABI_VERSION
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_version_is_the_package_version_and_the_abi_version_the_constant() {
        // SAFETY: a static NUL-terminated string.
        let version = unsafe { CStr::from_ptr(primm_version()) }.to_str().unwrap();
        assert_eq!(version, env!("CARGO_PKG_VERSION"));
        let parts: Vec<u32> = version.split('.').map(|part| part.parse().unwrap()).collect();
        assert_eq!(parts.len(), 3, "MAJOR.MINOR.PATCH: {version}");
        assert_eq!(primm_abi_version(), PRIMM_ABI_VERSION);
        const { assert!(PRIMM_ABI_VERSION >= 1) };
    }
}
