import numpy as np
import pytest

from plantmech.geometry.periodic import RadiusCurve, convexity


def test_circle_is_convex_with_its_radius():
    th = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    c = convexity(RadiusCurve.from_samples(th, np.full(12, 40.0)))
    assert c["convex"] and c["concave_spans_deg"] == []
    assert c["min_convex_radius_mm"] == pytest.approx(40.0)


def test_five_lobe_curve_has_five_concave_spans():
    # r = 1 + 0.08 cos 5 phi: concave where r^2 + 2 r'^2 - r r'' < 0, around phi = 36 deg + k 72
    th = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    c = convexity(RadiusCurve.from_samples(th, 1 + 0.08 * np.cos(5 * th)))
    assert not c["convex"]
    assert len(c["concave_spans_deg"]) == 5
    mids = sorted((a + b) / 2 for a, b in c["concave_spans_deg"])
    assert np.allclose(mids, [36, 108, 180, 252, 324], atol=0.5)
    # at phi = 36 deg: r = 0.92, r' = 0, r'' = 2: |rho| = r^3 / (r r'' - r^2) = 0.778688 / 0.9936
    assert c["min_concave_radius_mm"] == pytest.approx(0.778688 / 0.9936, rel=1e-3)
    # at phi = 0: r = 1.08, r'' = -2: rho = r^3 / (r^2 + 2 r) = 1.259712 / 3.3264
    assert c["min_convex_radius_mm"] == pytest.approx(1.259712 / 3.3264, rel=1e-3)


def test_ellipse_about_focus_is_convex():
    A, e = 50.0, 0.35
    t = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    c = convexity(RadiusCurve.from_samples(t, A * (1 - e**2) / (1 - e * np.cos(t))))
    assert c["convex"]


def test_cyclic_runs_wrap_and_edges():
    from plantmech.geometry.periodic import cyclic_runs

    m = np.array([1, 1, 0, 0, 1, 0, 1, 1], dtype=bool)
    assert cyclic_runs(m) == [(4, 4), (6, 1)]  # last run wraps through index 0
    assert cyclic_runs(np.zeros(4, bool)) == []
    assert cyclic_runs(np.ones(4, bool)) == [(0, 3)]
