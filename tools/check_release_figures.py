#!/usr/bin/env python3
"""Checks that the reports' tables carry figures of the release they describe.

The three reports, docs/EVALUATION.md, docs/BENCHMARKS.md and docs/RELIABILITY.md, each open with
a headline table of the current release. Every figure in their tables is generated from a results
file by tools/doc_tables.py, and every such results file records, in comment lines at its top, the
release it was measured on and the commit (``# release: 0.2.0``, ``# commit: SHA``;
tools/release_figures.sh writes them). This script fails when

* a report's first table is not generated from a results file, or that file's release is not the
  workspace's version (``[workspace.package] version`` in Cargo.toml): the headline describes the
  current release, so a version bump without a new measurement fails here;
* a generated table of a report comes from a results file that records no release or no commit,
  or a release newer than the workspace's (tables of an earlier release are allowed below the
  headline; doc_tables renders the release, commit and date under each of them);
* a table of a report that is not generated carries a digit in its rows, unless the line
  before it is ``<!-- no measured figures -->`` (a table of tests or options whose numbers are
  inputs, not measurements): measured figures are not kept by hand;
* the recorded commit is not a commit of this repository's history (checked where git and the
  repository's history are at hand);
* with ``--strict``, the tracker's sources (crates/, src/, config/, models/, Cargo.lock) differ
  between the headline's commit and HEAD: the figures predate the code. Run before a release
  (after tools/release_figures.sh); ./test.sh runs the check without it, so that a change to the
  tracker does not have to re-measure everything in the same commit.

    python3 tools/check_release_figures.py [--strict] [--root DIR]

Exit status 0 when every check holds, 1 with one line per failure otherwise.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import doc_tables  # noqa: E402

REPORTS = ("docs/EVALUATION.md", "docs/BENCHMARKS.md", "docs/RELIABILITY.md")
# What the figures depend on: a change here since the headline's commit makes them stale (--strict).
SOURCES = ("crates", "src", "config", "models", "Cargo.lock", "publisher", "subscriber")
COMMIT = re.compile(r"^[0-9a-f]{7,40}$")
DIGIT = re.compile(r"[0-9]")
NO_FIGURES = "<!-- no measured figures -->"


def workspace_version(root: Path) -> str:
    """`version` of Cargo.toml's `[workspace.package]` (or `[package]`) table."""
    table = None
    for line in (root / "Cargo.toml").read_text(encoding="utf-8").split("\n"):
        header = re.match(r"^\s*\[([^\]]+)\]", line)
        if header:
            table = header.group(1).strip()
            continue
        match = re.match(r'^\s*version\s*=\s*"([^"]+)"', line)
        if match and table in ("workspace.package", "package"):
            return match.group(1)
    raise SystemExit("check_release_figures: Cargo.toml names no workspace version")


def version_key(version: str) -> tuple[int, ...]:
    return tuple(int(part) for part in re.findall(r"\d+", version.split("-")[0]))


def table_starts(lines: list[str]) -> list[int]:
    """0-based line numbers of the header row of every markdown table outside code fences."""
    starts = []
    fenced = False
    for index, line in enumerate(lines):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        if fenced or not line.lstrip().startswith("|"):
            continue
        if index > 0 and lines[index - 1].lstrip().startswith("|"):
            continue
        if index + 1 < len(lines) and doc_tables.SEPARATOR.match(lines[index + 1]):
            starts.append(index)
    return starts


def declared_without_figures(lines: list[str], start: int) -> bool:
    before = [line.strip() for line in lines[max(0, start - 2) : start] if line.strip()]
    return bool(before) and before[-1] == NO_FIGURES


def git(root: Path, *args: str) -> subprocess.CompletedProcess | None:
    try:
        return subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True, check=False)
    except FileNotFoundError:
        return None


def check_commit(root: Path, commit: str, where: str, strict: bool) -> list[str]:
    if not COMMIT.match(commit):
        return [f"{where}: the commit {commit!r} is not a commit hash"]
    inside = git(root, "rev-parse", "--is-inside-work-tree")
    if inside is None or inside.returncode != 0 or inside.stdout.strip() != "true":
        return []  # no git, or a copy without history: nothing to check the commit against
    if git(root, "cat-file", "-e", f"{commit}^{{commit}}").returncode != 0:
        shallow = git(root, "rev-parse", "--is-shallow-repository").stdout.strip() == "true"
        return [] if shallow else [f"{where}: the commit {commit} is not in this repository"]
    if git(root, "merge-base", "--is-ancestor", commit, "HEAD").returncode != 0:
        return [f"{where}: the commit {commit} is not an ancestor of HEAD"]
    if strict:
        changed = git(root, "diff", "--name-only", commit, "HEAD", "--", *SOURCES).stdout.split()
        if changed:
            shown = ", ".join(changed[:5]) + (f" and {len(changed) - 5} more" if len(changed) > 5 else "")
            return [f"{where}: measured on {commit[:10]}, but {shown} changed since; run tools/release_figures.sh"]
    return []


def check_report(root: Path, report: str, version: str, strict: bool) -> list[str]:
    doc = root / report
    if not doc.is_file():
        return [f"{report}: missing"]
    lines = doc.read_text(encoding="utf-8").split("\n")
    blocks = doc_tables.find_blocks(doc, lines)
    starts = table_starts(lines)
    failures = []
    if not starts:
        return [f"{report}: no table; the report opens with a headline table of release {version}"]

    def block_of(start: int) -> doc_tables.Block | None:
        return next((block for block in blocks if block.body_start <= start < block.body_end), None)

    for position, start in enumerate(starts):
        where = f"{report}:{start + 1}"
        block = block_of(start)
        if block is None:
            rows = []
            for line in lines[start + 2 :]:
                if not line.lstrip().startswith("|"):
                    break
                rows.append(line)
            if position == 0:
                failures.append(f"{where}: the first table is not generated from a results file (the headline)")
            elif any(DIGIT.search(line) for line in rows) and not declared_without_figures(lines, start):
                failures.append(f"{where}: a table with figures that is not generated from a results file")
            continue
        results = root / block.results
        metadata = doc_tables.read_metadata(results) if results.is_file() else {}
        release = metadata.get("release")
        commit = metadata.get("commit")
        if release is None or commit is None:
            failures.append(f"{where}: {block.results} records no release or no commit (# release:, # commit:)")
            continue
        if position == 0 and release != version:
            failures.append(
                f"{where}: the headline's figures are of release {release} ({block.results}), "
                f"the workspace is {version}; run tools/release_figures.sh"
            )
        elif version_key(release) > version_key(version):
            failures.append(f"{where}: {block.results} claims release {release}, newer than the workspace's {version}")
        failures += check_commit(root, commit, f"{where} ({block.results})", strict and position == 0)
    return failures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--root", type=Path, default=Path(__file__).resolve().parent.parent)
    parser.add_argument("--strict", action="store_true", help="also fail when the sources changed since the headline's commit")
    args = parser.parse_args(argv)
    root = args.root.resolve()
    doc_tables.ROOT = root
    version = workspace_version(root)
    failures = []
    try:
        for report in REPORTS:
            failures += check_report(root, report, version, args.strict)
    except doc_tables.DocTableError as error:
        failures.append(str(error))
    for failure in failures:
        print(failure, file=sys.stderr)
    if failures:
        print(f"check_release_figures: {len(failures)} failure(s)", file=sys.stderr)
        return 1
    print(f"check_release_figures: the reports' headlines are figures of release {version}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
