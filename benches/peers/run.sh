#!/usr/bin/env bash
# primm against Python trackers on the same sequences, scored by one scorer (`primm score`).
#
#   benches/peers/run.sh [SEQUENCES]     (default: all 22 sequences of the evaluation split)
#
# Creates .venv-peers (filterpy, scipy, Stone Soup), builds primm, generates the evaluation split,
# tracks it with primm (cv, imm, pr-imm) and with the peers (benches/peers/peers.py), scores every
# association file with `primm score`, and writes benches/results/peers.md. Every tracker runs
# single-threaded; the timings cover the per-frame tracking loop only (no file I/O).
set -euo pipefail
cd "$(dirname "$0")/../.."
sequences=${1:-22}
out=out/peers
export OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 MKL_NUM_THREADS=1
if [ ! -x .venv-peers/bin/python ]; then
    python3 -m venv .venv-peers
fi
.venv-peers/bin/python -m pip install --quiet -r benches/peers/requirements.txt
cargo build --release --quiet
primm=target/release/primm
rm -rf "$out"
mkdir -p "$out"
"$primm" generate --output "$out/data" --split evaluation > /dev/null
data="$out/data/evaluation"
files=$(ls "$data"/*.csv | head -n "$sequences")

for method in cv imm pr-imm; do
    mkdir -p "$out/$method"
    for file in $files; do
        "$primm" track --input "$file" --output "$out/$method/tracks.csv" --method "$method" \
            --associations "$out/$method/$(basename "$file")" --timing "$out/$method.steps" > /dev/null
    done
    "$primm" score --data "$data" --associations "$out/$method" --sequences "$sequences" --name "primm $method" > "$out/$method.score.json"
done
for peer in filterpy stonesoup; do
    .venv-peers/bin/python benches/peers/peers.py --tracker "$peer" --data "$data" --out "$out/$peer" \
        --sequences "$sequences" --timing "$out/$peer.steps" > /dev/null
    "$primm" score --data "$data" --associations "$out/$peer" --sequences "$sequences" --name "$peer" > "$out/$peer.score.json"
done
.venv-peers/bin/python benches/peers/summarize.py "$out" "$sequences" | tee benches/results/peers.md
