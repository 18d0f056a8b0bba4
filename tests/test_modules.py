"""Standard modules (gears/modules.py): the ISO 54 series, the finding for a gear cut at
another module, and the candidates `plantmech design` scales a transplanter to."""

import tomllib

import numpy as np
import pytest

from plantmech.gears import modules
from tests.conftest import EXAMPLES


def test_series_are_iso_54():
    # ISO 54:1996 series I from 1 mm: 1, 1.25, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10, 12, 16, 20,
    # 25, 32, 40, 50; series II between them; no module in both
    first = [m for m in modules.FIRST_SERIES if m >= 1]
    assert first == [1, 1.25, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10, 12, 16, 20, 25, 32, 40, 50]
    assert not set(modules.FIRST_SERIES) & set(modules.SECOND_SERIES)
    assert modules.series_of(2.5) == "I" and modules.series_of(2.75) == "II"
    assert modules.series_of(2.5357) is None
    # every series-II module lies strictly between two series-I ones
    for m in modules.SECOND_SERIES:
        assert min(modules.FIRST_SERIES) < m < max(modules.FIRST_SERIES)


def test_standard_nearest_and_candidates():
    assert modules.is_standard(2.5 * (1 + 5e-5)) and not modules.is_standard(2.5 * 1.001)
    assert modules.nearest(2.5357) == 2.5
    assert modules.nearest(2.70) == 2.75  # series II is nearer
    assert modules.nearest(2.5357, low=2.6) == 2.75
    # series I first, then the nearest listed; scale = m_std / m
    cand = modules.scale_candidates(2.70)
    assert [c for c, _ in cand] == [2.5, 2.75]
    assert cand[0][1] == pytest.approx(2.5 / 2.70) and cand[1][1] == pytest.approx(2.75 / 2.7)
    # nothing within 10 %
    assert modules.scale_candidates(2.5357, [1.0, 4.0]) == []
    assert modules.largest_at_most(2.7) == 2.5
    assert modules.largest_at_most(2.7, first_series=False) == 2.5
    assert modules.largest_at_most(2.8, first_series=False) == 2.75
    assert modules.largest_at_most(0.4) is None


class _Man:
    def __init__(self, modules_mm=None, special_module=False):
        self.modules_mm, self.special_module = modules_mm, special_module


def test_module_finding():
    f = modules.module_finding("internal_planet", 2.5357, _Man())
    assert f["check"] == "standard_module" and f["limit"] == 2.5 and f["value"] == 2.5357
    assert "0.9859" in f["why"]  # the scale to the nearest cutter
    assert modules.module_finding("p", 2.5, _Man()) is None
    assert modules.module_finding("p", 2.5357, _Man(special_module=True)) is None
    # the workshop's own list
    assert modules.module_finding("p", 2.75, _Man([2.0, 3.0]))["limit"] == 3.0
    assert modules.module_finding("p", 3.0, _Man([2.0, 3.0])) is None


def test_a_gear_cut_at_a_non_standard_module_is_a_finding(tmp_path):
    """The elliptic train's default: the largest series-I module its curves allow (the
    undercut bound at the ellipse's near vertex, 2 (B^2 / A) / 17.1 = 2.83 mm: 2.5 mm), on
    the sun the odd tooth count nearest P / (2.5 pi) = 19.8 (the sun and idler 1 are the
    same ellipse about its focus turning 1:1: an odd count makes them identical, issue 35):
    19 teeth closing at 2.6101 mm, not a cutter's; without the file's special_module the cut
    gears carry the
    finding, and the record says what was chosen and why."""
    from plantmech.design import load_design
    from plantmech.workflows import run_gears

    doc = tomllib.loads((EXAMPLES / "rotary_transplanter_elliptic.toml").read_text())
    assert doc["manufacturing"]["special_module"] is True
    del doc["manufacturing"]["special_module"]
    rec = run_gears(load_design(doc, name="e.toml"), tmp_path, steps=36)
    std = [f for f in rec["findings"] if f["check"] == "standard_module"]
    assert rec["verdict"]["label"] == "not manufacturable"
    assert {f["gear"] for f in std} == {"sun_idler1", "idler1_planet"}
    m = rec["gears"][0]["module_mm"]
    # the module: the sun's pitch perimeter (ellipse A = 25, e = 0.18) over 25 pi
    a, e = 25.0, 0.18
    t = np.linspace(0, 2 * np.pi, 200001)
    perim = np.trapezoid(np.hypot(a * np.sin(t), a * np.sqrt(1 - e**2) * np.cos(t)), t)
    b = a * np.sqrt(1 - e**2)
    high = 2 * (b**2 / a) / (2 / np.sin(np.radians(20)) ** 2)
    assert 2.5 < high < 3.0  # the window holds 2.5 mm, not 3
    x = perim / (2.5 * np.pi)
    z = min((k for k in range(1, 60, 2)), key=lambda k: abs(k - x))  # the nearest odd
    assert z == 19 and m == pytest.approx(perim / (z * np.pi), rel=1e-4)
    assert std[0]["value"] == pytest.approx(m, rel=1e-6) and std[0]["limit"] == 2.5
    ch = rec["module_choice"][0]
    assert ch["source"] == "default" and ch["standard_module_mm"] == 2.5
    assert ch["teeth"] == 19 and ch["window_mm"][1] == pytest.approx(high, rel=0.01)


def test_choose_teeth_closes_the_curve_with_a_standard_module():
    """The workshop's default (gears.modules.choose_teeth), against perimeter / (pi m) by
    hand: the largest series-I module in the window, the nearest whole tooth count (in
    multiples of the lobes / turns) whose closing module stays in the window."""
    ch = modules.choose_teeth
    # a circle of radius 50 mm and a window up to 5.85 mm: 5 mm, 2 r / m = 20 teeth exactly
    c = ch(2 * np.pi * 50.0, 5.85, 1.0)
    assert (c["standard_module_mm"], c["teeth"]) == (5.0, 20)
    assert c["module_mm"] == pytest.approx(5.0) and c["scale_to_standard"] == pytest.approx(1)
    # 381.13 mm at 1.5 mm: 381.13 / (1.5 pi) = 80.88 -> 81 teeth, closing at P / (81 pi)
    P = 381.13
    c = ch(P, 1.85, 1.0)
    assert (c["standard_module_mm"], c["teeth"], c["series"]) == (1.5, 81, "I")
    assert c["module_mm"] == pytest.approx(P / (81 * np.pi), rel=1e-12)
    assert c["scale_to_standard"] == pytest.approx(1.5 * 81 * np.pi / P, rel=1e-5)
    # 4 lobes: 704.65 / (3 pi) = 74.77; multiples of 4 are 72 (m 3.115) and 76 (m 2.951):
    # 76 is nearer the cutter's module
    c = ch(704.65, 3.2, 2.5, 4)
    assert (c["standard_module_mm"], c["teeth"]) == (3.0, 76)
    assert c["module_mm"] == pytest.approx(704.65 / (76 * np.pi))
    # rounding to the nearest count would push the module past the window's top: the
    # other count (74.3 -> 74 gives 3.012 mm > 3.0; 75 gives 2.972 mm)
    c = ch(74.3 * 3 * np.pi, 3.0, 1.0)
    assert c["teeth"] == 75 and c["module_mm"] <= 3.0
    # series I first (2.5 before 2.75), unless the workshop lists its cutters
    assert ch(300.0, 2.8, 1.0)["standard_module_mm"] == 2.5
    assert ch(300.0, 2.8, 1.0, modules=[1.75, 2.75])["standard_module_mm"] == 2.75
    # a pair's mate counts too: a mate of twice the perimeter carries twice the teeth
    c = ch(2 * np.pi * 50.0, 5.85, 1.0, mates={"mate": 4 * np.pi * 50.0}, gear="g")
    assert c["teeth_per_gear"] == {"g": 20, "mate": 40}


def test_choose_teeth_without_a_standard_module_in_the_window():
    ch = modules.choose_teeth
    # the curves allow 2.2 mm, the design asks for 2.5 (strength): 2.5 kept, said so
    c = ch(300.0, 2.2, 2.5)
    assert c["standard_module_mm"] == 2.5 and not c["fits_window"]
    assert c["teeth"] == round(300.0 / (2.5 * np.pi)) and "undercut" in c["why"]
    # the curves allow less than any cutter (0.356 mm), the design 1 mm or more: 1 mm
    c = ch(529.53, 0.356, 1.0)
    assert c["standard_module_mm"] == 1.0 and c["teeth"] == round(529.53 / np.pi) == 169
    # 1 mm would leave 2000 / pi = 637 teeth (> 500), 1.125 566, 1.25 509: the next up,
    # 1.375 mm, leaves 463
    c = ch(2000.0, 0.356, 1.0)
    assert c["standard_module_mm"] == 1.375 and c["teeth"] == round(2000 / (1.375 * np.pi))
    # nothing at or above 60 mm: the largest below whose whole count has at least 6 teeth
    # (300 / (18 pi) = 5.3: 6 teeth, closing at 300 / (6 pi) = 15.9 mm; 20 mm: 4.8 -> 5)
    c = ch(300.0, 0.1, 60.0)
    assert (c["standard_module_mm"], c["teeth"]) == (18.0, 6)
    assert c["module_mm"] == pytest.approx(300 / (6 * np.pi))
    assert "below the design's" in c["why"]
    # no cutter leaves 6-500 teeth: refused, naming the option that overrides
    with pytest.raises(ValueError, match="--module"):
        ch(600 * np.pi * 50.0 * 2, 0.4, 0.1)
