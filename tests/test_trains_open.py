"""Open pitch curves of the train model (trains/curves.py ``open``: a break at body angle
0, seed 000's inverse-designed gears with a dwell), their pair law (trains/pairs.py: the
running integral F across the radius step, its inversion, the solved centre distance, the
mate's matching break) against closed forms, and the design file's validation.

The analytic case: a driver whose radius grows linearly over its open turn, r(t) = R0 + A t
(0 <= t < 2 pi; right limit R0 at the break, left limit R0 + 2 pi A), an external pair at
centre distance a. Then g = r / (a - r) and

    F(t) = integral_0^t g = -(a / A) ln((a - R0 - A t) / (a - R0)) - t,

continuous across the break (F(t + 2 pi) = F(t) + F(2 pi)), its slope stepping there.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from plantmech.trains.curves import TWO_PI, convexity, interpolated
from plantmech.trains.pairs import PairError, pair_law

R0, A, CD = 20.0, 2.0, 60.0


def _exact_F(t):
    return -(CD / A) * np.log((CD - R0 - A * t) / (CD - R0)) - t


def _ramp(grid=4096, kind="spline"):
    nodes = np.linspace(0.0, TWO_PI, 40)
    return interpolated(nodes, R0 + A * nodes, grid, kind, open_turn=True, name="ramp")


@pytest.mark.parametrize("kind", ["spline", "hermite"])
def test_open_curve_keeps_both_limits_and_never_reads_across_the_break(kind):
    c = _ramp(kind=kind)
    assert c.open and c.r[0, 0] == pytest.approx(R0) and c.r_end[0] == pytest.approx(
        R0 + A * TWO_PI)
    t = np.array([[1e-9, 0.5, 3.0, TWO_PI - 1e-9, -1e-9, TWO_PI, 7.0]])
    r, dr = c(t)
    # a line is reproduced exactly by both interpolants (the spline's not-a-knot ends, the
    # Hermite's one-sided end slopes): the left limit just before 2 pi, the right just after
    expected = R0 + A * np.mod(t, TWO_PI)
    assert np.abs(r - expected).max() < 1e-9
    assert np.abs(dr - A).max() < 1e-7


def test_open_curve_refuses_lobes_and_angles_that_do_not_span_the_turn():
    from plantmech.trains.curves import CurveError

    with pytest.raises(CurveError, match="one lobe"):
        interpolated(np.linspace(0, TWO_PI, 8), np.full(8, 10.0), 512, "spline", lobes=2,
                     open_turn=True)
    with pytest.raises(CurveError, match="from 0 deg"):
        interpolated(np.linspace(0.1, TWO_PI, 8), np.full(8, 10.0), 512, "spline",
                     open_turn=True)


def test_running_integral_across_the_break_equals_the_closed_form():
    law = pair_law("external", _ramp(), 1.0, CD, tolerance=10.0, periodic_mate=False)
    t = np.array([[0.0, 0.3, 1.0, 3.0, 6.0, TWO_PI - 1e-7]])
    F, g = law.F(t)
    assert np.abs(F - _exact_F(t)).max() < 1e-10
    assert law.q_e[0] == pytest.approx(_exact_F(TWO_PI) / TWO_PI, abs=1e-12)
    # continuous across the break, the ratio stepping there from the left to the right limit
    eps = 1e-8
    F2, g2 = law.F(np.array([[TWO_PI - eps, TWO_PI + eps]]))
    assert F2[0, 1] - F2[0, 0] == pytest.approx(0.0, abs=1e-6)
    assert g2[0, 0] == pytest.approx((R0 + A * TWO_PI) / (CD - R0 - A * TWO_PI), rel=1e-6)
    assert g2[0, 1] == pytest.approx(R0 / (CD - R0), rel=1e-6)
    # the inversion, either side of the break and a turn on
    y = np.array([[0.5, 2.0, _exact_F(TWO_PI) - 1e-6, _exact_F(TWO_PI) + 0.1]])
    theta = law.invert(y)
    assert np.abs(law.F(theta)[0] - y).max() < 1e-11
    assert theta[0, 1] == pytest.approx(brentq(lambda x: _exact_F(x) - 2.0, 0, TWO_PI),
                                        abs=1e-10)


def test_solved_centre_distance_closes_the_open_law():
    """The centre distance at which the follower turns once per driver turn: the root of
    F(2 pi; a) = 2 pi with the closed form (brentq), not the grid's periodic mean."""
    law = pair_law("external", _ramp(), 1.0, None, periodic_mate=False)

    def closure(a):
        return -(a / A) * np.log((a - R0 - A * TWO_PI) / (a - R0)) - 2 * TWO_PI

    a_exact = brentq(closure, R0 + A * TWO_PI + 1e-6, 500.0)
    assert law.a[0] == pytest.approx(a_exact, abs=1e-9)
    assert abs(law.closure_error[0]) < 1e-11


def test_mate_of_an_open_driver_breaks_at_its_zero_with_the_matching_limits():
    """Follower angle phi = -F(theta_d) (external): just after 0 the contact is on the
    driver's end of turn (theta_d -> 2 pi from below), just before 2 pi on its start."""
    law = pair_law("external", _ramp(), 1.0, CD, tolerance=10.0, periodic_mate=False)
    mate = law.mate("mate")
    assert mate.open
    assert mate.r[0, 0] == pytest.approx(CD - (R0 + A * TWO_PI), abs=1e-9)
    assert mate.r_end[0] == pytest.approx(CD - R0, abs=1e-9)
    for phi in (0.2, 2.0, 5.0):
        # the closed form: the driver angle whose F is the wrapped phi (F rises by q_e 2 pi
        # per turn, here not exactly 2 pi: the follower's angle is measured on its own turn)
        period = _exact_F(TWO_PI)
        target = np.mod(-phi, period)
        theta_d = brentq(lambda x, y=target: _exact_F(x) - y, 0.0, TWO_PI)
        assert mate(np.array([[phi]]))[0][0, 0] == pytest.approx(CD - (R0 + A * theta_d),
                                                                  abs=1e-9)


def test_open_driver_needs_one_follower_turn():
    with pytest.raises(PairError, match="follower_turns = 1"):
        pair_law("external", _ramp(), 2.0)


def test_convexity_does_not_see_the_break_as_a_kink():
    """A ramp's r'' is 0 on both sides: the break's step is not read as curvature."""
    c = _ramp()
    from plantmech.trains.curves import second_derivative

    assert np.abs(second_derivative(c)).max() < 1e-6
    assert convexity(c)["convex"][0]


def _doc(**follower):
    """A design file with an open given follower on a dwell pair (fields overridden)."""
    import tomllib

    from tests.conftest import EXAMPLES

    doc = tomllib.loads((EXAMPLES / "planetary" / "sugarcane_table4.toml").read_text())
    f = doc["train"]["pairs"][0]["follower"]
    f.update(radii_mm=[55.4, 54.9, 62.0, 74.0, 52.9, 60.9, 58.9, 55.9, 60.0],
             angles_deg=[0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0, 360.0],
             interpolation="spline", open=True)
    f.update(follower)
    doc["train"]["pairs"][0].pop("centre_distance_mm")  # solved: the new curve closes there
    return doc


@pytest.mark.parametrize("change, field, words", [
    (lambda d: d["train"]["pairs"][0].pop("dwell"), "pairs.0.follower.open",
     "toothless dwell"),
    (lambda d: d["train"]["pairs"][0]["follower"].update(lobes=2), "open", "one lobe"),
    (lambda d: d["train"]["pairs"][0].update(follower_turns=2.0), "pairs.0.follower.open",
     "follower_turns = 1"),
    (lambda d: d["train"]["pairs"][0]["follower"]["angles_deg"].__setitem__(-1, 350.0),
     "angles_deg", "360 deg"),
    (lambda d: d["train"]["pairs"][0]["follower"]["radii_mm"].extend([50.0] * 1000),
     "radii_mm", "at most"),
])
def test_a_break_the_file_cannot_have_is_refused_naming_the_field(change, field, words):
    from plantmech.design import DesignError, load_design

    doc = _doc()
    change(doc)
    if "radii_mm" in field:  # a periodic curve keeps its own limit of control radii
        doc["train"]["pairs"][0]["follower"].update(open=False, angles_deg=None)
        doc["train"]["pairs"][0]["follower"].pop("angles_deg")
    with pytest.raises(DesignError) as exc:
        load_design(doc)
    assert field in str(exc.value) and words in str(exc.value), str(exc.value)


@pytest.mark.parametrize("which", ["train.pairs.0.follower", "train.pairs.1.driver"])
def test_a_break_not_held_by_the_dwell_exits_2_naming_the_field(tmp_path, capsys, which):
    """An open gear 2 (or gear 3) whose break is not at the contact where the dwell starts
    would be rolled across while the teeth mesh: `plantmech forward` exits 2 naming it."""
    import tomli_w

    from plantmech.interfaces.cli import main

    doc = _doc()
    if which.endswith("driver"):  # gear 2 as in Table 4, gear 3 open
        doc["train"]["pairs"][0]["follower"].update(
            radii_mm=[55.4, 54.9, 62.0, 74.0, 52.9, 60.9, 58.9, 55.9], interpolation="hermite",
            angles_deg=[0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0], open=False)
        doc["train"]["pairs"][1]["driver"].update(
            radii_mm=[86.7, 88.0, 68.0, 32.0, 93.1, 71.2, 76.9, 85.3, 80.0],
            angles_deg=[0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0, 360.0],
            interpolation="spline", open=True)
        doc["train"]["pairs"][1].pop("centre_distance_mm")
    path = tmp_path / "open.toml"
    path.write_text(tomli_w.dumps(doc))
    assert main(["forward", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert f"{which}.open" in err and "break" in err, err
    assert not (tmp_path / "o").exists()
