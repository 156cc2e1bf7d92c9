#!/usr/bin/env bash
# Runs every test of primm: the Rust workspace, then the Python tools' tests.
set -euo pipefail
cd "$(dirname "$0")"
if cargo fmt --version >/dev/null 2>&1; then
    cargo fmt --all -- --check # formatting (rustfmt.toml); skipped where rustfmt is not installed
fi
cargo test --workspace --locked
if [ -d tools/tests ] && ls tools/tests/test_*.py >/dev/null 2>&1; then
    python3 -m pytest -q tools/tests
fi
