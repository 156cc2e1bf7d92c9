"""Tests of tools/doc_tables.py: the tables of figures in the docs against their results files."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[1]
ROOT = TOOLS.parent
sys.path.insert(0, str(TOOLS))

import doc_tables  # noqa: E402

SCRIPT = TOOLS / "doc_tables.py"


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True, check=False)


def docs() -> list[Path]:
    return doc_tables.default_docs()


def markers() -> list[tuple[Path, int, str]]:
    found = []
    for doc in docs():
        for number, line in enumerate(doc.read_text(encoding="utf-8").split("\n"), start=1):
            match = doc_tables.BEGIN.match(line)
            if match:
                results, _ = doc_tables.parse_marker(match.group("spec"), f"{doc}:{number}")
                found.append((doc, number, results))
    return found


def test_every_table_in_the_docs_is_what_its_results_file_renders() -> None:
    result = run("--check")
    assert result.returncode == 0, result.stdout + result.stderr


def test_every_marker_names_an_existing_results_file() -> None:
    found = markers()
    assert found, "no table markers in the docs"
    missing = [f"{doc.relative_to(ROOT)}:{line}: {results}" for doc, line, results in found if not (ROOT / results).is_file()]
    assert not missing, missing


def test_the_moved_reports_have_their_tables_generated() -> None:
    counts = {}
    for doc, _, _ in markers():
        counts[doc.name] = counts.get(doc.name, 0) + 1
    for name in ("BENCHMARKS.md", "EVALUATION.md", "RELIABILITY.md"):
        assert counts.get(name, 0) > 0, name


def copy_of_the_repository(tmp_path: Path) -> Path:
    copy = tmp_path / "repo"
    (copy / "docs").mkdir(parents=True)
    for doc in docs():
        target = copy / doc.relative_to(ROOT)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(doc, target)
    for _, _, results in markers():
        target = copy / results
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / results, target)
    return copy


def test_a_changed_figure_fails_the_check_and_write_repairs_it(tmp_path: Path) -> None:
    copy = copy_of_the_repository(tmp_path)
    results = copy / "docs/results/benchmarks_tunnel.csv"
    text = results.read_text(encoding="utf-8")
    assert "2324.5" in text
    results.write_text(text.replace("2324.5", "2325.5"), encoding="utf-8")

    failed = run("--root", str(copy), "--check")
    assert failed.returncode == 1
    assert re.search(r"docs/BENCHMARKS\.md:\d+: the table differs from its results file docs/results/benchmarks_tunnel\.csv", failed.stderr)
    assert "-| tunnel (zenoh, loopback) | tracks | 594.9 | 726.0 | 2324.5 |" in failed.stderr
    assert "+| tunnel (zenoh, loopback) | tracks | 594.9 | 726.0 | 2325.5 |" in failed.stderr

    written = run("--root", str(copy), "--write")
    assert written.returncode == 0, written.stderr
    assert run("--root", str(copy), "--check").returncode == 0
    # Nothing but that one figure changed.
    before = (ROOT / "docs/BENCHMARKS.md").read_text(encoding="utf-8")
    assert (copy / "docs/BENCHMARKS.md").read_text(encoding="utf-8") == before.replace("| 2324.5 |", "| 2325.5 |")


def test_a_results_file_that_names_its_release_is_rendered_with_it_under_the_table(tmp_path: Path) -> None:
    results = tmp_path / "docs" / "results" / "r.csv"
    results.parent.mkdir(parents=True)
    results.write_text(
        "# what was run\n# release: 1.2.3\n# commit: 0123456789abcdef\n# measured: 2026-12-04\na,b\nx,1\n", encoding="utf-8"
    )
    doc = tmp_path / "docs" / "R.md"
    doc.write_text("<!-- table: docs/results/r.csv -->\n<!-- /table -->\n", encoding="utf-8")
    assert run("--root", str(tmp_path), "--write", str(doc)).returncode == 0
    rendered = doc.read_text(encoding="utf-8")
    assert "| x | 1 |\n\n*Measured on primm 1.2.3, commit 0123456789, 2026-12-04.*\n<!-- /table -->" in rendered
    results.write_text(results.read_text(encoding="utf-8").replace("1.2.3", "1.2.4"), encoding="utf-8")
    failed = run("--root", str(tmp_path), "--check", str(doc))
    assert failed.returncode == 1
    assert "+*Measured on primm 1.2.4" in failed.stderr


def test_a_text_results_file_keeps_its_release_lines_out_of_the_fence(tmp_path: Path) -> None:
    (tmp_path / "t.txt").write_text("# primm eval\n# release: 0.2.0\n# commit: abcdef0\nTable II\n", encoding="utf-8")
    doc_tables.ROOT, saved = tmp_path, doc_tables.ROOT
    try:
        lines = doc_tables.render("t.txt", {}, "test")
    finally:
        doc_tables.ROOT = saved
    assert lines == ["```text", "Table II", "```", "", "*Measured on primm 0.2.0, commit abcdef0.*"]


def test_columns_digits_and_labels_select_round_and_relabel(tmp_path: Path) -> None:
    (tmp_path / "r.md").write_text("# r\n\n| a | b | c |\n|---|---|---|\n| x | 7.45 | 1 |\n| y | 2.449 | 2 |\n")
    doc_tables.ROOT, saved = tmp_path, doc_tables.ROOT
    try:
        lines = doc_tables.render("r.md", {"columns": "b=B; a", "digits": "b=1", "labels": "7.5 m; 2.4 m"}, "test")
    finally:
        doc_tables.ROOT = saved
    assert lines == ["| B | a |", "|---|---|", "| 7.5 m | x |", "| 2.4 m | y |"]


def test_a_marker_without_its_closing_line_is_refused(tmp_path: Path) -> None:
    doc = tmp_path / "doc.md"
    doc.write_text("text\n<!-- table: docs/results/x.csv -->\n| a |\n|---|\n")
    result = run("--root", str(tmp_path), "--check", str(doc))
    assert result.returncode == 2
    assert "no closing" in result.stderr
