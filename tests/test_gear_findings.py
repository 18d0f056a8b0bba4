"""Findings and the verdict of a cut gear set (gears/findings.py)."""

import numpy as np
import pytest

from plantmech.gears.findings import (
    CutLimits,
    describe,
    gear_findings,
    mesh_findings,
    verdict,
)
from plantmech.gears.outline import teeth_on_outline
from plantmech.gears.teeth import PitchPolyline, ToothSpec, cut_gear, gear_checks

TH = np.linspace(0, 2 * np.pi, 3001)[:-1]
KEYS = {"gear", "check", "value", "limit", "unit", "where", "why"}


def circle_gear(z, **spec):
    spec = ToothSpec(module=2.0, cutter="rack", **spec)
    pitch = PitchPolyline.from_polar(TH, np.full(3000, z * 1.0))
    g = cut_gear(pitch, spec)
    return gear_checks("g", pitch, spec, z), teeth_on_outline(g, pitch.xy, 2.0, spec.addendum)


def test_a_30_tooth_spur_gear_has_no_finding():
    check, teeth = circle_gear(30)
    assert gear_findings(check, teeth) == []
    assert verdict([]) == "ok"


def test_a_12_tooth_gear_is_undercut_by_the_rack_rule():
    """z = 12 < 2 / sin^2(20 deg) = 17.1: undercut everywhere; the finding carries the
    equivalent tooth count (12 for a circle of radius 12 at m = 2) and a place."""
    check, teeth = circle_gear(12)
    (f,) = [f for f in gear_findings(check, teeth) if f["check"] == "undercut"]
    assert set(f) == KEYS
    assert f["value"] == pytest.approx(12.0, rel=1e-3)
    assert f["limit"] == pytest.approx(2 / np.sin(np.radians(20)) ** 2, rel=1e-6)
    assert 1 <= f["where"]["tooth"] <= 12 and 0 <= f["where"]["body_angle_deg"] < 360
    assert verdict([f]) == "not manufacturable"
    line = describe(f)
    assert line.startswith("g: undercut 12") and "limit 17.1" in line and "tooth" in line


def test_pointed_teeth_are_found_on_the_cut_outline():
    check, teeth = circle_gear(10, addendum=1.4, dedendum=1.65)
    found = {f["check"]: f for f in gear_findings(check, teeth)}
    assert found["pointed_teeth"]["value"] == 0.0
    assert found["pointed_teeth"]["limit"] == pytest.approx(0.4)
    assert found["pointed_teeth"]["where"]["teeth"] == list(range(1, 11))


def test_missing_teeth_are_a_finding():
    check, teeth = circle_gear(30)
    keep = np.ones(30, bool)
    keep[10:13] = False  # three teeth gouged away around 120 deg
    gone = {k: v[keep] for k, v in teeth.items()}
    (f,) = gear_findings(check, gone)
    assert f["check"] == "tooth_count" and (f["value"], f["limit"]) == (27, 30)
    assert f["where"]["body_angle_deg"] == pytest.approx(132.0, abs=0.5)


def mesh(lo, hi, interference=0.0):
    return {"pair": "a_b", "max_interference_mm": interference,
            "worst_at_contact_angle_deg": 10.0 if interference else None,
            "min_circumferential_backlash_mm": lo, "min_circumferential_backlash_at_deg": 1.0,
            "max_circumferential_backlash_mm": hi, "max_circumferential_backlash_at_deg": 2.0}


def test_backlash_band_and_interference():
    lim = CutLimits()
    assert mesh_findings(mesh(0.09, 0.12), 2.0, 0.1, lim) == []
    checks = [f["check"] for f in mesh_findings(mesh(0.02, 0.5, 0.05), 2.0, 0.1, lim)]
    assert checks == ["mesh_interference", "backlash_min", "backlash_max"]
    (f,) = mesh_findings(mesh(None, None), 2.0, 0.1, lim)
    assert f["check"] == "backlash_min" and f["value"] is None
