#!/usr/bin/env bash
# The paper's tables for two presets: generates the evaluation split of the default and the
# robustness preset, then runs `primm eval` on both (docs/EVALUATION.md's headline table comes
# from tools/release_figures.sh, which covers six presets).
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
