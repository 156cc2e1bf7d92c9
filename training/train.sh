#!/usr/bin/env bash
# Retrains the PR model from scratch: generates the training and validation data of the default,
# turning, clutter and extended presets and of every scenario in training/scenarios/ with primm's
# scenario generator, trains on all of them, and writes models/pr.onnx, models/pr.json and
# models/pr_parity.json.
#
#   training/train.sh [DATA_DIR] [train.py options ...]     (default DATA_DIR: data)
#
# Scenario files named held_out_*.toml and the robustness preset are held out: only their
# validation split is generated, and train.py reports its loss without ever training on it. The default preset's validation
# split selects the epoch. No evaluation split is generated or read.
#
# PYTHON selects the interpreter (default: python3); it needs training/requirements.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
data="${1:-data}"
shift || true
python="${PYTHON:-python3}"
# The default preset's seed base, stated so that pr.json records what the data came from.
seed_base=88314347343104
SECONDS=0

echo "== building primm (release)"
cargo build --release --quiet --bin primm

generate() {  # NAME SPLIT [generate options ...]
  local name="$1" split="$2"
  shift 2
  rm -rf "${data:?}/$name/$split"
  cargo run --release --quiet -- generate --output "$data/$name" --split "$split" "$@" >/dev/null
  echo "   $name/$split: $(ls "$data/$name/$split" | wc -l) sequences"
}

echo "== generating data into $data (${SECONDS} s)"
generate default train --preset default --seed-base "$seed_base"
generate default validation --preset default --seed-base "$seed_base"
sets=(default)
# Presets with their own seed bases: other ego motion, false detections, extended vehicles.
for preset in turning clutter extended; do
  generate "$preset" train --preset "$preset"
  generate "$preset" validation --preset "$preset"
  sets+=("$preset")
done
generate robustness validation --preset robustness
held_out=(robustness)
for file in training/scenarios/*.toml; do
  name="$(basename "$file" .toml)"
  if [[ "$name" == held_out_* ]]; then
    generate "$name" validation --scenario "$file"
    held_out+=("$name")
  else
    generate "$name" train --scenario "$file"
    generate "$name" validation --scenario "$file"
    sets+=("$name")
  fi
done

echo "== training on ${sets[*]}; held out: ${held_out[*]} (${SECONDS} s)"
"$python" training/train.py --data "$data" --out models --data-seed-base "$seed_base" \
  --sets "${sets[@]}" --held-out "${held_out[@]}" --selection-set default --epochs 30 --patience 6 "$@"
echo "== done in ${SECONDS} s"
