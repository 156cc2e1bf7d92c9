#!/usr/bin/env bash
# Reproduces docs/EVALUATION.md: generates the evaluation split (default preset) and the robustness
# split (a second generator configuration), then runs `primm eval` on both.
#   tools/evaluate.sh [OUT_DIR]      (default: out/evaluation)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/evaluation}
mkdir -p "$out"
cargo build --release --quiet
primm=target/release/primm
"$primm" generate --output "$out/data" --split evaluation
"$primm" generate --output "$out/robustness" --split evaluation --preset robustness
"$primm" eval --data "$out/data/evaluation" --json "$out/evaluation.json" --plots "$out/figures" | tee "$out/evaluation.txt"
"$primm" eval --data "$out/robustness/evaluation" --methods imm,pr,pr-imm --json "$out/robustness.json" | tee "$out/robustness.txt"
