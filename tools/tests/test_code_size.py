"""Tests of tools/code_size.py: the file and function limits of the Rust code."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(TOOLS))

import code_size  # noqa: E402


def test_the_tree_is_within_its_limits_apart_from_the_named_exceptions():
    result = subprocess.run(
        [sys.executable, str(TOOLS / "code_size.py"), "--check"], capture_output=True, text=True, check=False
    )
    assert result.returncode == 0, result.stderr


def test_braces_in_comments_strings_and_chars_do_not_count():
    code = code_size.blank_literals('fn a() { let s = "}"; let c = \'{\'; // }\n /* { */ }\n')
    assert code.count("{") == 1 and code.count("}") == 1
    # A lifetime is not a char literal.
    assert "'a" in code_size.blank_literals("fn b<'a>(x: &'a str) {}")


def test_a_long_function_is_found_with_its_length_and_a_declaration_is_not():
    body = "\n".join("    let x = 1;" for _ in range(85))
    code = code_size.blank_literals(f"trait T {{ fn declared(&self); }}\nfn long() -> Vec<u8> {{\n{body}\n}}\n")
    found = list(code_size.long_functions(code))
    assert [(name, length) for name, _, length in found] == [("long", 87)]


def test_an_inline_test_module_is_not_counted_against_its_file():
    code = code_size.blank_literals("fn a() {}\n#[cfg(test)]\nmod tests {\n    fn b() {}\n}\n")
    assert code_size.test_module_lines(code) == 4
