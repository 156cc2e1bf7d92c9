//! The committed `include/primm.h` is what cbindgen generates from the crate today.
//!
//! cbindgen runs as a library (a dev-dependency pinned to the version that wrote the header),
//! so the check needs no tool installed beside the Rust toolchain. With `PRIMM_WRITE_HEADER`
//! set, the test writes the header first (how the header is regenerated).

use std::path::Path;

const CRATE_DIR: &str = env!("CARGO_MANIFEST_DIR");
const REGENERATE: &str = "PRIMM_WRITE_HEADER=1 cargo test -p primm-ffi --test header";

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
    let header = crate_dir.join("../../include/primm.h");
    if std::env::var_os("PRIMM_WRITE_HEADER").is_some() {
        std::fs::write(&header, &generated).expect("include/primm.h is writable");
    }
    let committed = std::fs::read_to_string(&header).unwrap_or_default();
    assert!(committed == generated, "stale header include/primm.h: run `{REGENERATE}` in the workspace root");
}
