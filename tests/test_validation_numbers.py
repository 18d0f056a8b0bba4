"""docs/validation.md re-measured (scripts/validation_numbers.py, issue 34): every cheap
section of the script recomputes its figures from the bundled files and each must appear in
the document exactly as the document prints it (a changed number in the code or in the
document fails here, naming it)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "validation_numbers.py"


@pytest.fixture(scope="module")
def script():
    spec = importlib.util.spec_from_file_location("validation_numbers", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod  # its dataclass looks its module up
    spec.loader.exec_module(mod)
    yield mod
    sys.modules.pop(spec.name, None)


SECTIONS = ["table2", "inverse", "dwell", "round_trip", "estimate", "table4",
            "table4_reading", "transplanter", "convexity", "optimized"]


def test_the_cheap_sections_are_these(script):
    assert sorted(script.CHEAP) == sorted(SECTIONS)


@pytest.mark.parametrize("section", SECTIONS)
def test_section_figures_are_as_the_document_prints_them(script, section):
    rows = script.run([section])
    assert len(rows) >= 3
    missing = [f"{f.label} = {f.value:.6g}: {f.text!r}" for _, f, found in rows if not found]
    assert not missing, "not in docs/validation.md:\n" + "\n".join(missing)


def test_a_changed_number_in_the_document_is_found(script, tmp_path, monkeypatch, capsys):
    """The check can fail: the document with Table 2's printed minimum ratio changed, and
    with the sampled value it printed before issue 34."""
    doc = script.DOC.read_text(encoding="utf-8")
    assert "reaches -3.2336)" in doc
    changed = tmp_path / "validation.md"
    changed.write_text(doc.replace("reaches -3.2336)", "reaches -3.224)"), encoding="utf-8")
    monkeypatch.setattr(script, "DOC", changed)
    rows = script.run(["table2"])
    assert [f.label for _, f, found in rows if not found] == ["as printed: smallest ratio"]
    assert script.main(["table2", "--check"]) == 1
    assert "NOT IN docs/validation.md" in capsys.readouterr().out
    assert script.main(["nonsense"]) == 2
