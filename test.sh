#!/usr/bin/env bash
# Runs every test of primm: the Rust workspace, then the Python tools' tests.
set -euo pipefail
cd "$(dirname "$0")"
cargo test --workspace --locked
if [ -d tools/tests ] && ls tools/tests/test_*.py >/dev/null 2>&1; then
    python3 -m pytest -q tools/tests
fi
