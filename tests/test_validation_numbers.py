"""docs/validation.md re-measured (scripts/validation_numbers.py, issue 34): every cheap
section of the script recomputes its figures from the bundled files and each must appear in
the document exactly as the document prints it (a changed number in the code or in the
document fails here, naming it)."""

from __future__ import annotations

import importlib.util
import sys
from collections import Counter
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


SECTIONS = ["paper", "table2", "inverse", "dwell", "round_trip", "estimate", "table4",
            "table4_record", "table4_reading", "transplanter", "convexity", "optimized",
            "forward_checks", "table4_planetary"]


@pytest.fixture(scope="module")
def rows(script):
    """Every cheap section's figures, computed once for the module."""
    return script.run(SECTIONS)


def test_the_cheap_sections_are_these(script):
    assert sorted(script.CHEAP) == sorted(SECTIONS)


@pytest.mark.parametrize("section", SECTIONS)
def test_section_figures_are_as_the_document_prints_them(rows, section):
    mine = [r for r in rows if r[0] == section]
    assert len(mine) >= 3
    missing = [f"{f.label} = {f.value:.6g}: {f.text!r}" for _, f, found in mine if not found]
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
    assert script.main(["table2", "--chek"]) == 2  # a misspelt option is refused, not ignored
    assert "unknown option(s) ['--chek']" in capsys.readouterr().err
    assert script.main(["--help"]) == 0 and "--write-unmeasured" in capsys.readouterr().out


def test_every_number_of_the_document_has_a_section_or_is_listed(script, rows):
    """Each number of docs/validation.md lies in a figure a section re-measures (the
    expensive ones by their EXPENSIVE_TEXTS), or is listed in
    scripts/validation_unmeasured.txt; a listed number that is now re-measured, or gone
    from the page, fails too (`--write-unmeasured` rewrites the list)."""
    left = Counter(script.uncovered(rows))
    listed = Counter(script.unmeasured_listed())
    new = sorted((left - listed).elements())
    stale = sorted((listed - left).elements())
    assert not new, ("numbers of docs/validation.md that no section re-measures and "
                     "scripts/validation_unmeasured.txt does not list:\n" + "\n".join(new))
    assert not stale, ("listed in scripts/validation_unmeasured.txt but re-measured or gone:"
                       "\n" + "\n".join(stale))


def test_the_coverage_can_fail(script, rows):
    """A new number in the page is found, a reference is not a number, a figure's text
    covers the numbers in it, and an expensive section counts by its template."""
    doc = script.DOC.read_text(encoding="utf-8")
    base = Counter(script.uncovered(rows, doc))
    added = doc + "\n## Added\n\nThe sun turns 12.34 mm (issue 77, gear 5, Table 9, `x 3`).\n"
    new = list((Counter(script.uncovered(rows, added)) - base).elements())
    assert len(new) == 1 and new[0].startswith("Added: ...") and new[0].endswith(
        "## Added The sun turns 12.34"), new
    one = [(s, f, True) for s, f, _ in rows if s == "dwell"][:1]
    text = one[0][1].text
    assert text in " ".join(doc.split())
    assert len(script.uncovered(one, doc)) < len(script.uncovered([], doc))
    tmpl = script._template(script.EXPENSIVE_TEXTS["table4_fit"][0])
    assert tmpl.search("ends at 305.30 deg and 10.23 deg (305.301 / 10.225), RMS 13.4532 mm, "
                       "largest 36.85 mm")
    assert not tmpl.search("ends at 305.30 deg and 10.23 deg, RMS 13.4532 mm")


def test_a_misquoted_paper_value_is_found(script, monkeypatch):
    """The papers' values the page quotes are compared with the papers' text (shared/seeds
    beside the repository): a quote with a number the paper does not have fails."""
    if script._papers() is None:
        pytest.skip("the papers' text (shared/seeds) is not beside the repository")
    good = [f for f in script.paper()]
    assert good and all(not f.text.startswith("NOT IN PAPER") for f in good)
    monkeypatch.setattr(script, "QUOTES", [
        ("001", "| picking angle (iii) | 343 deg |",
         "arms in the transplanting mechanism was 342°"),
        ("000", "| L1 (carrier) | 254 |", "$L_1=255$")])
    bad = script.paper()
    assert [f.text.startswith("NOT IN PAPER") for f in bad] == [True, True]
