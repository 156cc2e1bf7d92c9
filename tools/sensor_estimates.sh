#!/usr/bin/env bash
# How close the tracker's online estimates of its sensors (detection probability, clutter
# density) come to the simulated truth (docs/EVALUATION.md, "What the tracker learns of its
# sensors"): `primm sensor-truth --estimates` on every sequence of SPLIT of seven presets, the
# IMM with the shipped configuration. Writes OUT_DIR/<preset>.csv (a row per sensor, class and
# quantity) and OUT_DIR/sensor_estimates.csv (a row per preset and quantity: scored cells,
# cells within 10 % of the truth, mean relative error) and, with --results, the latter to
# docs/results/sensor_estimates_SPLIT.csv.
#   tools/sensor_estimates.sh [SPLIT] [OUT_DIR] [--results]
# PRIMM_BINARY names a binary to use instead of building one.
set -euo pipefail
cd "$(dirname "$0")/.."
split=${1:-evaluation}
out=${2:-out/sensor_estimates/$split}
results=${3:-}
mkdir -p "$out"
primm=${PRIMM_BINARY:-target/release/primm}
[ -n "${PRIMM_BINARY:-}" ] || cargo build --release --quiet -p primm
presets=(default extended robustness clutter_turning centroid dense_static point_cloud)
for preset in "${presets[@]}"; do
    "$primm" sensor-truth --preset "$preset" --split "$split" --estimates --estimates-csv "$out/$preset.csv" > /dev/null
done
python3 - "$out" "$split" "${presets[@]}" <<'PY'
import csv, math, sys
out, split, presets = sys.argv[1], sys.argv[2], sys.argv[3:]
with open(f"{out}/sensor_estimates.csv", "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["preset", "quantity", "scored_cells", "within_10_percent", "mean_relative_error"])
    for preset in presets:
        rows = list(csv.DictReader(open(f"{out}/{preset}.csv")))
        for quantity in ("detection_probability", "clutter_density"):
            sel = [r for r in rows if r["quantity"] == quantity]
            scored = sum(int(r["scored"]) for r in sel)
            within = sum(int(r["within_tolerance"]) for r in sel)
            errors = [(float(r["mean_relative_error"]), int(r["scored"])) for r in sel
                      if not math.isnan(float(r["mean_relative_error"]))]
            weight = sum(n for _, n in errors)
            mean = sum(e * n for e, n in errors) / weight if weight else float("nan")
            w.writerow([preset, quantity, scored, within, "nan" if math.isnan(mean) else f"{mean:.3f}"])
PY
echo "wrote $out/sensor_estimates.csv"
if [ "$results" = --results ]; then
    target="docs/results/sensor_estimates_$split.csv"
    {
        echo "# tools/sensor_estimates.sh $split: the IMM's estimates at each sequence's end against that sequence's truth, cells with at least 100 samples"
        echo "# release: $(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)"
        echo "# commit: $(git rev-parse HEAD)"
        echo "# measured: $(date -u +%Y-%m-%d)"
        cat "$out/sensor_estimates.csv"
    } > "$target"
    echo "wrote $target"
fi
