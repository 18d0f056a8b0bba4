import numpy as np
import pytest

from plantmech.gears.pitch import (
    body_polar_curve,
    radii_from_speed_ratio,
    toothless_sector_follower_angle,
)


def test_radii_from_ratio_eq9():
    # i = omega_d/omega_f = 2 -> follower twice the driver: r_f = 2a/3, r_d = a/3
    rd, rf = radii_from_speed_ratio(120.0, 0.5)
    assert rd == pytest.approx(40.0)
    assert rf == pytest.approx(80.0)
    rd, rf = radii_from_speed_ratio(120.0, 0.0)
    assert rd == 0.0 and rf == 120.0


def test_eq5_geometry():
    # chord ends of the toothless arc seen from the follower centre at (a, 0)
    a, R2, th1 = 127.0, 40.0, np.radians(45.0)
    p = R2 * np.array([np.cos(th1 / 2), np.sin(th1 / 2)])
    expected = 2 * np.arctan2(p[1], a - p[0])
    assert toothless_sector_follower_angle(th1, R2, a) == pytest.approx(expected)


def test_body_polar_curve_wraps():
    ang = np.radians([350.0, 10.0, 100.0, 200.0])
    r = np.array([1.0, 3.0, 5.0, 7.0])
    got = body_polar_curve(ang, r, np.radians([0.0, 355.0]))
    assert got == pytest.approx([2.0, 1.5])
