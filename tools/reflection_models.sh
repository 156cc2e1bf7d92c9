#!/usr/bin/env bash
# Scores the three measurement models of a sensor (`reflection = "outline" | "centre" | "auto"`,
# ARCHITECTURE.md "Sensors and their estimates") with the IMM on validation splits, every sensor
# (and the radars without a mount) set to each model in turn; prints one line per preset and model
# and writes OUT_DIR/reflection_models.csv (docs/EVALUATION.md, "One tracker for every radar").
#   tools/reflection_models.sh [OUT_DIR] [SEQUENCES] [PRESET...]
# Defaults: out/reflection_models, 24 sequences, presets default extended robustness
# clutter_turning centroid; PRIMM_BINARY names a binary to use instead of building one.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/reflection_models}
sequences=${2:-24}
shift $(( $# > 2 ? 2 : $# ))
presets=("$@")
[ ${#presets[@]} -gt 0 ] || presets=(default extended robustness clutter_turning centroid)
mkdir -p "$out"
primm=${PRIMM_BINARY:-target/release/primm}
[ -n "${PRIMM_BINARY:-}" ] || cargo build --release --quiet -p primm
for model in outline centre auto; do
    python3 - "$model" "$out/$model.toml" <<'PY'
import sys
model, path = sys.argv[1], sys.argv[2]
text = open("config/primm.toml").read()
text = text.replace('unmounted_reflection = "outline"', f'unmounted_reflection = "{model}"')
text = text.replace("[[frame.sensors]]\n", f'[[frame.sensors]]\nreflection = "{model}"\n')
open(path, "w").write(text)
PY
done
echo "preset,model,rmse_xy_m,car_rmse_xy_m,idf1_confirmed,velocity_rmse_mps" > "$out/reflection_models.csv"
for preset in "${presets[@]}"; do
    [ -d "$out/$preset/validation" ] || "$primm" generate --output "$out/$preset" --split validation --preset "$preset" --sequences "$sequences" > /dev/null
    for model in outline centre auto; do
        "$primm" eval --data "$out/$preset/validation" --methods imm --config "$out/$model.toml" --json "$out/$preset-$model.json" > /dev/null
        python3 - "$out/$preset-$model.json" "$preset" "$model" >> "$out/reflection_models.csv" <<'PY'
import json, sys
imm = json.load(open(sys.argv[1]))["methods"]["imm"]
car = imm["scenarios"]["class_car"]["rmse_xy"]
print(f"{sys.argv[2]},{sys.argv[3]},{imm['rmse_xy']:.4f},{car:.4f},{imm['confirmed_tracks']['idf1']:.4f},{imm['velocity']['rmse_mps']:.3f}")
PY
    done
done
column -s, -t < "$out/reflection_models.csv"
