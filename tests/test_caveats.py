"""Caveats of a verdict (outputs/caveats.py): limits from the file, thin margins, what a job
changed; printed above the verdict line and stored in the record."""

import json
import tomllib

import pytest

from plantmech.design import load_design
from plantmech.outputs import caveats as cv
from plantmech.outputs.verdict import verdict, verdict_line
from tests.conftest import EXAMPLES


def _doc(name):
    return tomllib.loads((EXAMPLES / name).read_text())


def test_limits_taken_from_the_file():
    found = cv.limits_from_file(load_design(EXAMPLES / "rice_transplanter.toml"))
    assert [c["field"] for c in found] == ["limits.max_working_pressure_angle_deg"]
    assert found[0]["value"] == 70 and found[0]["default"] == 45
    assert "= 70 from the file (default 45)" in found[0]["text"]
    doc = _doc("rice_transplanter.toml")
    del doc["limits"]["max_working_pressure_angle_deg"]
    assert cv.limits_from_file(load_design(doc, name="d.toml")) == []
    doc["manufacturing"] = {"special_module": True}
    assert [c["field"] for c in cv.limits_from_file(load_design(doc, name="d.toml"))] == [
        "manufacturing.special_module"]


def test_thin_margins():
    assert cv.bounds_of("> 45 and < 65 deg") == (45.0, 65.0)
    assert cv.bounds_of("< 30 mm") == (None, 30.0) and cv.bounds_of(">= 1.4") == (1.4, None)
    rows = [{"name": "picking_swing", "value": 29.80, "unit": "deg", "limit": "< 30 deg",
             "ok": True},
            {"name": "module", "value": 2.5, "unit": "mm", "limit": "> 2.5 mm", "ok": True},
            {"name": "far", "value": 20.0, "unit": "deg", "limit": "< 30 deg", "ok": True},
            {"name": "failed", "value": 31.0, "unit": "deg", "limit": "< 30 deg", "ok": False},
            {"name": "info", "value": 29.9, "unit": "", "limit": "< 30", "ok": True,
             "required": False},
            # a zero limit: the margin is measured against 1 (as relative_violation does)
            {"name": "clearance", "value": 0.005, "unit": "mm", "limit": "> 0 mm", "ok": True}]
    found = cv.thin_margins(rows)
    assert [c["name"] for c in found] == ["picking_swing", "module", "clearance"]
    assert found[0]["margin"] == pytest.approx(0.2 / 30, abs=1e-6)
    assert found[1]["margin"] == 0.0 and "0 % to spare" in found[1]["text"]


def test_changes_the_job_made():
    doc = _doc("sugarcane_seeder.toml")
    planned = load_design(doc, name="p.toml")
    moved = _doc("sugarcane_seeder.toml")
    pts = [list(p) for p in moved["trajectory"]["points"]]
    pts[3][1] += 79.0
    pts[5][0] += 10.0
    moved["trajectory"]["points"] = pts
    sec = moved["trajectory"]["sections"]
    e0 = sec["e"]
    sec["e"] += 1  # f moves with it where needed
    if sec["f"] == sec["e"]:
        sec["f"] += 1
    final = load_design(moved, name="f.toml")
    rec = {"design_choices": {
        "tooth_system": {"value": "stub 25 deg", "set_by": "plantmech design (the file does "
                         "not fix it)"},
        "interpolation": {"value": "hermite", "set_by": "the design file"}}}
    found = cv.changes(planned, final, rec)
    kinds = [c["kind"] for c in found]
    assert kinds == ["points_moved", "seeding_point_moved", "choice"]
    assert found[0]["count"] == 2 and found[0]["point"] == "q3"
    assert found[0]["largest_mm"] == pytest.approx(79.0)
    assert found[1]["from"] == f"q{e0}" and found[1]["to"] == f"q{e0 + 1}"
    assert "stub 25 deg" in found[2]["text"]
    assert cv.changes(planned, planned, {}) == []


def test_verdict_line_prints_caveats_above_the_verdict():
    v = verdict([{"name": "a", "ok": True}])
    text = verdict_line(v, "all met", [{"text": "x = 1 from the file"}, "y thin"])
    assert text.splitlines() == ["  caveat: x = 1 from the file", "  caveat: y thin",
                                 "verdict: ok - all met"]
    assert verdict_line(v, "all met") == "verdict: ok - all met"


def test_forward_transplanter_states_its_caveats(tmp_path, capsys):
    from plantmech.interfaces.cli import main

    out = tmp_path / "o"
    rc = main(["forward", str(EXAMPLES / "rice_transplanter_manufacturable.toml"), "--out",
               str(out), "--no-plots"])
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[-1].startswith("verdict: ok") and rc == 0
    cav = [line for line in lines if "caveat:" in line]
    assert any("limits.max_working_pressure_angle_deg = 70" in c for c in cav)
    assert any("manufacturing.special_module = True" in c for c in cav)
    s = json.loads((out / "summary.json").read_text())
    assert [c["text"] for c in s["caveats"]] == [c.split("caveat: ")[1] for c in cav]


def test_design_scales_a_transplanter_to_a_standard_module():
    """The manufacturable transplanter without its special_module: 80 teeth at 2.5568 mm;
    the design job's step scales its gear by 2.5 / 2.5568 and the scaled design still meets
    every objective at full resolution; the record and the line say so."""
    from plantmech.gears.modules import is_standard
    from plantmech.optimize.jobs import verify
    from plantmech.pipeline import _standard_module

    doc = _doc("rice_transplanter_manufacturable.toml")
    del doc["manufacturing"]["special_module"]
    design = load_design(doc, name="m.toml")
    check = verify(design, True)
    m0 = next(o["value"] for o in check["objectives"] if o["name"] == "module")
    assert check["all_met"] and not is_standard(m0)
    final, c2, std = _standard_module(design, check, verify)
    assert std["standard"] and std["module_mm"] == 2.5
    assert std["scale"] == pytest.approx(2.5 / m0, rel=1e-5)
    assert c2["all_met"]
    m1 = next(o["value"] for o in c2["objectives"] if o["name"] == "module")
    assert is_standard(m1) and m1 >= 2.5
    r0, r1 = design.internal_gear.radii_mm, final.internal_gear.radii_mm
    assert [b / a for a, b in zip(r0, r1, strict=True)] == pytest.approx(
        [std["scale"]] * len(r0), rel=1e-4)
    assert "2.5568 -> 2.5 mm (ISO 54 series I)" in std["line"]
    # allowed a special module: kept, and said
    doc["manufacturing"]["special_module"] = True
    kept, _, std2 = _standard_module(load_design(doc, name="s.toml"), check, verify)
    assert std2["scale"] == 1.0 and "special" in std2["line"] and "tried" not in std2
