#!/usr/bin/env python3
"""Checks the code references of a design doc: every file it names exists, every name it names occurs.

A reference is a backticked span of ARCHITECTURE.md (or the docs given) of one of these forms:

* a path of a file, ``crates/primm-core/src/imm/mod.rs`` or a shorter tail of one
  (``association/associator.rs``, ``tracking.rs``), ``*`` matching within one path component:
  some file of the repository must end with it;
* a file and names in it, ``imm/mixing.rs::Imm::mixing_probabilities`` or
  ``motion/coordinated_turn.rs::{transition, jacobian}``: the file must exist and the last name
  (each of the braced names) must occur in it as a word;
* a Rust path without a file, ``Tracker::predict_to``, ``primm_core::invariants::check_tracker``:
  the last name must occur as a word in a file that defines the name before it (a type, trait or
  module of that name, or the file of that module);
* a span of the forms above whose first name is a crate outside the workspace (iceoryx2, tract,
  std, ...) is not checked.

Spans inside fenced code blocks, spans with spaces (other than inside braces) and spans that look
like neither are left alone.

    python3 tools/doc_references.py [DOC ...]     # default: ARCHITECTURE.md; exit 1 on a stale reference
"""

from __future__ import annotations

import argparse
import fnmatch
import re
import sys
from functools import lru_cache
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SKIPPED_DIRECTORIES = {".git", "target", "out", "node_modules", "__pycache__", ".venv-test", ".venv"}
FILE_SUFFIXES = (".rs", ".py", ".sh", ".toml", ".h", ".hpp", ".c", ".cpp", ".md", ".onnx", ".json", ".txt", ".cmake", ".pc.in")
EXTERNAL_CRATES = ("iceoryx2", "tract", "std", "core", "alloc", "serde", "nalgebra", "glam", "zenoh", "clap", "hdrhistogram", "onnx")
SPAN = re.compile(r"`([^`\n]+)`")
IDENTIFIER = r"[A-Za-z_][A-Za-z0-9_]*\*?"
RUST_PATH = re.compile(rf"^{IDENTIFIER}(::({IDENTIFIER}|\{{[^}}]+\}}))+$")
FILE_PATH = re.compile(r"^[A-Za-z0-9_.*/-]+\.[A-Za-z0-9.]+$")


@lru_cache(maxsize=None)
def repository_files(root: Path) -> tuple[str, ...]:
    files = []
    for path in root.rglob("*"):
        relative = path.relative_to(root)
        if any(part in SKIPPED_DIRECTORIES for part in relative.parts[:-1]) or not path.is_file():
            continue
        files.append(relative.as_posix())
    return tuple(sorted(files))


@lru_cache(maxsize=None)
def text_of(root: Path, relative: str) -> str:
    try:
        return (root / relative).read_text(encoding="utf-8", errors="replace")
    except OSError:
        return ""


def files_ending_with(root: Path, tail: str) -> list[str]:
    pattern_parts = tail.split("/")
    found = []
    for relative in repository_files(root):
        parts = relative.split("/")
        if len(parts) >= len(pattern_parts) and all(
            fnmatch.fnmatchcase(part, pattern) for part, pattern in zip(parts[-len(pattern_parts):], pattern_parts)
        ):
            found.append(relative)
    return found


def occurs(name: str, text: str) -> bool:
    if name.endswith("*"):
        return re.search(rf"\b{re.escape(name[:-1])}\w*", text) is not None
    return re.search(rf"\b{re.escape(name)}\b", text) is not None


def split_names(segment: str) -> list[str]:
    if segment.startswith("{"):
        return [name.strip() for name in segment[1:-1].split(",") if name.strip()]
    return [segment]


def rust_segments(path: str) -> list[str]:
    return re.findall(r"\{[^}]+\}|[^:]+", path)


def defining_files(root: Path, name: str) -> list[str]:
    """Rust files that define `name` as a type, trait or module, or that are module `name`."""
    crate = name.replace("_", "-")
    definition = re.compile(rf"\b(struct|enum|trait|union|type|mod|impl(<[^>]*>)?)\s+{re.escape(name)}\b")
    found = []
    for relative in repository_files(root):
        if not relative.endswith(".rs"):
            continue
        parts = relative.split("/")
        if parts[-1] == f"{name}.rs" or (parts[-1] == "mod.rs" and len(parts) > 1 and parts[-2] == name):
            found.append(relative)
        elif len(parts) > 2 and parts[0] == "crates" and parts[1] == crate and parts[-1] == "lib.rs":
            found.append(relative)
        elif definition.search(text_of(root, relative)):
            found.append(relative)
    return found


def module_files(root: Path, first: str) -> list[str]:
    """The files of a crate (`primm_core`) or a module directory named `first`."""
    crate = first.replace("_", "-")
    return [
        relative
        for relative in repository_files(root)
        if relative.endswith(".rs")
        and (relative.startswith(f"crates/{crate}/src/") or f"/{first}/" in f"/{relative}" or relative.endswith(f"/{first}.rs"))
    ]


def check_rust_path(root: Path, path: str, file_text: str | None = None) -> str | None:
    segments = rust_segments(path)
    if segments[0] in EXTERNAL_CRATES or segments[0].split("_")[0] in EXTERNAL_CRATES:
        return None
    names = split_names(segments[-1])
    if file_text is not None:
        missing = [name for name in names if not occurs(name, file_text)]
        return f"{', '.join(missing)} not found in the file" if missing else None
    owner = segments[-2]
    if owner == "crate" or owner.startswith("{"):
        return None
    candidates = defining_files(root, owner)
    if len(segments) > 2 or not candidates:
        candidates = candidates + module_files(root, owner)
    if not candidates:
        return f"nothing defines {owner}"
    texts = [text_of(root, relative) for relative in candidates]
    missing = [name for name in names if not any(occurs(name, text) for text in texts)]
    return f"{', '.join(missing)} not found where {owner} is defined" if missing else None


def check_span(root: Path, span: str) -> str | None:
    """Why a reference is stale, or None when it holds (or is not a reference)."""
    span = span.strip()
    if "://" in span or span.startswith(("-", "$", "<")):
        return None
    file_part, separator, rest = span.partition("::")
    if FILE_PATH.match(file_part) and file_part.endswith(FILE_SUFFIXES) and " " not in file_part:
        files = files_ending_with(root, file_part)
        if not files:
            return "no such file"
        if separator:
            text = "\n".join(text_of(root, relative) for relative in files)
            return check_rust_path(root, "file::" + rest, file_text=text)
        return None
    if " " in re.sub(r"\{[^}]*\}", "", span) or not RUST_PATH.match(span):
        return None
    return check_rust_path(root, span)


def references(doc: Path) -> list[tuple[int, str]]:
    found = []
    fenced = False
    for number, line in enumerate(doc.read_text(encoding="utf-8").split("\n"), start=1):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        if not fenced:
            found += [(number, match.group(1)) for match in SPAN.finditer(line)]
    return found


def stale_references(doc: Path, root: Path = ROOT) -> list[str]:
    stale = []
    for number, span in references(doc):
        reason = check_span(root, span)
        if reason:
            stale.append(f"{doc.name}:{number}: `{span}`: {reason}")
    return stale


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("docs", nargs="*", type=Path, default=[ROOT / "ARCHITECTURE.md"])
    args = parser.parse_args(argv)
    stale = [line for doc in args.docs for line in stale_references(doc)]
    for line in stale:
        print(line, file=sys.stderr)
    if stale:
        print(f"doc_references: {len(stale)} stale reference(s)", file=sys.stderr)
        return 1
    print(f"doc_references: every code reference of {', '.join(doc.name for doc in args.docs)} holds")
    return 0


if __name__ == "__main__":
    sys.exit(main())
