#!/usr/bin/env bash
# Runs every test of primm: formatting, the Rust workspace, then the Python tools' tests.
#
# Needs what README.md, "Prerequisites", lists (Rust, Python 3 with venv, C and C++ compilers,
# readelf): the Python packages the tests use (tools/requirements-test.txt) are installed into a
# local virtual environment, .venv-test/, on the first run and whenever that file changes.
set -euo pipefail
cd "$(dirname "$0")"

venv=.venv-test
requirements=tools/requirements-test.txt
stamp="$venv/.requirements.sha256"
wanted=$(sha256sum "$requirements" | cut -d' ' -f1)
if [ ! -x "$venv/bin/python3" ] || [ "$(cat "$stamp" 2>/dev/null)" != "$wanted" ]; then
    echo "test.sh: installing the Python test packages into $venv/ ($requirements)"
    python3 -m venv "$venv"
    "$venv/bin/python3" -m pip install --quiet --disable-pip-version-check -r "$requirements"
    echo "$wanted" > "$stamp"
fi
# Every `python3` the tests start is the one of the virtual environment.
export PATH="$PWD/$venv/bin:$PATH"

if cargo fmt --version >/dev/null 2>&1; then
    cargo fmt --all -- --check # formatting (rustfmt.toml); skipped where rustfmt is not installed
fi
# `primm/tunnel`: the host-to-host tunnel (zenoh) and its loopback tests, off in a plain build.
cargo test --workspace --locked --features primm/tunnel
python3 -m pytest -q tools/tests
