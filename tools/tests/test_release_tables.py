"""Tests of tools/release_tables.py: the release's results files from what tools/release_figures.sh measured."""

from __future__ import annotations

import json
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
    shutil.copy(ROOT / "benches/results/step_growth.json", directory / "step_growth.json")
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


def test_the_step_table_divides_pr_imm_by_imm_at_each_count() -> None:
    step_growth = json.loads((ROOT / "benches/results/step_growth.json").read_text(encoding="utf-8"))
    rows = release_tables.step_rows(step_growth)
    imm = next(row for row in step_growth if row["method"] == "imm" and row["objects"] == 64)
    pr_imm = next(row for row in step_growth if row["method"] == "pr-imm" and row["objects"] == 64)
    row64 = next(row for row in rows if row[0] == "64")
    assert row64[-1] == f"{pr_imm['step_p50_us'] / imm['step_p50_us']:.2f}×"


def test_a_missed_target_is_marked_missed() -> None:
    step_growth = [
        {"method": "imm", "objects": 64, "step_p50_us": 40.0},
        {"method": "pr-imm", "objects": 64, "step_p50_us": 200.0},
    ]
    rows = release_tables.benchmark_headline(step_growth, {})
    ratio = next(row for row in rows if row[0].startswith("PR-IMM step / IMM step"))
    assert ratio[1:] == ["5.00×", "≤ 4×", "**missed**"]
    imm = next(row for row in rows if row[0] == "IMM step, median")
    assert imm[-1] == "met"


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
