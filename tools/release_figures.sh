#!/usr/bin/env bash
# Measures the figures of the reports' headline tables on the shipped defaults (config/primm.toml,
# models/pr.onnx) and rewrites their results files (docs/results/release_*.csv) and the tables:
#
#   tools/release_figures.sh [--part evaluation|benchmarks|reliability]... [OUT_DIR]
#
# (default: every part, into out/release). One command for a release: run it on the release's
# tree after the last change to the tracker, then commit docs/. Each results file records the
# workspace's version and the commit measured (tools/check_release_figures.py, run by ./test.sh,
# fails when the headline tables are of another version; with --strict also when the tracker's
# sources changed since). The sources must be committed: the figures describe a commit.
#
# What it runs, in a release build:
#   evaluation   primm generate --split evaluation --preset P, then primm eval --json, for the
#                six presets, default, turning, clutter, clutter_turning, extended and
#                robustness (methods cv, imm, pr-imm; the default preset with every method)
#   benchmarks   primm track --timing on every evaluation sequence of the default and robustness
#                presets (imm and pr-imm), and primm bench-service --objects 64 --rate-hz 100
#                --duration-s 20 --find-max-rate for imm and pr-imm
#   reliability  primm soak --objects 64 --frames SOAK_FRAMES (default 200 000) for imm and
#                pr-imm; the service rows come from the benchmarks
# Latencies depend on the host and on what else runs on it: run it on a quiet machine.
# Environment: SOAK_FRAMES (default 200000); PRIMM_BINARY (a primm binary built from this tree);
# RELEASE_FIGURES_ALLOW_DIRTY=1 (a trial run on uncommitted sources, recorded as such).
set -euo pipefail
cd "$(dirname "$0")/.."

parts=()
out=out/release
while [ $# -gt 0 ]; do
    case "$1" in
        --part) parts+=("$2"); shift 2 ;;
        -h|--help) sed -n '2,24p' "$0"; exit 0 ;;
        *) out=$1; shift ;;
    esac
done
[ ${#parts[@]} -gt 0 ] || parts=(evaluation benchmarks reliability)
wants() { [[ " ${parts[*]} " == *" $1 "* ]]; }

# What the figures depend on (the benchmarks' own result files excepted: step_growth rewrites them).
sources=(crates src config models Cargo.lock Cargo.toml publisher subscriber benches ':!benches/results')
if [ -n "$(git status --porcelain -- "${sources[@]}")" ] && [ "${RELEASE_FIGURES_ALLOW_DIRTY:-0}" != 1 ]; then
    echo "release_figures: uncommitted changes under ${sources[*]}; commit first (the figures name a commit)," >&2
    echo "or set RELEASE_FIGURES_ALLOW_DIRTY=1 for a trial run (the files then say +uncommitted)" >&2
    git status --short -- "${sources[@]}" >&2
    exit 1
fi
commit=$(git rev-parse HEAD)
release=$(python3 -c 'import sys; sys.path.insert(0, "tools"); import check_release_figures as c, pathlib; print(c.workspace_version(pathlib.Path(".")))')
mkdir -p "$out"
echo "$(nproc) logical CPUs ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)), load average $(cut -d' ' -f1 /proc/loadavg) at the start" > "$out/host.txt"

started=$SECONDS
step() { echo "release_figures: $* ($((SECONDS - started)) s)"; }
# PRIMM_BINARY: a primm built from this same tree elsewhere (skips the build here).
primm=${PRIMM_BINARY:-target/release/primm}
[ -n "${PRIMM_BINARY:-}" ] || cargo build --release --quiet --workspace --bins

if wants evaluation; then
    mkdir -p "$out/evaluation"
    for preset in default turning clutter clutter_turning extended robustness; do
        step "evaluation, preset $preset"
        "$primm" generate --output "$out/data/$preset" --split evaluation --preset "$preset" >/dev/null
        methods=cv,imm,pr-imm
        [ "$preset" = default ] && methods=cv,ca,ct,pr,imm,pr-imm
        "$primm" eval --data "$out/data/$preset/evaluation" --methods "$methods" \
            --json "$out/evaluation/$preset.json" > "$out/evaluation/$preset.txt"
    done
fi

if wants benchmarks; then
    # The tracker's step on recorded sequences: every evaluation sequence of two presets through
    # `primm track --timing` (offline: the PR model runs on the tracking thread), both methods.
    mkdir -p "$out/timing"
    for preset in default robustness; do
        [ -d "$out/data/$preset/evaluation" ] ||
            "$primm" generate --output "$out/data/$preset" --split evaluation --preset "$preset" >/dev/null
        for method in imm pr-imm; do
            step "benchmarks: primm track --timing, preset $preset, $method"
            rm -f "$out/timing/$preset.$method.txt"
            for sequence in "$out/data/$preset/evaluation"/*.csv; do
                "$primm" track --input "$sequence" --output "$out/timing/tracks.csv" --method "$method" \
                    --timing "$out/timing/$preset.$method.txt" >/dev/null 2>&1
            done
        done
    done
    for method in imm pr-imm; do
        step "benchmarks: bench-service $method"
        rm -rf "$out/bench_service/$method"
        "$primm" bench-service --method "$method" --objects 64 --rate-hz 100 --duration-s 20 \
            --find-max-rate --trial-s 3 --steps 3 --latency-out "$out/bench_service/$method" > "$out/bench_service_$method.log" 2>&1
    done
fi

if wants reliability; then
    # A soak that finds violations exits 1; its report (with the count) is the figure, so the
    # script goes on (the violations themselves are on stderr, kept in soak_METHOD.log).
    for method in imm pr-imm; do
        step "reliability: soak $method"
        seed=1; [ "$method" = pr-imm ] && seed=3
        "$primm" soak --method "$method" --frames "${SOAK_FRAMES:-200000}" --objects 64 --seed "$seed" \
            > "$out/soak_$method.txt" 2> "$out/soak_$method.log" || true
    done
fi

[ -z "$(git status --porcelain -- "${sources[@]}")" ] || commit="$commit+uncommitted"
step "tables"
python3 tools/release_tables.py --measured "$out" --release "$release" --commit "$commit"
python3 tools/doc_tables.py --write
step "done: release $release, commit ${commit:0:10}"
