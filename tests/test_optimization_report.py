"""outputs.optimization_report.design_toml: a design written as a person would write it (a
point per line; numbers in full: the file is the design checked) and, made from an input
file, that file edited with its comments and layout kept; every written file reads back as
the design."""

from __future__ import annotations

import difflib
import re

import pytest

from plantmech.design import load_design
from plantmech.outputs.optimization_report import design_toml
from tests.conftest import EXAMPLES

SHIPPED = ["rice_transplanter", "rice_transplanter_khv", "sugarcane_seeder",
           "sugarcane_table4", "rotary_transplanter_elliptic", "planetary/sugarcane_table4"]


@pytest.mark.parametrize("name", SHIPPED)
def test_written_afresh_reads_back_a_point_per_line(name):
    d = load_design(EXAMPLES / f"{name}.toml")
    text = design_toml(d, "made here\n\nsecond line")
    assert text.startswith("# made here\n#\n# second line\n\n")
    assert load_design(text) == d
    # no number is split over lines: every line holding a number inside brackets opens
    # and closes its point (a list of points is one point per line)
    for line in text.splitlines():
        if re.match(r"\s+\[", line):
            assert line.rstrip().endswith(("],", "]")), line


@pytest.mark.parametrize("name", SHIPPED)
def test_an_unchanged_design_is_its_input_file(name):
    path = EXAMPLES / f"{name}.toml"
    assert design_toml(load_design(path), "", path) == path.read_text()


def test_an_edited_design_keeps_the_inputs_comments(tmp_path):
    path = EXAMPLES / "rice_transplanter.toml"
    d = load_design(path)
    arm = d.arm.model_copy(update={"S_mm": 147.12339721471105})
    gear = d.internal_gear.model_copy(update={"radii_mm": [r + 0.5 for r in
                                                           d.internal_gear.radii_mm]})
    new = d.model_copy(update={"arm": arm, "internal_gear": gear})
    text = design_toml(new, "made", path)
    src = path.read_text()
    removed = [ln for ln in difflib.ndiff(src.splitlines(), text.splitlines())
               if ln.startswith("- ")]
    # only the changed values' lines go; every comment of the input stays
    assert all(not ln[2:].lstrip().startswith("#") for ln in removed)
    assert [c for c in src.splitlines() if c.lstrip().startswith("#")] == [
        c for c in text.splitlines()[2:] if c.lstrip().startswith("#")]
    assert "S_mm = 147.12339721471105\n" in text  # exactly the design checked
    assert load_design(text) == new


def test_a_missing_input_file_writes_the_design_afresh(tmp_path):
    d = load_design(EXAMPLES / "sugarcane_table4.toml")
    assert design_toml(d, "", tmp_path / "gone.toml") == design_toml(d)
