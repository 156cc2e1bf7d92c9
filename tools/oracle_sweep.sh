#!/usr/bin/env bash
# What a learned predictor of a given accuracy could give PR-IMM (docs/EVALUATION.md, "How much room
# there is"): for each noise level, PR gets each object's true displacement plus that much
# Gaussian noise per axis (`primm eval --displacement-oracle --displacement-oracle-noise-m`), the
# PR mode's noises and the IMM side are tuned for it on the validation splits only
# (tools/tune_physics.py, as for the shipped model), then every split is scored with both truth
# protocols. About 1.5 minutes per noise level on 2 cores.
#   tools/oracle_sweep.sh [NOISE_M ...]      (default: 0 0.025 0.05 0.1 0.2)
set -euo pipefail
cd "$(dirname "$0")/.."
levels=("$@")
[ ${#levels[@]} -gt 0 ] || levels=(0 0.025 0.05 0.1 0.2)
cargo build --release --quiet
primm=target/release/primm
generate() { # DIR ARGS...: generate unless already there
    local dir=$1; shift
    [ -d "$dir" ] || "$primm" generate --output "${dir%/*}" "$@" > /dev/null
}
generate out/tune/default/validation --split validation --sequences 30
generate out/tune/robust/validation --split validation --preset robustness --sequences 30
generate out/evaluation/data/evaluation --split evaluation
generate out/evaluation/robustness/evaluation --split evaluation --preset robustness
generate out/held_out/evaluation --split evaluation --scenario training/scenarios/held_out_mixed.toml

# The starting point: the shipped configuration with one IMM for all classes.
out=out/tune/oracle
mkdir -p "$out"
python3 -c 'import sys; sys.path.insert(0, "tools"); import tune_physics
open(sys.argv[1], "w").write(tune_physics.without_class_imm(open("config/primm.toml").read()))' "$out/start.toml"

splits=(validation_default:out/tune/default/validation validation_robustness:out/tune/robust/validation
        evaluation_default:out/evaluation/data/evaluation evaluation_robustness:out/evaluation/robustness/evaluation
        evaluation_held_out:out/held_out/evaluation)
for noise in "${levels[@]}"; do
    dir=$out/noise_$noise
    mkdir -p "$dir"
    oracle=(--displacement-oracle --displacement-oracle-noise-m "$noise")
    python3 tools/tune_physics.py --data out/tune/default/validation out/tune/robust/validation \
        --parameters pr-noise --method pr-imm --rounds 2 "${oracle[@]}" --config "$out/start.toml" \
        --out "$dir/pr_noise.toml" > "$dir/pr_noise.log"
    python3 tools/tune_physics.py --data out/tune/default/validation out/tune/robust/validation \
        --parameters imm --rounds 2 "${oracle[@]}" --config "$dir/pr_noise.toml" --out "$dir/imm.toml" > "$dir/imm.log"
    for split in "${splits[@]}"; do
        name=${split%%:*}
        for truth in centre measurement; do
            "$primm" eval --data "${split#*:}" --methods imm,pr,pr-imm "${oracle[@]}" --config "$dir/imm.toml" \
                --truth "$truth" --json "$dir/${name}_$truth.json" > /dev/null 2>&1
        done
    done
done

python3 - "$out" "${levels[@]}" <<'PY'
import json, sys
out, levels = sys.argv[1], sys.argv[2:]
names = ["validation_default", "validation_robustness", "evaluation_default", "evaluation_robustness",
         "evaluation_held_out"]
print("PR-IMM RMSE_xy against the IMM's (centre / measurement truth); PR alone in brackets")
print("noise m/axis | " + " | ".join(names))
for noise in levels:
    cells = []
    for name in names:
        parts = []
        for truth in ("centre", "measurement"):
            methods = json.load(open(f"{out}/noise_{noise}/{name}_{truth}.json"))["methods"]
            imm = methods["imm"]["rmse_xy"]
            parts.append(f"{100 * (methods['pr_imm']['rmse_xy'] / imm - 1):+.1f} % "
                         f"({100 * (methods['pr']['rmse_xy'] / imm - 1):+.1f} %)")
        cells.append(" / ".join(parts))
    print(f"{noise} | " + " | ".join(cells))
PY
