"""Tests of tools/doc_references.py: the code references of ARCHITECTURE.md name files and names that exist."""

from __future__ import annotations

import sys
from pathlib import Path

TOOLS = Path(__file__).resolve().parents[1]
ROOT = TOOLS.parent
sys.path.insert(0, str(TOOLS))

import doc_references  # noqa: E402


def test_every_code_reference_of_the_architecture_holds() -> None:
    stale = doc_references.stale_references(ROOT / "ARCHITECTURE.md")
    assert not stale, "\n".join(stale)


def test_the_architecture_has_code_references_to_check() -> None:
    spans = [span for _, span in doc_references.references(ROOT / "ARCHITECTURE.md")]
    checked = [span for span in spans if "::" in span or span.endswith(".rs")]
    assert len(checked) > 50, checked


def test_a_file_that_does_not_exist_is_stale() -> None:
    assert doc_references.check_span(ROOT, "crates/primm-core/src/imm.rs") == "no such file"
    assert doc_references.check_span(ROOT, "crates/primm-core/src/imm/mod.rs") is None


def test_a_name_missing_from_its_file_is_stale() -> None:
    reason = doc_references.check_span(ROOT, "motion/coordinated_turn.rs::{transition, turn_functions}")
    assert reason is not None and "turn_functions" in reason
    assert doc_references.check_span(ROOT, "motion/coordinated_turn.rs::{transition, jacobian}") is None


def test_a_method_missing_from_its_type_is_stale() -> None:
    assert doc_references.check_span(ROOT, "Tracker::predict_to") is None
    assert doc_references.check_span(ROOT, "Tracker::predict_into_the_past") is not None
    assert doc_references.check_span(ROOT, "primm_core::invariants::check_tracker") is None
    assert doc_references.check_span(ROOT, "primm_core::invariants::check_everything") is not None


def test_spans_that_are_not_references_are_left_alone(tmp_path: Path) -> None:
    doc = tmp_path / "DOC.md"
    doc.write_text(
        "`tracker.lifecycle` and `a b c`, `iceoryx2_link::Link`\n```rust\nlet x = `gone.rs`;\n```\n`gone.rs`\n",
        encoding="utf-8",
    )
    stale = doc_references.stale_references(doc)
    assert stale == ["DOC.md:5: `gone.rs`: no such file"]
