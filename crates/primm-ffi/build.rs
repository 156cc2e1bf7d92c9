//! Gives the shared library the soname `libprimm_ffi.so.ABI` on Linux, where ABI is
//! `PRIMM_ABI_VERSION` of `src/version.rs` (the versioning policy is documented there).

use std::path::Path;

fn main() {
    let source = Path::new("src/version.rs");
    println!("cargo:rerun-if-changed={}", source.display());
    let text = std::fs::read_to_string(source).expect("src/version.rs is readable");
    let abi_version: u32 = text
        .lines()
        .find_map(|line| line.trim().strip_prefix("pub const PRIMM_ABI_VERSION: u32 = "))
        .and_then(|rest| rest.strip_suffix(';'))
        .and_then(|number| number.parse().ok())
        .expect("src/version.rs defines `pub const PRIMM_ABI_VERSION: u32 = N;`");
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libprimm_ffi.so.{abi_version}");
    }
}
