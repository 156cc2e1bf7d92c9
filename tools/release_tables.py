#!/usr/bin/env python3
"""Writes the release's results files (docs/results/release_*.csv) from what tools/release_figures.sh measured.

tools/release_figures.sh runs the evaluation, the benchmarks and the soak into one directory, then
this script turns their outputs into the CSV results files the reports' tables are rendered from
(tools/doc_tables.py). Every file opens with comment lines naming the release, the commit and the
date of the measurement and the command that made it; tools/check_release_figures.py checks them.

    python3 tools/release_tables.py --measured DIR --release 0.2.0 --commit SHA [--date YYYY-MM-DD]

What DIR holds (each part is optional; a results file is written for every part present):

* ``evaluation/PRESET.json``: ``primm eval --json`` on the evaluation split of a preset;
  ``evaluation/default.txt`` the text tables of the default preset;
* ``timing/PRESET.METHOD.txt``: ``primm track --timing`` over a preset's evaluation sequences
  (one step time in ns per line);
* ``bench_service/METHOD/summary.md``: ``primm bench-service``'s summary per method;
* ``soak_METHOD.txt``: ``primm soak``'s report per method;
* ``host.txt``: one line describing the machine.
"""

from __future__ import annotations

import argparse
import csv
import datetime
import io
import json
import math
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "docs" / "results"
COMMAND = "tools/release_figures.sh"

PRESETS = ("default", "turning", "clutter", "clutter_turning", "extended", "robustness")
METHOD_NAMES = {"cv": "CV", "ca": "CA", "ct": "CT", "pr": "PR", "imm": "IMM", "pr_imm": "PR-IMM", "pr-imm": "PR-IMM"}

# The targets the benchmarks are held to (docs/BENCHMARKS.md), as (limit, better): a measured value
# meets its target when it is at most (better = "lower") or at least (better = "higher") the limit.
TARGET_PR_IMM_STEP_RATIO = 4.0
TARGET_PR_IMM_P99_US = 2000.0
TARGET_PR_IMM_RATE_HZ = 1500.0


class Measured:
    """What one run of tools/release_figures.sh left in its output directory."""

    def __init__(self, directory: Path):
        self.directory = directory

    def path(self, relative: str) -> Path | None:
        path = self.directory / relative
        return path if path.is_file() else None

    def evaluation(self, preset: str) -> dict | None:
        path = self.path(f"evaluation/{preset}.json")
        return json.loads(path.read_text(encoding="utf-8")) if path else None

    def host(self) -> str | None:
        path = self.path("host.txt")
        return path.read_text(encoding="utf-8").strip() if path else None


def number(value: float | None, digits: int) -> str:
    return "–" if value is None else f"{value:.{digits}f}"


def thousands(value: float) -> str:
    return f"{value:,.0f}".replace(",", " ")


def header(release: str, commit: str, date: str, host: str | None, what: str) -> list[str]:
    lines = [f"# {what}", f"# release: {release}", f"# commit: {commit}", f"# measured: {date}", f"# command: {COMMAND}"]
    if host:
        lines.append(f"# host: {host}")
    return lines


def write_csv(name: str, comments: list[str], rows: list[list[str]]) -> Path:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerows(rows)
    path = RESULTS / name
    path.write_text("\n".join(comments) + "\n" + buffer.getvalue(), encoding="utf-8")
    return path


def evaluated_methods(document: dict) -> list[str]:
    order = ("cv", "ca", "ct", "pr", "imm", "pr_imm")
    return [key for key in order if document["methods"].get(key, {}).get("available")]


def evaluation_rows(measured: Measured, methods: tuple[str, ...]) -> list[list[str]]:
    rows = [["preset", "method", "RMSE_xy m", "velocity RMSE m/s", "IDF1", "IDF1, confirmed tracks",
             "false tracks / min", "sequences"]]
    for preset in PRESETS:
        document = measured.evaluation(preset)
        if document is None:
            continue
        for key in evaluated_methods(document):
            if key not in methods:
                continue
            method = document["methods"][key]
            velocity = (method.get("velocity") or {}).get("rmse_mps")
            confirmed = method.get("confirmed_tracks") or {}
            rows.append([preset, METHOD_NAMES[key], number(method["rmse_xy"], 3), number(velocity, 3),
                         number(method["idf1"], 4), number(confirmed.get("idf1"), 4),
                         number(confirmed.get("false_tracks_per_minute"), 2), str(method["counts"]["sequences"])])
    return rows


def write_evaluation(measured: Measured, meta: dict) -> list[Path]:
    written = []
    headline = evaluation_rows(measured, ("cv", "imm", "pr_imm"))
    if len(headline) > 1:
        what = "primm eval on the evaluation split (22 sequences) of each preset, config/primm.toml and models/pr.onnx"
        written.append(write_csv("release_evaluation.csv", header(what=what, **meta), headline))
    text = measured.path("evaluation/default.txt")
    if text is not None:
        what = "primm eval --data out/release/data/default/evaluation (the default preset's evaluation split)"
        path = RESULTS / "release_evaluation_default.txt"
        path.write_text("\n".join(header(what=what, **meta)) + "\n" + text.read_text(encoding="utf-8"), encoding="utf-8")
        written.append(path)
    return written


def percentile(sorted_ns: list[int], q: float) -> float:
    """The nearest-rank percentile in µs, as `primm track --timing` computes it."""
    rank = min(max(math.ceil(q * len(sorted_ns)), 1), len(sorted_ns))
    return sorted_ns[rank - 1] / 1000.0


def read_timing(path: Path) -> list[int]:
    steps = sorted(int(line) for line in path.read_text(encoding="utf-8").split() if line.strip())
    if not steps:
        raise SystemExit(f"release_tables: {path} holds no step times")
    return steps


def step_rows(timings: dict[str, dict[str, list[int]]]) -> list[list[str]]:
    rows = [["preset (evaluation split)", "frames", "IMM step p50 / p99 µs", "PR-IMM step p50 / p99 µs",
             "PR-IMM / IMM, medians", "PR-IMM / IMM, total time"]]
    for preset, methods in timings.items():
        imm, pr_imm = methods.get("imm"), methods.get("pr-imm")
        if not imm or not pr_imm:
            continue
        rows.append([preset, thousands(len(imm)),
                     f"{percentile(imm, 0.5):.1f} / {percentile(imm, 0.99):.1f}",
                     f"{percentile(pr_imm, 0.5):.1f} / {percentile(pr_imm, 0.99):.1f}",
                     f"{percentile(pr_imm, 0.5) / percentile(imm, 0.5):.2f}×",
                     f"{sum(pr_imm) / sum(imm):.2f}×"])
    return rows


SUMMARY_ROW = re.compile(r"^\| (?P<name>[a-z_]+) \| (?P<count>\d+) \| (?P<p50>[\d.]+) \| (?P<p90>[\d.]+) \| (?P<p99>[\d.]+) \| (?P<p999>[\d.]+) \| (?P<max>[\d.]+) \|$")
FRAMES = re.compile(r"^Frames: (?P<sent>\d+) sent, (?P<answered>\d+) answered, (?P<lost_client>\d+) lost \(client\), (?P<lost_tracker>\d+) lost \(tracker\)")
MAX_RATE = re.compile(r"\*\*(?P<rate>[\d.]+) Hz\*\*; lowest rate with loss: (?P<loss>[\d.]+) Hz")


def read_summary(path: Path) -> dict:
    """The latencies (µs), frame counts and highest lossless rate of a bench-service summary."""
    summary = {"latency": {}}
    for line in path.read_text(encoding="utf-8").split("\n"):
        match = SUMMARY_ROW.match(line.strip())
        if match:
            summary["latency"][match.group("name")] = {k: float(v) for k, v in match.groupdict().items() if k != "name"}
        match = FRAMES.match(line)
        if match:
            summary.update({k: int(v) for k, v in match.groupdict().items()})
        match = MAX_RATE.search(line)
        if match:
            summary["max_rate_hz"] = float(match.group("rate"))
            summary["loss_rate_hz"] = float(match.group("loss"))
    return summary


def service_rows(summaries: dict[str, dict]) -> list[list[str]]:
    rows = [["method", "frames sent / answered", "receive → publish p50 / p99 / p99.9 µs",
             "end to end from the schedule p50 / p99 µs", "highest rate without loss"]]
    for method, summary in summaries.items():
        receive = summary["latency"]["receive_to_publish"]
        corrected = summary["latency"]["end_to_end_corrected"]
        rate = summary.get("max_rate_hz")
        rows.append([METHOD_NAMES[method], f"{summary.get('sent', 0)} / {summary.get('answered', 0)}",
                     f"{receive['p50']:.1f} / {receive['p99']:.1f} / {receive['p999']:.1f}",
                     f"{corrected['p50']:.1f} / {corrected['p99']:.1f}",
                     f"{rate:.0f} Hz (loss at {summary['loss_rate_hz']:.0f})" if rate else "–"])
    return rows


def verdict(value: float, limit: float, better: str) -> str:
    met = value <= limit if better == "lower" else value >= limit
    return "met" if met else "**missed**"


def benchmark_headline(timings: dict[str, dict[str, list[int]]], summaries: dict[str, dict]) -> list[list[str]]:
    rows = [["figure (the shipped configuration)", "measured", "target", "verdict"]]
    for preset, methods in timings.items():
        imm, pr_imm = methods.get("imm"), methods.get("pr-imm")
        if not imm or not pr_imm:
            continue
        rows.append([f"IMM step, median, {preset} sequences", f"{percentile(imm, 0.5):.1f} µs", "", ""])
        ratio = sum(pr_imm) / sum(imm)
        rows.append([f"PR-IMM step / IMM step, {preset} sequences (total time, same run)", f"{ratio:.2f}×",
                     f"≤ {TARGET_PR_IMM_STEP_RATIO:.0f}×", verdict(ratio, TARGET_PR_IMM_STEP_RATIO, "lower")])
    for method in ("imm", "pr-imm"):
        summary = summaries.get(method)
        if summary is None:
            continue
        receive = summary["latency"]["receive_to_publish"]
        target = f"≤ {TARGET_PR_IMM_P99_US / 1000:.0f} ms" if method == "pr-imm" else ""
        rows.append([f"{METHOD_NAMES[method]} service, receive → publish p50 / p99 (100 Hz)",
                     f"{receive['p50']:.0f} / {receive['p99']:.0f} µs", target,
                     verdict(receive["p99"], TARGET_PR_IMM_P99_US, "lower") if target else ""])
        if summary.get("max_rate_hz"):
            target = f"≥ {TARGET_PR_IMM_RATE_HZ:.0f} Hz" if method == "pr-imm" else ""
            rows.append([f"{METHOD_NAMES[method]} service, highest rate without a lost frame",
                         f"{summary['max_rate_hz']:.0f} Hz", target,
                         verdict(summary["max_rate_hz"], TARGET_PR_IMM_RATE_HZ, "higher") if target else ""])
    if "imm" in summaries and "pr-imm" in summaries:
        imm_p50 = summaries["imm"]["latency"]["receive_to_publish"]["p50"]
        pr_imm_p50 = summaries["pr-imm"]["latency"]["receive_to_publish"]["p50"]
        rows.append(["PR-IMM / IMM service, receive → publish (medians)", f"{pr_imm_p50 / imm_p50:.2f}×", "", ""])
    return rows


def write_benchmarks(measured: Measured, meta: dict) -> tuple[list[Path], dict[str, dict]]:
    written = []
    timings: dict[str, dict[str, list[int]]] = {}
    for preset in PRESETS:
        for method in ("imm", "pr-imm"):
            path = measured.path(f"timing/{preset}.{method}.txt")
            if path:
                timings.setdefault(preset, {})[method] = read_timing(path)
    if timings:
        what = "primm track --timing on every sequence of the evaluation split, both methods one after the other"
        written.append(write_csv("release_benchmarks_step.csv", header(what=what, **meta), step_rows(timings)))
    summaries = {}
    for method in ("imm", "pr-imm"):
        path = measured.path(f"bench_service/{method}/summary.md")
        if path:
            summaries[method] = read_summary(path)
    if summaries:
        what = "primm bench-service --objects 64 --rate-hz 100 --find-max-rate (its summary.md per method)"
        written.append(write_csv("release_benchmarks_service.csv", header(what=what, **meta), service_rows(summaries)))
    headline = benchmark_headline(timings, summaries)
    if len(headline) > 1:
        what = "primm track --timing on the evaluation sequences, and primm bench-service at 64 objects"
        written.append(write_csv("release_benchmarks.csv", header(what=what, **meta), headline))
    return written, summaries


SOAK_PATTERNS = {
    "frames": re.compile(r"^\s*frames: (\d+) \((\d+) rejected\)"),
    "rss": re.compile(r"^\s*resident set: (.+) at start, (.+) at end"),
    "first": re.compile(r"^\s*step latency, first 10 %: (.+)$"),
    "last": re.compile(r"^\s*step latency, last 10 %: (.+)$"),
    "tracks": re.compile(r"^\s*tracks: (\d+) started, (\d+) deleted, (\d+) live at the end, at most (\d+) live \(bound (\d+)\)"),
    "wall": re.compile(r"^\s*wall time: ([\d.]+) s"),
    "violations": re.compile(r"^\s*invariant violations: (\d+)"),
}


def read_soak(path: Path) -> dict[str, tuple[str, ...]]:
    found = {}
    for line in path.read_text(encoding="utf-8").split("\n"):
        for key, pattern in SOAK_PATTERNS.items():
            match = pattern.match(line)
            if match:
                found[key] = match.groups()
    missing = sorted(set(SOAK_PATTERNS) - set(found))
    if missing:
        raise SystemExit(f"release_tables: {path} lacks {', '.join(missing)} (not a primm soak report?)")
    return found


def write_reliability(measured: Measured, meta: dict, summaries: dict[str, dict]) -> list[Path]:
    soaks = {method: measured.path(f"soak_{method}.txt") for method in ("imm", "pr-imm")}
    soaks = {method: read_soak(path) for method, path in soaks.items() if path}
    rows = [["check (64 objects, the shipped configuration)", "result", "frames", "details"]]
    for method, soak in soaks.items():
        frames, rejected = soak["frames"]
        started, deleted, live, most, bound = soak["tracks"]
        rows.append([f"{METHOD_NAMES[method]} soak: invariant violations", f"**{soak['violations'][0]}**", thousands(int(frames)),
                     f"{rejected} frames rejected; resident set {soak['rss'][0]} → {soak['rss'][1]}; "
                     f"tracks {thousands(int(started))} started, {thousands(int(deleted))} deleted, at most {most} live (bound {bound}); "
                     f"{float(soak['wall'][0]):.0f} s"])
    for method, summary in summaries.items():
        lost = summary.get("lost_client", 0) + summary.get("lost_tracker", 0)
        rows.append([f"{METHOD_NAMES[method]} service at 100 Hz: frames lost", f"**{lost}**", thousands(summary.get("sent", 0)),
                     f"highest rate without loss {summary['max_rate_hz']:.0f} Hz, loss from {summary['loss_rate_hz']:.0f} Hz"
                     if summary.get("max_rate_hz") else ""])
    written = []
    if len(rows) > 1:
        what = "primm soak --objects 64 per method, and primm bench-service at 100 Hz"
        written.append(write_csv("release_reliability.csv", header(what=what, **meta), rows))
    if soaks:
        latency = [["run", "frames", "step latency, first 10 %", "step latency, last 10 %"]]
        for method, soak in soaks.items():
            latency.append([METHOD_NAMES[method], thousands(int(soak["frames"][0])), soak["first"][0], soak["last"][0]])
        what = "primm soak --objects 64: step latency at the start and the end of the run"
        written.append(write_csv("release_reliability_soak.csv", header(what=what, **meta), latency))
    return written


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--measured", type=Path, required=True, help="the output directory of tools/release_figures.sh")
    parser.add_argument("--release", required=True, help="the workspace version the figures were measured on")
    parser.add_argument("--commit", required=True, help="the commit the figures were measured on")
    parser.add_argument("--date", default=datetime.date.today().isoformat())
    args = parser.parse_args(argv)
    measured = Measured(args.measured)
    meta = {"release": args.release, "commit": args.commit, "date": args.date, "host": measured.host()}
    written = write_evaluation(measured, meta)
    benchmark_files, summaries = write_benchmarks(measured, meta)
    written += benchmark_files + write_reliability(measured, meta, summaries)
    for path in written:
        print(f"release_tables: wrote {path.relative_to(ROOT)}")
    if not written:
        print(f"release_tables: nothing measured under {args.measured}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
