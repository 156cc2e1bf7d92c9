#!/usr/bin/env bash
# Alternating runs of IMM and PR-IMM for the PR-latency figures of docs/BENCHMARKS.md ("PR off
# the critical path"): the service under a fixed-rate load, offline tracking of one sequence,
# and the highest lossless rate. Each run of a series is followed by the other methods' before
# the next, so that a noisy spell hits all of them.
#
#   benches/pr_latency_runs.sh PRIMM SEQUENCE_CSV OUT_DIR [RUNS [DURATION_S [TRIAL_S]]]
#
# PRIMM is a release build of `primm` (target/release/primm); SEQUENCE_CSV a measurement CSV
# (e.g. the robustness preset's evaluation sequence 4: `primm generate --output out/eval_robust
# --split evaluation --preset robustness`, then out/eval_robust/evaluation/evaluation_0004.csv).
# Writes OUT_DIR/service.csv, track.csv, max_rate.csv and the raw outputs beside them.
set -euo pipefail
primm=$1
sequence=$2
out=$3
runs=${4:-5}
duration_s=${5:-10}
trial_s=${6:-5}
mkdir -p "$out"

# Service variants: name and `primm bench-service` arguments.
service_variants=("imm|--method imm" "pr-imm|--method pr-imm" "pr-imm-in-frame|--method pr-imm --no-speculation")
# Offline variants: name and `primm track` arguments.
track_variants=("imm|--method imm" "pr-imm|--method pr-imm" "pr-imm-2-threads|--method pr-imm --inference-threads 2" "pr-imm-4-threads|--method pr-imm --inference-threads 4" "pr-imm-6-threads|--method pr-imm --inference-threads 6")

echo "run,variant,receive_to_publish_p50_us,receive_to_publish_p99_us,learned_wait_p50_us,learned_wait_p99_us,predict_p50_us,frames_sent,frames_lost_client,frames_lost_tracker" >"$out/service.csv"
echo "run,variant,frames,step_seconds,step_p50_us,step_p99_us,tracks_identical_to_synchronous" >"$out/track.csv"

# `| name | count | p50 | p90 | p99 | ...` rows of a bench-service summary.
column() { awk -F'|' -v name="$2" -v col="$3" '$2 ~ "^ "name" $" { gsub(/ /, "", $col); print $col; exit }' "$1"; }

for run in $(seq 1 "$runs"); do
    for variant in "${service_variants[@]}"; do
        name=${variant%%|*}
        directory="$out/service-$name-$run"
        # shellcheck disable=SC2086
        "$primm" bench-service ${variant#*|} --objects 64 --rate-hz 200 --duration-s "$duration_s" \
            --latency-out "$directory" >"$directory.log" 2>&1 || echo "bench-service $name run $run failed" >&2
        summary="$directory/summary.md"
        frames=$(grep -o 'Frames: [0-9]* sent, [0-9]* answered, [0-9]* lost (client), [0-9?]* lost (tracker)' "$summary" || true)
        read -r sent lost_client lost_tracker < <(echo "$frames" | awk '{print $2, $6, $9}')
        echo "$run,$name,$(column "$summary" receive_to_publish 4),$(column "$summary" receive_to_publish 6),$(column "$summary" learned_wait 4),$(column "$summary" learned_wait 6),$(column "$summary" predict 4),$sent,$lost_client,$lost_tracker" >>"$out/service.csv"
    done
    for variant in "${track_variants[@]}"; do
        name=${variant%%|*}
        tracks="$out/tracks-$name-$run.csv"
        # shellcheck disable=SC2086
        json=$("$primm" track --input "$sequence" --output "$tracks" ${variant#*|} --timing "$out/track-$name-$run.ns" 2>/dev/null)
        field() { echo "$json" | grep -o "\"$1\":[0-9.e+-]*" | cut -d: -f2; }
        identical=""
        if [[ $name == pr-imm-*-threads ]]; then
            cmp -s "$tracks" "$out/tracks-pr-imm-$run.csv" && identical=yes || identical=no
        fi
        echo "$run,$name,$(field frames),$(field step_seconds),$(field step_p50_us),$(field step_p99_us),$identical" >>"$out/track.csv"
    done
done
rm -f "$out"/tracks-*.csv

echo "variant,highest_lossless_hz,lowest_lossy_hz" >"$out/max_rate.csv"
for variant in "${service_variants[@]}"; do
    name=${variant%%|*}
    directory="$out/max-rate-$name"
    # shellcheck disable=SC2086
    "$primm" bench-service ${variant#*|} --objects 64 --rate-hz 200 --duration-s 2 --find-max-rate \
        --trial-s "$trial_s" --start-hz 1000 --latency-out "$directory" >"$directory.log" 2>&1 || true
    line=$(grep -o 'trials): \*\*[^*]*\*\*; lowest rate with loss: [^.]*' "$directory/summary.md" || true)
    highest=$(echo "$line" | sed -E 's/.*\*\*([^*]*)\*\*.*/\1/; s/ Hz//')
    lowest=$(echo "$line" | sed -E 's/.*with loss: //; s/ Hz//')
    echo "$name,$highest,$lowest" >>"$out/max_rate.csv"
done
