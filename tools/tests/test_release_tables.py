"""Tests of tools/release_tables.py: the release's results files from what tools/release_figures.sh measured."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import pytest

TOOLS = Path(__file__).resolve().parents[1]
ROOT = TOOLS.parent
sys.path.insert(0, str(TOOLS))

import doc_tables  # noqa: E402
import release_tables  # noqa: E402

SOAK = """soak report
  method: imm (no learned predictor)
  frames: 200000 (0 rejected), seed 1
  objects in view: 64 (8123 replaced after leaving the scene)
  resident set: 12.4 MiB at start, 12.6 MiB at end
  step latency, first 10 %: p50 61.0 µs, p90 80.1 µs, p99 120.3 µs, max 900.2 µs (20000 frames)
  step latency, last 10 %: p50 60.2 µs, p90 79.0 µs, p99 118.0 µs, max 850.0 µs (20000 frames)
  tracks: 420000 started, 419900 deleted, 80 live at the end, at most 91 live (bound 512)
  learned predictions: 0 missing, 0 rejected non-finite, 0 rejected implausible, 0 rejected for their covariance
  wall time: 14.2 s
  invariant violations: 0
"""


@pytest.fixture
def measured(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    directory = tmp_path / "measured"
    (directory / "bench_service" / "imm").mkdir(parents=True)
    shutil.copy(ROOT / "benches/results/bench_service/imm/summary.md", directory / "bench_service/imm/summary.md")
    (directory / "timing").mkdir()
    (directory / "timing" / "default.imm.txt").write_text("\n".join(str(ns) for ns in range(1000, 11000, 10)) + "\n")
    (directory / "timing" / "default.pr-imm.txt").write_text("\n".join(str(3 * ns) for ns in range(1000, 11000, 10)) + "\n")
    (directory / "soak_imm.txt").write_text(SOAK, encoding="utf-8")
    results = tmp_path / "results"
    results.mkdir()
    monkeypatch.setattr(release_tables, "RESULTS", results)
    monkeypatch.setattr(release_tables, "ROOT", tmp_path)
    return directory


def test_a_bench_service_summary_gives_its_latencies_losses_and_highest_rate() -> None:
    summary = release_tables.read_summary(ROOT / "benches/results/bench_service/imm/summary.md")
    assert summary["latency"]["receive_to_publish"]["p99"] == pytest.approx(236.9)
    assert summary["sent"] == 3000 and summary["lost_client"] == 0 and summary["lost_tracker"] == 0
    assert summary["max_rate_hz"] == 11200 and summary["loss_rate_hz"] == 12000


def test_the_step_table_gives_nearest_rank_percentiles_and_both_ratios() -> None:
    imm = list(range(1000, 101000, 1000))  # 1 ... 100 µs
    pr_imm = [3 * ns for ns in imm]
    rows = release_tables.step_rows({"default": {"imm": imm, "pr-imm": pr_imm}})
    assert rows[1] == ["default", "100", "50.0 / 99.0", "150.0 / 297.0", "3.00×", "3.00×"]


def test_a_missed_target_is_marked_missed() -> None:
    timings = {"robustness": {"imm": [40_000] * 10, "pr-imm": [200_000] * 10}}
    rows = release_tables.benchmark_headline(timings, {})
    ratio = next(row for row in rows if row[0].startswith("PR-IMM step / IMM step"))
    assert ratio[1:] == ["5.00×", "≤ 4×", "**missed**"]
    timings = {"robustness": {"imm": [40_000] * 10, "pr-imm": [120_000] * 10}}
    ratio = next(row for row in release_tables.benchmark_headline(timings, {}) if row[0].startswith("PR-IMM step"))
    assert ratio[-1] == "met"


def test_every_written_file_names_release_and_commit_and_renders(measured: Path) -> None:
    assert release_tables.main(["--measured", str(measured), "--release", "9.8.7", "--commit", "abcdef1234", "--date", "2026-12-04"]) == 0
    written = sorted(release_tables.RESULTS.iterdir())
    assert [path.name for path in written] == [
        "release_benchmarks.csv",
        "release_benchmarks_service.csv",
        "release_benchmarks_step.csv",
        "release_reliability.csv",
        "release_reliability_soak.csv",
    ]
    for path in written:
        metadata = doc_tables.read_metadata(path)
        assert metadata["release"] == "9.8.7" and metadata["commit"] == "abcdef1234", path
        rows = doc_tables.read_csv(path)
        assert len(rows) > 1 and all(len(row) == len(rows[0]) for row in rows), path
    reliability = doc_tables.read_csv(release_tables.RESULTS / "release_reliability.csv")
    assert reliability[1][:3] == ["IMM soak: invariant violations", "**0**", "200 000"]


def test_a_soak_report_missing_its_verdict_is_refused(measured: Path) -> None:
    (measured / "soak_imm.txt").write_text(SOAK.replace("  invariant violations: 0\n", ""), encoding="utf-8")
    with pytest.raises(SystemExit, match="lacks violations"):
        release_tables.main(["--measured", str(measured), "--release", "1.0.0", "--commit", "abcdef1"])
