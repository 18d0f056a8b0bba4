import numpy as np
import pytest

from plantmech.gears.closure import (
    ClosureError,
    close_pair,
    mate_turn,
    solve_centre_distance,
    solve_radial_offset,
    solve_scale,
)
from plantmech.geometry.periodic import RadiusCurve

TH = np.radians(np.arange(8) * 45.0)
TABLE4_R3 = np.array([86.7, 88.0, 68.0, 32.0, 93.1, 71.2, 76.9, 85.3])


def test_mate_turn_of_circles_is_the_radius_ratio():
    c = RadiusCurve.from_samples(TH, np.full(8, 40.0))
    assert mate_turn(c, 100.0) == pytest.approx(2 * np.pi * 40 / 60, rel=1e-12)


def test_each_restoration_closes_the_pair():
    for method in ("centre_distance", "radial_offset", "scale"):
        curve, a, fix = close_pair("gear 3 - planet", TH, TABLE4_R3, 127.0, 2 * np.pi, method,
                                   kind="hermite", name="gear 3")
        assert abs(mate_turn(curve, a) - 2 * np.pi) < 1e-10
        assert fix.residual_rad < 1e-10
        assert fix.turn_as_given_deg == pytest.approx(591.4, abs=0.1)  # docs/validation.md


def test_restorations_change_only_what_they_say():
    curve = RadiusCurve.from_samples(TH, TABLE4_R3, kind="hermite")
    a = solve_centre_distance(curve)
    assert a == pytest.approx(155.59, abs=0.01)
    c = solve_radial_offset(curve, 127.0)
    s = solve_scale(curve, 127.0)
    shifted = RadiusCurve.from_samples(TH, TABLE4_R3 + c, kind="hermite")
    scaled = RadiusCurve.from_samples(TH, TABLE4_R3 * s, kind="hermite")
    assert mate_turn(shifted, 127.0) == pytest.approx(2 * np.pi, abs=1e-10)
    assert mate_turn(scaled, 127.0) == pytest.approx(2 * np.pi, abs=1e-10)
    # circles: offset and scale that make a 50 mm circle close 1:1 at a = 120 give r = 60
    circ = RadiusCurve.from_samples(TH, np.full(8, 50.0))
    assert solve_radial_offset(circ, 120.0) == pytest.approx(10.0, abs=1e-9)
    assert solve_scale(circ, 120.0) == pytest.approx(1.2, abs=1e-12)


def test_check_refuses_an_unclosed_pair_and_says_how_to_fix_it():
    with pytest.raises(ClosureError) as exc:
        close_pair("gear 3 - planet", TH, TABLE4_R3, 127.0, 2 * np.pi, "check",
                   kind="hermite", name="gear 3")
    msg = str(exc.value)
    assert "do not close" in msg and "591.396 deg" in msg and "155.586 mm" in msg
    assert "train.closure" in msg


def test_check_accepts_a_closed_pair():
    curve, a, fix = close_pair("p", TH, np.full(8, 60.0), 120.0, 2 * np.pi, "check")
    assert a == 120.0 and fix.residual_rad < 1e-12
