#!/usr/bin/env bash
# Installs primm's C and C++ API into PREFIX:
#
#   PREFIX/include/primm.h, primm.hpp        the C header and the C++17 wrapper
#   PREFIX/include/primm_wire.h              the shared-memory payloads, for subscribers in C
#   PREFIX/lib/libprimm_ffi.a                the static library
#   PREFIX/lib/libprimm_ffi.so.ABI           the shared library (soname libprimm_ffi.so.ABI),
#   PREFIX/lib/libprimm_ffi.so -> .so.ABI    ABI being PRIMM_ABI_VERSION of primm.h
#   PREFIX/lib/cmake/primm/                  CMake package: find_package(primm), primm::primm
#   PREFIX/lib/pkgconfig/primm.pc            pkg-config, shared library
#   PREFIX/lib/pkgconfig/primm-static.pc     pkg-config, static library
#
# Usage: tools/install_c_api.sh [--library-dir DIR] PREFIX
#
# Without --library-dir the libraries are built first (`cargo build --release --locked -p
# primm-ffi`, into $CARGO_TARGET_DIR or target/) and taken from its release directory; with it,
# libprimm_ffi.a and libprimm_ffi.so are taken from DIR as they are (the tests install what
# cargo built for them this way). The installed files are relocatable: the CMake and
# pkg-config files find the prefix from their own place. See docs/integrating-c-cpp.md.
set -euo pipefail

usage() {
    echo "usage: $0 [--library-dir DIR] PREFIX" >&2
    exit 2
}

library_dir=""
prefix=""
while [ $# -gt 0 ]; do
    case "$1" in
    --library-dir)
        [ $# -ge 2 ] || usage
        library_dir=$2
        shift 2
        ;;
    -h | --help) usage ;;
    -*)
        echo "install_c_api.sh: unknown option $1" >&2
        usage
        ;;
    *)
        [ -z "$prefix" ] || usage
        prefix=$1
        shift
        ;;
    esac
done
[ -n "$prefix" ] || usage

root=$(cd "$(dirname "$0")/.." && pwd)
templates="$root/tools/c_api"

if [ -z "$library_dir" ]; then
    (cd "$root" && cargo build --release --locked -p primm-ffi)
    target_dir=${CARGO_TARGET_DIR:-$root/target}
    case "$target_dir" in /*) ;; *) target_dir="$root/$target_dir" ;; esac
    library_dir="$target_dir/release"
fi
for library in libprimm_ffi.a libprimm_ffi.so; do
    if [ ! -f "$library_dir/$library" ]; then
        echo "install_c_api.sh: no $library in $library_dir" >&2
        exit 1
    fi
done

abi_version=$(sed -n 's/^#define PRIMM_ABI_VERSION \([0-9][0-9]*\)$/\1/p' "$root/include/primm.h" | head -n 1)
version=$(sed -n '/^\[workspace.package\]/,/^\[/s/^version = "\([^"]*\)"$/\1/p' "$root/Cargo.toml" | head -n 1)
if [ -z "$abi_version" ] || [ -z "$version" ]; then
    echo "install_c_api.sh: cannot read PRIMM_ABI_VERSION from include/primm.h or the version from Cargo.toml" >&2
    exit 1
fi
pointer_bytes=$(getconf LONG_BIT)
pointer_bytes=$((pointer_bytes / 8))

mkdir -p "$prefix/include" "$prefix/lib/cmake/primm" "$prefix/lib/pkgconfig"
install -m 644 "$root/include/primm.h" "$root/include/primm.hpp" "$prefix/include/"
install -m 644 "$root/crates/primm-wire/include/primm_wire.h" "$prefix/include/"
install -m 644 "$library_dir/libprimm_ffi.a" "$prefix/lib/libprimm_ffi.a"
install -m 755 "$library_dir/libprimm_ffi.so" "$prefix/lib/libprimm_ffi.so.$abi_version"
ln -sfn "libprimm_ffi.so.$abi_version" "$prefix/lib/libprimm_ffi.so"

substitute() {
    sed -e "s/@VERSION@/$version/g" -e "s/@ABI_VERSION@/$abi_version/g" -e "s/@SIZEOF_VOID_P@/$pointer_bytes/g" "$1" >"$2"
}
substitute "$templates/primmConfig.cmake.in" "$prefix/lib/cmake/primm/primmConfig.cmake"
substitute "$templates/primmConfigVersion.cmake.in" "$prefix/lib/cmake/primm/primmConfigVersion.cmake"
substitute "$templates/primm.pc.in" "$prefix/lib/pkgconfig/primm.pc"
substitute "$templates/primm-static.pc.in" "$prefix/lib/pkgconfig/primm-static.pc"

echo "install_c_api.sh: primm $version (ABI $abi_version) installed into $prefix"
