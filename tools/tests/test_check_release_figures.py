"""Tests of tools/check_release_figures.py: the reports' headline tables are figures of the current release."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[1]
ROOT = TOOLS.parent
sys.path.insert(0, str(TOOLS))

import check_release_figures  # noqa: E402

SCRIPT = TOOLS / "check_release_figures.py"
HEADLINE = "| figure | value |\n|---|---|\n| step | 35.1 µs |\n\n*Measured on primm {release}.*"


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True, check=False)


def make_repository(tmp_path: Path, version: str = "0.2.0", release: str = "0.2.0", body: str = "") -> Path:
    """A copy with the three reports, each opening with a generated headline table of `release`."""
    root = tmp_path / "repo"
    (root / "docs" / "results").mkdir(parents=True)
    (root / "Cargo.toml").write_text(f'[workspace]\nmembers = []\n\n[workspace.package]\nversion = "{version}"\n', encoding="utf-8")
    results = root / "docs" / "results" / "release_headline.csv"
    results.write_text(
        f"# what\n# release: {release}\n# commit: 0123456789abcdef0123456789abcdef01234567\n# measured: 2026-12-04\n"
        "figure,value\nstep,35.1 µs\n",
        encoding="utf-8",
    )
    for report in check_release_figures.REPORTS:
        (root / report).write_text(
            "# Report\n\n<!-- table: docs/results/release_headline.csv -->\n"
            + HEADLINE.format(release=release)
            + "\n<!-- /table -->\n\n## A topic\n\n"
            + body,
            encoding="utf-8",
        )
    return root


def test_the_reports_of_this_repository_pass() -> None:
    result = run()
    assert result.returncode == 0, result.stdout + result.stderr


def test_headlines_of_the_workspace_version_pass(tmp_path: Path) -> None:
    result = run("--root", str(make_repository(tmp_path)))
    assert result.returncode == 0, result.stderr


def test_a_version_bump_without_new_figures_fails(tmp_path: Path) -> None:
    result = run("--root", str(make_repository(tmp_path, version="0.3.0", release="0.2.0")))
    assert result.returncode == 1
    assert result.stderr.count("the headline's figures are of release 0.2.0") == 3, result.stderr


def test_a_hand_written_table_with_figures_fails(tmp_path: Path) -> None:
    body = "| method | RMSE |\n|---|---|\n| IMM | 0.670 m |\n"
    result = run("--root", str(make_repository(tmp_path, body=body)))
    assert result.returncode == 1
    assert "not generated from a results file" in result.stderr


def test_a_hand_written_table_declared_without_measured_figures_passes(tmp_path: Path) -> None:
    body = "<!-- no measured figures -->\n| fault | test |\n|---|---|\n| 1e6 m displacement | `absurd` |\n"
    result = run("--root", str(make_repository(tmp_path, body=body)))
    assert result.returncode == 0, result.stderr


def test_a_hand_written_table_without_figures_passes(tmp_path: Path) -> None:
    body = "| key | what |\n|---|---|\n| `tracker.lifecycle` | how tracks are kept |\n"
    result = run("--root", str(make_repository(tmp_path, body=body)))
    assert result.returncode == 0, result.stderr


def test_a_report_that_opens_with_a_hand_written_table_fails(tmp_path: Path) -> None:
    root = make_repository(tmp_path)
    report = root / "docs" / "EVALUATION.md"
    report.write_text("# Evaluation\n\n| a | b |\n|---|---|\n| x | y |\n\n" + report.read_text(encoding="utf-8"), encoding="utf-8")
    result = run("--root", str(root))
    assert result.returncode == 1
    assert "docs/EVALUATION.md:3: the first table is not generated" in result.stderr


def test_a_results_file_that_names_no_release_fails(tmp_path: Path) -> None:
    root = make_repository(tmp_path)
    results = root / "docs" / "results" / "release_headline.csv"
    results.write_text(results.read_text(encoding="utf-8").replace("# release: 0.2.0\n", ""), encoding="utf-8")
    result = run("--root", str(root))
    assert result.returncode == 1
    assert "records no release or no commit" in result.stderr


def test_a_measurement_of_uncommitted_sources_fails(tmp_path: Path) -> None:
    root = make_repository(tmp_path)
    results = root / "docs" / "results" / "release_headline.csv"
    text = results.read_text(encoding="utf-8")
    results.write_text(text.replace("01234567\n", "01234567+uncommitted\n"), encoding="utf-8")
    result = run("--root", str(root))
    assert result.returncode == 1
    assert "is not a commit hash" in result.stderr


def test_a_commit_outside_the_history_fails() -> None:
    failures = check_release_figures.check_commit(ROOT, "0" * 40, "here", strict=False)
    shallow = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--is-shallow-repository"], capture_output=True, text=True)
    if shallow.returncode == 0 and shallow.stdout.strip() == "false":
        assert failures == [f"here: the commit {'0' * 40} is not in this repository"]
