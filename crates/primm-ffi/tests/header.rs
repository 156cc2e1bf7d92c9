//! The committed `include/primm.h` is what cbindgen generates from the crate today.
//!
//! cbindgen runs as a library (a dev-dependency pinned to the version that wrote the header),
//! so the check needs no tool installed beside the Rust toolchain.

use std::path::Path;

const CRATE_DIR: &str = env!("CARGO_MANIFEST_DIR");
const REGENERATE: &str =
    "cargo install cbindgen --locked --version 0.29.4 && cbindgen --config crates/primm-ffi/cbindgen.toml --crate primm-ffi --output include/primm.h";

#[test]
fn the_committed_header_is_what_cbindgen_generates() {
    let crate_dir = Path::new(CRATE_DIR);
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).expect("cbindgen.toml parses");
    let bindings = cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header");
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = String::from_utf8(generated).unwrap();
    let committed = std::fs::read_to_string(crate_dir.join("../../include/primm.h")).unwrap_or_default();
    assert!(committed == generated, "stale header include/primm.h: run `{REGENERATE}` in the workspace root");
}
