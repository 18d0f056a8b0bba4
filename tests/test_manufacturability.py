"""The manufacturability rules against cases whose numbers are known by hand."""

import numpy as np
import pytest

from plantmech.gears.manufacturability import (
    CuttingRules,
    PairShape,
    assess_pair,
    choose_module,
    findings,
    shape_from_polar,
    violation,
)

N = 4096
T = np.linspace(0.0, 2 * np.pi, N, endpoint=False)


def _circle_pair(radius, mate_radius, module=None, rules=None):
    a = radius + mate_radius
    r = np.full((1, N), radius)
    z = np.zeros((1, N))
    g1 = shape_from_polar("g1", T, r, z, z)
    mate = np.full((1, N), a - radius)
    g2 = shape_from_polar("g2", T, mate, z, z, np.full((1, N), radius / mate_radius), z)
    return assess_pair(PairShape("g1_g2", (g1, g2), np.zeros((1, N)),
                                 module=None if module is None else np.array([module])),
                       rules or CuttingRules())


def test_involute_circle_undercut_limit_is_the_textbook_17():
    rules = CuttingRules()
    assert rules.undercut_teeth == pytest.approx(2 / np.sin(np.radians(20)) ** 2)
    assert rules.undercut_teeth == pytest.approx(17.097, abs=1e-3)
    # at 20 deg the standard tooth is pointed (top land 0.25 m) only far below the undercut
    # limit, so undercut decides: z_eq >= 17.1
    assert rules.pointed_teeth < rules.undercut_teeth
    # a 17-tooth circular gear at m = 2 (r = 17 mm) is undercut, an 18-tooth one is not
    v17 = _circle_pair(17.0, 40.0, module=2.0)
    v18 = _circle_pair(18.0, 40.0, module=2.0)
    assert not v17.module_ok[0] and v18.module_ok[0]
    assert v18.bounds["undercut/pointed g1"][0] == pytest.approx(2 * 18 / 17.097, rel=1e-4)
    f = findings(v17, rules)
    assert f and f[0]["gear"] == "g1" and "undercut" in f[0]["why"]
    assert v18.teeth["g1"][0] == 18
    # a mate's perimeter is the arc it rolls over one period of t: one turn of equal circles
    v = _circle_pair(30.0, 30.0, module=2.0)
    assert v.teeth["g1"][0] == 30 and v.teeth["g2"][0] == 30


def test_stub_teeth_and_larger_pressure_angle_lower_the_limit():
    stub = CuttingRules(pressure_angle_deg=25.0, addendum=0.8)
    assert stub.undercut_teeth == pytest.approx(1.6 / np.sin(np.radians(25)) ** 2)
    assert stub.undercut_teeth < 9.0


def test_ellipse_about_its_focus_smallest_radius_of_curvature():
    A, e = 40.0, 0.5
    p = A * (1 - e**2)  # semi-latus rectum = B^2 / A = the smallest radius of curvature
    d = 1 - e * np.cos(T)
    r = p / d
    r1 = -p * e * np.sin(T) / d**2
    r2 = -p * e * np.cos(T) / d**2 + 2 * p * e**2 * np.sin(T) ** 2 / d**3
    g = shape_from_polar("ellipse", T, r[None], r1[None], r2[None])
    assert g.curvature_radius.min() == pytest.approx(p, rel=1e-6)
    # perimeter of the ellipse, Ramanujan's second approximation
    B = A * np.sqrt(1 - e**2)
    h = ((A - B) / (A + B)) ** 2
    ram = np.pi * (A + B) * (1 + 3 * h / (10 + np.sqrt(4 - 3 * h)))
    assert g.perimeter[0] == pytest.approx(ram, rel=1e-6)
    rules = CuttingRules()
    v = assess_pair(PairShape("e_e", (g, g), np.arctan(np.abs(r1) / r)[None]), rules)
    assert v.bounds["undercut/pointed ellipse"][0] == pytest.approx(
        2 * p / rules.undercut_teeth, rel=1e-6)
    # mu of an ellipse about its focus: tan mu = e sin / (1 - e cos); max at cos = e
    mu_max = np.degrees(np.arctan(e / np.sqrt(1 - e**2)))
    assert v.working_pressure_angle_deg[0] == pytest.approx(20 + mu_max, abs=1e-3)


def test_concave_span_needs_a_shaper_smaller_than_its_radius():
    R0, eps = 50.0, 0.15
    r = R0 * (1 + eps * np.cos(3 * T))
    r1 = -3 * R0 * eps * np.sin(3 * T)
    r2 = -9 * R0 * eps * np.cos(3 * T)
    g = shape_from_polar("trefoil", T, r[None], r1[None], r2[None])
    # by hand at the radius minima (theta = 60 deg): r' = 0, rho = r^2 / (r - r'')
    rho_hand = R0 * (1 - eps) ** 2 / (1 - 10 * eps)
    assert rho_hand == pytest.approx(-72.25)
    concave = -g.curvature_radius[g.curvature_radius < 0]
    assert concave.min() == pytest.approx(-rho_hand, rel=1e-6)
    rules = CuttingRules(min_cutter_teeth=12, min_internal_difference=8)
    v = assess_pair(PairShape("t", (g, g), np.zeros((1, N))), rules)
    m_hand = 2 * 72.25 / (12 + 8)  # 7.225 mm: a 12-tooth shaper, 8 teeth of difference
    assert v.bounds["concave span trefoil"][0] == pytest.approx(m_hand, rel=1e-6)
    where = v.where["concave span trefoil"][1][0]
    assert min(abs(where - a) for a in (60, 180, 300)) < 0.2


def test_working_pressure_angle_and_violation():
    rules = CuttingRules(max_working_pressure_angle_deg=45.0)
    v = _circle_pair(30.0, 30.0)
    assert v.working_pressure_angle_deg[0] == pytest.approx(20.0)
    assert violation(v, rules).max() == 0.0
    assert v.ok(rules)[0]
    mu = np.full((1, N), np.radians(40.0))
    r = np.full((1, N), 30.0)
    z = np.zeros((1, N))
    s = shape_from_polar("c", T, r, z, z)
    v2 = assess_pair(PairShape("c_c", (s, s), mu), rules)
    assert v2.working_pressure_angle_deg[0] == pytest.approx(60.0)
    assert violation(v2, rules)[0, 1] == pytest.approx(15.0 / 45.0)
    assert findings(v2, rules)[0]["check"] == "working pressure angle"


def test_choose_module_takes_the_largest_standard_module_with_whole_teeth():
    P = np.pi * 60.0  # a 60 mm pitch circle
    m = choose_module(P, 1.0, 2.7)
    assert m[0] == pytest.approx(2.5)  # 24 teeth
    m = choose_module(P, 1.0, 2.2)  # 2.0 -> 30 teeth
    assert m[0] == pytest.approx(2.0)
    assert np.isnan(choose_module(P, 3.0, 2.0)[0])
