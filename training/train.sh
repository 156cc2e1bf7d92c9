#!/usr/bin/env bash
# Generates the training and validation data with primm's scenario generator, then trains the PR
# model and writes models/pr.onnx, models/pr.json and models/pr_parity.json.
#
#   training/train.sh [DATA_DIR]        (default DATA_DIR: data)
#
# PYTHON selects the interpreter (default: python3); it needs training/requirements.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
data="${1:-data}"
python="${PYTHON:-python3}"
cargo run --release -- generate --output "$data" --split train
cargo run --release -- generate --output "$data" --split validation
"$python" training/train.py --data "$data" --out models
