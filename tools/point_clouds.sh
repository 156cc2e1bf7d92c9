#!/usr/bin/env bash
# Scores the IMM on the generator's point-cloud radars (ARCHITECTURE.md "Point clouds",
# docs/EVALUATION.md "Point clouds") with three sensor settings: the shipped configuration
# (detections = "auto"), config/sensors/point_cloud.toml (every radar "points") and every radar
# "objects" (the tracker without its front end); on the validation split (16 sequences, among
# those the settings were chosen on) and the evaluation split (22), of two presets:
# `point_cloud` and `point_cloud_range` (the same scenes from radars that resolve range finer
# than azimuth). Car RMSE_xy over all rows and over confirmed tracks' rows. Writes
# OUT_DIR/point_clouds.csv and, with --results,
# docs/results/evaluation_point_cloud.csv.
#   tools/point_clouds.sh [OUT_DIR] [--results]
# PRIMM_BINARY names a binary to use instead of building one (the results file then names the
# working tree's commit, so build it from a committed tree).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/point_clouds}
results=${2:-}
mkdir -p "$out"
primm=${PRIMM_BINARY:-target/release/primm}
[ -n "${PRIMM_BINARY:-}" ] || cargo build --release --quiet -p primm
python3 - "$out/objects.toml" <<'PY'
import sys
text = open("config/primm.toml").read()
text = text.replace('unmounted_detections = "auto"', 'unmounted_detections = "objects"')
text = text.replace("[[frame.sensors]]\n", '[[frame.sensors]]\ndetections = "objects"\n')
open(sys.argv[1], "w").write(text)
PY
csv="$out/point_clouds.csv"
echo "preset,split,sensors,idf1_confirmed,confirmed_tracks_per_object_frame,car_rmse_xy_m,car_rmse_xy_confirmed_m,rmse_xy_m,ghost_born_share,id_switches" > "$csv"
for preset in point_cloud point_cloud_range; do
    data="$out/data"
    [ "$preset" = point_cloud ] || data="$out/data_$preset"
    [ -d "$data/validation" ] || "$primm" generate --output "$data" --split validation --preset "$preset" --sequences 16 > /dev/null
    [ -d "$data/evaluation" ] || "$primm" generate --output "$data" --split evaluation --preset "$preset" > /dev/null
    for split in validation evaluation; do
        for setting in shipped points objects; do
            case $setting in
                shipped) config=config/primm.toml ;;
                points) config=config/sensors/point_cloud.toml ;;
                objects) config="$out/objects.toml" ;;
            esac
            json="$out/$preset-$split-$setting.json"
            "$primm" eval --data "$data/$split" --methods imm --config "$config" --json "$json" > /dev/null
            python3 - "$json" "$preset" "$split" "$setting" >> "$csv" <<'PY'
import json, sys
imm = json.load(open(sys.argv[1]))["methods"]["imm"]
c = imm["confirmed_tracks"]
car = imm["scenarios"]["class_car"]
print(f"{sys.argv[2]},{sys.argv[3]},{sys.argv[4]},{c['idf1']:.4f},{c['tracks_per_object_frame']:.3f},{car['rmse_xy']:.3f},{car['confirmed_rmse_xy']:.3f},{imm['rmse_xy']:.3f},{c['ghost_born_share']:.3f},{c['idsw']}")
PY
        done
    done
done
column -s, -t < "$csv"
if [ "$results" = "--results" ]; then
    target=docs/results/evaluation_point_cloud.csv
    {
        echo "# tools/point_clouds.sh $out --results: IMM on the point_cloud and point_cloud_range presets, 16 validation and 22 evaluation sequences, three sensor settings"
        echo "# release: $(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)"
        echo "# commit: $(git rev-parse HEAD)"
        echo "# measured: $(date -u +%Y-%m-%d)"
        cat "$csv"
    } > "$target"
    echo "wrote $target"
fi
