#!/usr/bin/env bash
# The tracking thread's p99 with and without a watching Foxglove client, in alternating runs of
# `primm bench-service` (docs/recording.md, "What it costs"). Writes one CSV row per pair:
#   tools/foxglove_view_cost.sh [PAIRS] [SECONDS] > docs/results/recording_view_cost.csv
# The tracker's `receive_to_publish` stage is its whole work on a frame (validation to publish);
# its p99 is read from the `.hgrm` file each run leaves.
set -euo pipefail
pairs=${1:-3}
seconds=${2:-20}
primm=${PRIMM:-target/release/primm}
out=$(mktemp -d)
p99() { awk '$2 ~ /^[0-9.]+$/ && $2 >= 0.99 { print $1; exit }' "$1/receive_to_publish.hgrm"; }
echo "# primm bench-service --rate-hz 200 --objects 64 --duration-s $seconds, alternating without and with"
echo "# --foxglove 127.0.0.1:8765 --foxglove-client; tools/foxglove_view_cost.sh $pairs $seconds, $(date -u +%F)"
echo "pair,receive_to_publish p99 without view (µs),with view and client (µs),ratio with/without"
for pair in $(seq 1 "$pairs"); do
  "$primm" bench-service --rate-hz 200 --objects 64 --duration-s "$seconds" --latency-out "$out/off$pair" > /dev/null
  "$primm" bench-service --rate-hz 200 --objects 64 --duration-s "$seconds" --latency-out "$out/on$pair" \
    --foxglove 127.0.0.1:8765 --foxglove-client > "$out/on$pair.log"
  off=$(p99 "$out/off$pair"); on=$(p99 "$out/on$pair")
  echo "$pair,$off,$on,$(awk -v a="$on" -v b="$off" 'BEGIN { printf "%.2f", a / b }')"
done
rm -rf "$out"
