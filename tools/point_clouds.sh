#!/usr/bin/env bash
# Scores the IMM on the generator's point-cloud radars (`point_cloud` preset; ARCHITECTURE.md
# "Point clouds", docs/EVALUATION.md "Point clouds") with three sensor settings: the shipped
# configuration (detections = "auto"), config/sensors/point_cloud.toml (every radar "points") and
# every radar "objects" (the tracker without its front end); on the validation split (16
# sequences, where the settings were chosen) and the evaluation split (22). Writes
# OUT_DIR/point_clouds.csv and, with --results, docs/results/evaluation_point_cloud.csv.
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
[ -d "$out/data/validation" ] || "$primm" generate --output "$out/data" --split validation --preset point_cloud --sequences 16 > /dev/null
[ -d "$out/data/evaluation" ] || "$primm" generate --output "$out/data" --split evaluation --preset point_cloud > /dev/null
csv="$out/point_clouds.csv"
echo "split,sensors,idf1_confirmed,confirmed_tracks_per_object_frame,car_rmse_xy_m,rmse_xy_m,ghost_born_share,id_switches" > "$csv"
for split in validation evaluation; do
    for setting in shipped points objects; do
        case $setting in
            shipped) config=config/primm.toml ;;
            points) config=config/sensors/point_cloud.toml ;;
            objects) config="$out/objects.toml" ;;
        esac
        "$primm" eval --data "$out/data/$split" --methods imm --config "$config" --json "$out/$split-$setting.json" > /dev/null
        python3 - "$out/$split-$setting.json" "$split" "$setting" >> "$csv" <<'PY'
import json, sys
imm = json.load(open(sys.argv[1]))["methods"]["imm"]
c = imm["confirmed_tracks"]
car = imm["scenarios"]["class_car"]["rmse_xy"]
print(f"{sys.argv[2]},{sys.argv[3]},{c['idf1']:.4f},{c['tracks_per_object_frame']:.3f},{car:.3f},{imm['rmse_xy']:.3f},{c['ghost_born_share']:.3f},{c['idsw']}")
PY
    done
done
column -s, -t < "$csv"
if [ "$results" = "--results" ]; then
    target=docs/results/evaluation_point_cloud.csv
    {
        echo "# tools/point_clouds.sh $out --results: IMM on the point_cloud preset, 16 validation and 22 evaluation sequences, three sensor settings"
        echo "# release: $(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)"
        echo "# commit: $(git rev-parse HEAD)"
        echo "# measured: $(date -u +%Y-%m-%d)"
        cat "$csv"
    } > "$target"
    echo "wrote $target"
fi
