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
    """The elliptic train's default module makes 25 whole teeth on the sun: 1.9837 mm, not a
    cutter's; without the file's special_module the cut gears carry the finding."""
    from plantmech.design import load_design
    from plantmech.workflows import run_gears

    doc = tomllib.loads((EXAMPLES / "rotary_transplanter_elliptic.toml").read_text())
    assert doc["manufacturing"]["special_module"] is True
    del doc["manufacturing"]["special_module"]
    rec = run_gears(load_design(doc, name="e.toml"), tmp_path, steps=36)
    std = [f for f in rec["findings"] if f["check"] == "standard_module"]
    assert rec["verdict"] == "not manufacturable"
    assert {f["gear"] for f in std} == {"sun_idler1", "idler1_planet"}
    m = rec["gears"][0]["module_mm"]
    # the module: the sun's pitch perimeter (ellipse A = 25, e = 0.18) over 25 pi
    a, e = 25.0, 0.18
    t = np.linspace(0, 2 * np.pi, 200001)
    perim = np.trapezoid(np.hypot(a * np.sin(t), a * np.sqrt(1 - e**2) * np.cos(t)), t)
    assert m == pytest.approx(perim / (25 * np.pi), rel=1e-4)
    assert std[0]["value"] == pytest.approx(m, rel=1e-6) and std[0]["limit"] == 2.0
