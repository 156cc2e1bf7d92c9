#!/usr/bin/env bash
# Scores the IMM's gate in metres (`association.likelihood_gate_distance_m`) and the platform
# model (`frame.platform`) on validation splits (docs/EVALUATION.md, "Dense scenes from a
# roadside radar"): the shipped configuration and the gates on every preset (dense_static 16
# sequences, the others 8), the platform models on dense_static. Writes OUT_DIR/dense_scenes.csv (a row per preset and setting) and
# OUT_DIR/dense_scenes_table.csv (a row per setting, RMSE_xy m / IDF1 of confirmed tracks per
# preset) and, with --results, the latter to docs/results/evaluation_dense_scenes_validation.csv.
#   tools/dense_scenes.sh [OUT_DIR] [--results]
# PRIMM_BINARY names a binary to use instead of building one.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/dense_scenes}
results=${2:-}
mkdir -p "$out"
primm=${PRIMM_BINARY:-target/release/primm}
[ -n "${PRIMM_BINARY:-}" ] || cargo build --release --quiet -p primm
settings=(none 20 12 10 8 6)
for setting in "${settings[@]}"; do
    gate=$([ "$setting" = none ] && echo inf || echo "$setting.0")
    printf '[association]\nlikelihood_gate_distance_m = %s\n' "$gate" > "$out/gate_$setting.toml"
done
printf '[frame]\nplatform = "moving"\n' > "$out/moving.toml"
printf '[frame]\nplatform = "moving"\n[association]\nlikelihood_gate_distance_m = 10.0\n' > "$out/moving_gate_10.toml"
printf '[frame]\nplatform = "stationary"\n' > "$out/stationary.toml"
csv="$out/dense_scenes.csv"
echo "preset,setting,rmse_xy_m,car_rmse_xy_m,idf1_confirmed" > "$csv"
score() { # preset setting config
    "$primm" eval --data "$out/$1/validation" --methods imm --config "$3" --json "$out/$1-$2.json" > /dev/null
    python3 - "$out/$1-$2.json" "$1" "$2" >> "$csv" <<'PY'
import json, sys
imm = json.load(open(sys.argv[1]))["methods"]["imm"]
car = imm["scenarios"].get("class_car", {}).get("rmse_xy", float("nan"))
print(f"{sys.argv[2]},{sys.argv[3]},{imm['rmse_xy']:.3f},{car:.3f},{imm['confirmed_tracks']['idf1']:.4f}")
PY
}
for preset in dense_static default clutter_turning robustness turning extended centroid point_cloud; do
    sequences=$([ "$preset" = dense_static ] && echo 16 || echo 8)
    [ -d "$out/$preset/validation" ] || "$primm" generate --output "$out/$preset" --split validation --preset "$preset" --sequences "$sequences" > /dev/null
    for setting in "${settings[@]}"; do
        label=$([ "$setting" = none ] && echo "shipped (auto platform; no gate)" || echo "gate $setting")
        score "$preset" "$label" "$out/gate_$setting.toml"
    done
done
score dense_static "platform moving (before)" "$out/moving.toml"
score dense_static "platform moving + gate 10" "$out/moving_gate_10.toml"
score dense_static "platform stationary" "$out/stationary.toml"
score dense_static "roadside.toml (stationary + gate 10)" config/sensors/roadside.toml
# One row per setting, one column per preset: RMSE_xy (m) / IDF1 of confirmed tracks.
python3 - "$csv" "$out/dense_scenes_table.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
presets = list(dict.fromkeys(r["preset"] for r in rows))
settings = list(dict.fromkeys(r["setting"] for r in rows))
cell = {(r["setting"], r["preset"]): f"{r['rmse_xy_m']} / {r['idf1_confirmed']}" for r in rows}
with open(sys.argv[2], "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["setting"] + presets)
    for s in settings:
        w.writerow([s] + [cell.get((s, p), "") for p in presets])
PY
column -s, -t < "$out/dense_scenes_table.csv"
if [ "$results" = "--results" ]; then
    target=docs/results/evaluation_dense_scenes_validation.csv
    {
        echo "# tools/dense_scenes.sh $out --results: IMM on validation splits (dense_static 16 sequences, the others 8), gates in metres and the platform models"
        echo "# release: $(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)"
        echo "# commit: $(git rev-parse HEAD)"
        echo "# measured: $(date -u +%Y-%m-%d)"
        cat "$out/dense_scenes_table.csv"
    } > "$target"
    echo "wrote $target"
fi
