#!/usr/bin/env python3
"""Keeps primm's Rust code in pieces a reader can hold: no source file over 700 lines (not
counting its inline test module) and no function over 80 lines outside the tests (a test in a
`tests/` directory may read as one long scenario).

    tools/code_size.py            list every file and function over its limit
    tools/code_size.py --check    the same, failing (exit 1) on any not named in
                                  tools/code_size_exceptions.txt, or on an exception that is
                                  no longer needed

Functions are found by brace matching over the source with comments, strings and character
literals blanked out, so braces inside them do not count. Generated code (build outputs), the
fuzz workspace's corpus and vendored code are not looked at.
"""
import argparse
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
MAX_FILE_LINES = 700
MAX_FUNCTION_LINES = 80
SKIP_DIRS = {"target", ".git", ".venv-test", "node_modules", "corpus", "artifacts"}
EXCEPTIONS = ROOT / "tools" / "code_size_exceptions.txt"


def rust_files():
    for path in sorted(ROOT.rglob("*.rs")):
        if not SKIP_DIRS.intersection(path.relative_to(ROOT).parts):
            yield path


def blank_literals(text):
    """The text with comments, string and char literals replaced by spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            hashes = re.match(r'r(#*)"', text[i:]).group(1)
            end = text.find('"' + hashes, i + 2 + len(hashes))
            end = n if end < 0 else end + 1 + len(hashes)
            out.append(re.sub(r"[^\n]", " ", text[i:end]))
            i = end
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(re.sub(r"[^\n]", " ", text[i:j + 1]))
            i = j + 1
        elif c == "'":
            # A char literal ('a', '\n', '\u{..}') but not a lifetime ('a without a closing quote).
            m = re.match(r"'(\\u\{[0-9a-fA-F]+\}|\\.|[^\\'])'", text[i:])
            if m:
                out.append(" " * len(m.group(0)))
                i += len(m.group(0))
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def matching_brace(code, open_index):
    depth = 0
    for j in range(open_index, len(code)):
        if code[j] == "{":
            depth += 1
        elif code[j] == "}":
            depth -= 1
            if depth == 0:
                return j
    return len(code) - 1


def test_module_lines(code):
    """Lines of inline `#[cfg(test)] mod name { ... }` blocks."""
    lines = 0
    for m in re.finditer(r"#\[cfg\(test\)\]\s*(pub(\([^)]*\))?\s+)?mod\s+\w+\s*\{", code):
        end = matching_brace(code, m.end() - 1)
        lines += code.count("\n", m.start(), end) + 1
    return lines


def long_functions(code):
    for m in re.finditer(r"\bfn\s+(\w+)", code):
        # The body starts at the first `{` after the signature (a `;` first: a declaration).
        k = m.end()
        depth = 0
        while k < len(code):
            ch = code[k]
            if ch in "([<":
                depth += 1
            elif ch in ")]>" and depth > 0 and not code.startswith("->", k - 1):
                depth -= 1
            elif ch == ";" and depth == 0:
                k = -1
                break
            elif ch == "{" and depth == 0:
                break
            k += 1
        if k < 0 or k >= len(code):
            continue
        end = matching_brace(code, k)
        start_line = code.count("\n", 0, m.start()) + 1
        length = code.count("\n", m.start(), end) + 1
        if length > MAX_FUNCTION_LINES:
            yield m.group(1), start_line, length


def findings():
    for path in rust_files():
        text = path.read_text(encoding="utf-8")
        code = blank_literals(text)
        relative = path.relative_to(ROOT).as_posix()
        lines = text.count("\n") + (0 if text.endswith("\n") else 1)
        counted = lines - test_module_lines(code)
        if counted > MAX_FILE_LINES:
            yield f"{relative}", f"file of {counted} lines (limit {MAX_FILE_LINES}, inline tests not counted)"
        if "tests" in path.relative_to(ROOT).parts:
            continue
        for name, line, length in long_functions(code):
            yield f"{relative}::{name}", f"function of {length} lines at line {line} (limit {MAX_FUNCTION_LINES})"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="fail on anything not in the exceptions file")
    args = parser.parse_args()
    found = dict(findings())
    if not args.check:
        for key, what in found.items():
            print(f"{key}: {what}")
        return 0
    allowed = set()
    if EXCEPTIONS.exists():
        for line in EXCEPTIONS.read_text().splitlines():
            line = line.split("#", 1)[0].strip()
            if line:
                allowed.add(line)
    new = sorted(set(found) - allowed)
    stale = sorted(allowed - set(found))
    for key in new:
        print(f"over the limit: {key}: {found[key]}", file=sys.stderr)
    for key in stale:
        print(f"no longer over the limit, remove it from {EXCEPTIONS.name}: {key}", file=sys.stderr)
    return 1 if new or stale else 0


if __name__ == "__main__":
    sys.exit(main())
