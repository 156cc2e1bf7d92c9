#!/usr/bin/env python3
"""Tunes the physics modes' process noises and the association gates on validation data.

Coordinate descent over per-class parameters of ``config/primm.toml`` (cars and pedestrians):
the CV acceleration PSD, the CA jerk PSD, the CT acceleration and turn-rate PSDs, the gate and
the initial tangential speed spread. Each parameter in turn is multiplied by every factor of
``--factors`` while the others stay where they are; the best value is kept; the whole round is
repeated ``--rounds`` times. Every candidate is scored by ``primm eval --methods imm`` on each
directory of ``--data`` (validation splits only: the script refuses a directory named
``evaluation``), with the objective

    mean over the directories of  RMSE_xy + idf1_weight * max(0, IDF1_start - IDF1)

(RMSE_xy in metres against the true object centre; IDF1_start: the starting configuration's),
i.e. prior accuracy, without giving up identity. The result is written as a complete TOML
file (the input with the chosen values substituted, comments kept) and a JSON log of every run.

    target/release/primm generate --output out/tune/default --split validation
    target/release/primm generate --output out/tune/turning --split validation --preset turning
    python3 tools/tune_physics.py --data out/tune/default/validation out/tune/turning/validation \\
        --out out/tune/primm.toml

``--parameters learned --method pr-imm`` tunes the learned mode's side instead, on the same
validation-only terms: the factor on the model's own displacement covariance
(``predictor.learned_process_noise_scale``), the likelihood temperature ``imm.likelihood_temperature``
and the constant ``Q_PR`` of cars and pedestrians (used where the model gives no covariance):

    python3 tools/tune_physics.py --data out/tune/default/validation --parameters learned \\
        --method pr-imm --config config/primm.toml --out out/tune/learned.toml

Needs only the Python standard library (3.11+) and a release build of primm.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import tomllib

# (section, key) of every tuned parameter of the physics modes.
PARAMETERS = [
    (f"classes.{cls}{sub}", key)
    for cls in ("car", "pedestrian")
    for sub, key in (
        (".constant_velocity", "acceleration_psd_m2_per_s3"),
        (".constant_acceleration", "jerk_psd_m2_per_s5"),
        (".coordinated_turn", "acceleration_psd_m2_per_s3"),
        (".coordinated_turn", "turn_rate_psd_rad2_per_s3"),
        ("", "gate_m"),
        ("", "initial_tangential_speed_std_mps"),
    )
]


# (section, key) of every tuned parameter of the learned mode and the mode update.
LEARNED_PARAMETERS = [
    ("predictor", "learned_process_noise_scale"),
    ("imm", "likelihood_temperature"),
]

PARAMETER_SETS = {"physics": PARAMETERS, "learned": LEARNED_PARAMETERS}


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--data", nargs="+", required=True, help="validation directories of measurement CSV files")
    parser.add_argument("--config", default="config/primm.toml", help="starting configuration")
    parser.add_argument("--primm", default="target/release/primm", help="the primm binary")
    parser.add_argument("--out", required=True, help="where to write the tuned configuration (TOML)")
    parser.add_argument("--factors", type=float, nargs="+", default=[0.5, 0.7, 1.4, 2.0])
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--idf1-weight", type=float, default=20.0, help="metres of RMSE per unit of IDF1 lost")
    parser.add_argument("--tracking-frame", choices=["world", "vehicle"], default="world")
    parser.add_argument("--parameters", choices=sorted(PARAMETER_SETS), default="physics",
                        help="which parameters to tune")
    parser.add_argument("--method", default="imm", help="the method scored (imm, pr-imm, ...)")
    return parser.parse_args(argv)


def get_value(config: dict, section: str, key: str) -> float:
    node = config
    for part in section.split("."):
        node = node[part]
    return float(node[key])


def substitute(text: str, section: str, key: str, value: float) -> str:
    """``text`` (TOML) with ``key`` of ``[section]`` set to ``value``; comments are kept."""
    lines = text.splitlines(keepends=True)
    current = None
    for index, line in enumerate(lines):
        header = re.match(r"\s*\[([^\[\]]+)\]\s*(#.*)?$", line)
        if header:
            current = header.group(1).strip()
            continue
        if current == section and re.match(rf"\s*{re.escape(key)}\s*=", line):
            comment = line[line.index("#"):].rstrip("\n") if "#" in line else ""
            lines[index] = f"{key} = {value!r}" + (f" {comment}" if comment else "") + "\n"
            return "".join(lines)
    raise KeyError(f"[{section}] {key} not found")


def score(args, text: str) -> dict:
    """The method's RMSE_xy and IDF1 on every data directory for the configuration ``text``."""
    with tempfile.TemporaryDirectory() as tmp:
        config = os.path.join(tmp, "config.toml")
        with open(config, "w") as handle:
            handle.write(text)
        result = {"rmse_xy": [], "idf1": []}
        for data in args.data:
            report = os.path.join(tmp, "report.json")
            subprocess.run(
                [args.primm, "eval", "--data", data, "--methods", args.method, "--config", config,
                 "--tracking-frame", args.tracking_frame, "--json", report],
                check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            )
            with open(report) as handle:
                scored = json.load(handle)["methods"][args.method.replace("-", "_")]
            result["rmse_xy"].append(scored["rmse_xy"])
            result["idf1"].append(scored["idf1"])
    return result


def objective(args, result: dict, start: dict) -> float:
    terms = [
        rmse + args.idf1_weight * max(0.0, idf1_start - idf1)
        for rmse, idf1, idf1_start in zip(result["rmse_xy"], result["idf1"], start["idf1"])
    ]
    return sum(terms) / len(terms)


def main(argv=None) -> int:
    args = parse_args(argv)
    for data in args.data:
        if os.path.basename(os.path.normpath(data)) == "evaluation":
            sys.exit(f"tune_physics: {data} is an evaluation split; tune on validation data only")
    with open(args.config) as handle:
        text = handle.read()
    config = tomllib.loads(text)
    start = score(args, text)
    best = objective(args, start, start)
    log = [{"parameter": None, "value": None, "result": start, "objective": best}]
    print(f"start: objective {best:.4f}  {start}", flush=True)
    for round_index in range(args.rounds):
        for section, key in PARAMETER_SETS[args.parameters]:
            base = get_value(config, section, key)
            for factor in args.factors:
                value = float(f"{base * factor:.4g}")
                candidate = substitute(text, section, key, value)
                result = score(args, candidate)
                value_objective = objective(args, result, start)
                log.append({"parameter": f"{section}.{key}", "value": value, "result": result,
                            "objective": value_objective})
                if value_objective < best - 1e-6:
                    best, text = value_objective, candidate
                    config = tomllib.loads(text)
                    print(f"round {round_index + 1}: {section}.{key} = {value}  objective {best:.4f}  {result}",
                          flush=True)
    with open(args.out, "w") as handle:
        handle.write(text)
    with open(os.path.splitext(args.out)[0] + ".log.json", "w") as handle:
        json.dump(log, handle, indent=1)
    print(f"wrote {args.out} (objective {log[0]['objective']:.4f} -> {best:.4f}, {len(log)} runs)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
