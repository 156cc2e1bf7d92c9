#!/usr/bin/env python3
"""Renders the tables of figures in the docs from their results files, or checks them.

A generated table sits in a markdown doc between two marker lines:

    <!-- table: RESULTS_PATH [OPTION="VALUE" ...] -->
    | ... the rendered table ... |
    <!-- /table -->

RESULTS_PATH is relative to the repository root. What is rendered depends on the file:

* ``.csv``: the first row that is not a ``# `` comment is the header, every further row a row of
  the table, each cell verbatim (bold markers, units and thousands separators included). Comment
  lines at the top name the command that produced the figures and its date. Comment lines of the
  form ``# release: VERSION``, ``# commit: SHA`` and ``# measured: DATE`` record what was
  measured (``tools/release_figures.sh`` writes them); a file with a ``release`` line is rendered
  with a line under its table that names the release, the commit and the date, and
  ``tools/check_release_figures.py`` checks them against the workspace's version.
* ``.md`` (the files the benchmarks write under ``benches/results/``): a markdown table of that
  file, the first unless ``table="N"`` selects the N-th.
* ``.txt``: the file's text verbatim, in a ``text`` code fence (the text tables `primm eval`
  prints); where it opens with ``# release:`` and the other comment lines below, those are left
  out of the fence and rendered as for a ``.csv``.

Options for tables (``.csv`` and ``.md``):

* ``columns="A; B=NEW HEADER; C"``: the columns to keep, in that order, by their header in the
  results file, each optionally shown under another header.
* ``digits="A=1; B=2"``: round the numbers of a column (by its header in the results file) to
  that many decimals, half up.
* ``labels="first; second; ..."``: the cells of the first column, row by row, in place of those
  of the results file.

    python3 tools/doc_tables.py --write     # rewrite every table from its results file
    python3 tools/doc_tables.py --check     # exit 1, with a diff, where a table differs

Without a file argument both go over every markdown file of the repository (``*.md`` at the top
level and under ``docs/``); with file arguments, over those. ``--root DIR`` takes another copy of
the repository (its docs and results files) instead of the one this script is in.
"""

from __future__ import annotations

import argparse
import csv
import difflib
import io
import re
import shlex
import sys
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal, InvalidOperation
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

BEGIN = re.compile(r"^<!-- table: (?P<spec>.+?) -->\s*$")
END = re.compile(r"^<!-- /table -->\s*$")
SEPARATOR = re.compile(r"^\s*\|(\s*:?-+:?\s*\|)+\s*$")
KNOWN_OPTIONS = {"table", "columns", "digits", "labels"}


class DocTableError(Exception):
    """A marker, an option or a results file that cannot be rendered."""


@dataclass
class Block:
    """One generated table of a doc: its marker and the lines between the markers."""

    doc: Path
    line: int  # 1-based line number of the opening marker
    results: str  # RESULTS_PATH as written in the marker
    options: dict[str, str]
    body_start: int  # 0-based index of the first line between the markers
    body_end: int  # 0-based index of the closing marker


def parse_marker(spec: str, where: str) -> tuple[str, dict[str, str]]:
    try:
        words = shlex.split(spec)
    except ValueError as error:
        raise DocTableError(f"{where}: cannot read the marker ({error})") from None
    if not words:
        raise DocTableError(f"{where}: the marker names no results file")
    options = {}
    for word in words[1:]:
        key, sep, value = word.partition("=")
        if not sep or key not in KNOWN_OPTIONS:
            raise DocTableError(
                f"{where}: unknown option {word!r} (known: {', '.join(sorted(KNOWN_OPTIONS))})"
            )
        options[key] = value
    return words[0], options


def find_blocks(doc: Path, lines: list[str]) -> list[Block]:
    blocks = []
    index = 0
    while index < len(lines):
        match = BEGIN.match(lines[index])
        if match:
            where = f"{display(doc)}:{index + 1}"
            results, options = parse_marker(match.group("spec"), where)
            end = index + 1
            while end < len(lines) and not END.match(lines[end]):
                if BEGIN.match(lines[end]):
                    raise DocTableError(f"{where}: a table marker opens before this one closes")
                end += 1
            if end == len(lines):
                raise DocTableError(f"{where}: no closing <!-- /table --> marker")
            blocks.append(Block(doc, index + 1, results, options, index + 1, end))
            index = end
        elif END.match(lines[index]):
            raise DocTableError(f"{display(doc)}:{index + 1}: a closing marker without an opening one")
        index += 1
    return blocks


def split_row(line: str) -> list[str]:
    """The cells of one markdown table row (no escaped pipes in these tables)."""
    text = line.strip()
    if not (text.startswith("|") and text.endswith("|")):
        raise DocTableError(f"not a table row: {line!r}")
    return [cell.strip() for cell in text[1:-1].split("|")]


def markdown_tables(text: str) -> list[list[list[str]]]:
    """Every table of a markdown file, as rows of cells (header first, separator left out)."""
    lines = text.split("\n")
    tables = []
    index = 0
    while index < len(lines):
        if lines[index].lstrip().startswith("|") and index + 1 < len(lines) and SEPARATOR.match(lines[index + 1]):
            rows = [split_row(lines[index])]
            index += 2
            while index < len(lines) and lines[index].lstrip().startswith("|"):
                rows.append(split_row(lines[index]))
                index += 1
            tables.append(rows)
        else:
            index += 1
    return tables


METADATA = re.compile(r"^# (?P<key>release|commit|measured|command|host): (?P<value>.+?)\s*$")


def read_metadata(path: Path) -> dict[str, str]:
    """The ``# key: value`` lines at the top of a results file (release, commit, measured, ...)."""
    metadata = {}
    for line in path.read_text(encoding="utf-8").split("\n"):
        if not line.startswith("#"):
            break
        match = METADATA.match(line)
        if match:
            metadata[match.group("key")] = match.group("value")
    return metadata


def provenance(metadata: dict[str, str]) -> list[str]:
    """The line under a table whose results file records the release it was measured on."""
    if "release" not in metadata:
        return []
    parts = [f"primm {metadata['release']}"]
    if "commit" in metadata:
        parts.append(f"commit {metadata['commit'][:10]}")
    if "measured" in metadata:
        parts.append(metadata["measured"])
    host = f"; {metadata['host']}" if "host" in metadata else ""
    return ["", f"*Measured on {', '.join(parts)}{host}.*"]


def read_csv(path: Path) -> list[list[str]]:
    lines = path.read_text(encoding="utf-8").split("\n")
    while lines and lines[0].startswith("#"):
        lines.pop(0)
    rows = [row for row in csv.reader(io.StringIO("\n".join(lines))) if row]
    return rows


def split_list(value: str) -> list[str]:
    return [item.strip() for item in value.split(";") if item.strip()]


def round_cell(cell: str, digits: int) -> str:
    try:
        number = Decimal(cell)
    except InvalidOperation:
        return cell
    return str(number.quantize(Decimal(1).scaleb(-digits), rounding=ROUND_HALF_UP))


def apply_options(rows: list[list[str]], options: dict[str, str], where: str) -> list[list[str]]:
    header = rows[0]
    width = len(header)
    for number, row in enumerate(rows[1:], start=2):
        if len(row) != width:
            raise DocTableError(f"{where}: row {number} has {len(row)} cells, the header {width}")
    if "digits" in options:
        for item in split_list(options["digits"]):
            name, _, digits = item.rpartition("=")
            if name not in header or not digits.isdigit():
                raise DocTableError(f"{where}: digits: no column {name!r} or no digit count")
            column = header.index(name)
            for row in rows[1:]:
                row[column] = round_cell(row[column], int(digits))
    if "columns" in options:
        picked, headers = [], []
        for item in split_list(options["columns"]):
            name, sep, shown = item.partition("=")
            name = name.strip()
            if name not in header:
                raise DocTableError(f"{where}: columns: no column {name!r} in {header}")
            picked.append(header.index(name))
            headers.append(shown.strip() if sep else name)
        rows = [headers] + [[row[column] for column in picked] for row in rows[1:]]
    if "labels" in options:
        labels = split_list(options["labels"])
        if len(labels) != len(rows) - 1:
            raise DocTableError(f"{where}: labels: {len(labels)} labels for {len(rows) - 1} rows")
        for row, label in zip(rows[1:], labels):
            row[0] = label
    return rows


def render_rows(rows: list[list[str]]) -> list[str]:
    def line(cells: list[str]) -> str:
        return "|" + "|".join(f" {cell} " if cell else " " for cell in cells) + "|"

    return [line(rows[0]), "|" + "---|" * len(rows[0])] + [line(row) for row in rows[1:]]


def render(results: str, options: dict[str, str], where: str) -> list[str]:
    """The lines that belong between the markers of a table with this results file and options."""
    path = ROOT / results
    if not path.is_file():
        raise DocTableError(f"{where}: results file {results} does not exist")
    suffix = path.suffix
    if suffix == ".txt":
        if options:
            raise DocTableError(f"{where}: a .txt results file takes no options")
        lines = path.read_text(encoding="utf-8").rstrip("\n").split("\n")
        metadata = read_metadata(path)
        if metadata:
            while lines and lines[0].startswith("# "):
                lines.pop(0)
        return ["```text"] + lines + ["```"] + provenance(metadata)
    if suffix == ".csv":
        if "table" in options:
            raise DocTableError(f"{where}: table= selects a table of a .md results file only")
        rows = read_csv(path)
        if not rows:
            raise DocTableError(f"{where}: {results} holds no rows")
        return render_rows(apply_options(rows, options, where)) + provenance(read_metadata(path))
    elif suffix == ".md":
        tables = markdown_tables(path.read_text(encoding="utf-8"))
        number = int(options.get("table", "1"))
        if not 1 <= number <= len(tables):
            raise DocTableError(f"{where}: {results} has {len(tables)} tables, not a table {number}")
        rows = [list(row) for row in tables[number - 1]]
    else:
        raise DocTableError(f"{where}: cannot render a {suffix or 'suffix-less'} results file")
    if not rows:
        raise DocTableError(f"{where}: {results} holds no rows")
    return render_rows(apply_options(rows, options, where))


def display(path: Path) -> str:
    try:
        return str(path.resolve().relative_to(ROOT))
    except ValueError:
        return str(path)


def default_docs() -> list[Path]:
    return sorted(ROOT.glob("*.md")) + sorted((ROOT / "docs").glob("**/*.md"))


def process(docs: list[Path], write: bool) -> tuple[int, list[str]]:
    """Checks (or rewrites) every table of these docs; returns (tables seen, messages)."""
    messages = []
    seen = 0
    for doc in docs:
        text = doc.read_text(encoding="utf-8")
        lines = text.split("\n")
        blocks = find_blocks(doc, lines)
        seen += len(blocks)
        replacements = []
        for block in blocks:
            where = f"{display(doc)}:{block.line}"
            wanted = render(block.results, block.options, where)
            present = lines[block.body_start : block.body_end]
            if present == wanted:
                continue
            replacements.append((block, wanted))
            if write:
                messages.append(f"{where}: rewrote the table from {block.results}")
            else:
                diff = difflib.unified_diff(
                    present,
                    wanted,
                    fromfile=f"{where} (the doc)",
                    tofile=f"{block.results} (rendered)",
                    lineterm="",
                )
                messages.append(
                    f"{where}: the table differs from its results file {block.results}\n" + "\n".join(diff)
                )
        if write and replacements:
            for block, wanted in reversed(replacements):
                lines[block.body_start : block.body_end] = wanted
            doc.write_text("\n".join(lines), encoding="utf-8")
    return seen, messages


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--write", action="store_true", help="rewrite the tables from their results files")
    mode.add_argument("--check", action="store_true", help="exit 1 where a table differs from its results file")
    parser.add_argument("--root", type=Path, help="the repository root (default: the one of this script)")
    parser.add_argument("docs", nargs="*", type=Path, help="markdown files (default: every doc)")
    args = parser.parse_args(argv)
    global ROOT
    if args.root is not None:
        ROOT = args.root.resolve()
    docs = args.docs or default_docs()
    try:
        seen, messages = process(docs, write=args.write)
    except DocTableError as error:
        print(f"doc_tables: {error}", file=sys.stderr)
        return 2
    for message in messages:
        print(message, file=sys.stderr if args.check else sys.stdout)
    if args.check:
        if messages:
            print(f"doc_tables: {len(messages)} of {seen} tables differ; run tools/doc_tables.py --write", file=sys.stderr)
            return 1
        print(f"doc_tables: {seen} tables match their results files")
    return 0


if __name__ == "__main__":
    sys.exit(main())
