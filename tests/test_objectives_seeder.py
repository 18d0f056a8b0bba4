import numpy as np
import pytest

from plantmech.design import PlanningLimits
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.objectives.seeder import attitude_by_section, planning_checks


def figure_eight(W=200.0, H=150.0, H2=450.0, W2=300.0, n=200):
    """Upper loop (t in 0..pi) W wide, H high; lower loop W2 wide, H2 high, crossing at
    (500, 100)."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False) + 1e-3
    upper = np.sin(t) >= 0
    x = 500 + np.where(upper, W / 2, W2 / 2) * np.sin(2 * t)
    y = 100 + np.where(upper, H, H2) * np.sin(t)
    return np.c_[x, y], t


def test_ring_extents_of_an_eight():
    pts, t = figure_eight()
    tr = ClosedTrajectory.through(pts)
    k = lambda tt: int(np.argmin(np.abs(t - tt)))  # noqa: E731
    sections = {"a": k(np.pi / 4), "b": k(np.pi / 2), "c": k(np.pi - 0.05),
                "d": k(np.pi + 0.3), "e": k(3 * np.pi / 2), "f": k(1.8 * np.pi)}
    checks = {c.name: c for c in planning_checks(tr, sections, PlanningLimits())}
    assert checks["small_ring_height"].value == pytest.approx(150.0, rel=5e-3)
    assert checks["small_ring_width"].value == pytest.approx(200.0, rel=5e-3)
    assert checks["large_ring_height"].value == pytest.approx(450.0, rel=5e-3)
    assert checks["large_ring_width"].value == pytest.approx(300.0, rel=5e-3)
    assert checks["centre_to_trench_bottom"].value == pytest.approx(350.0, rel=5e-3)
    assert checks["small_ring_height"].ok and checks["large_ring_width"].ok


def test_no_crossing_is_reported_not_guessed():
    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    tr = ClosedTrajectory.through(np.c_[500 + 100 * np.cos(t), 100 * np.sin(t)])
    sections = dict(a=0, b=5, c=10, d=15, e=20, f=30)
    checks = {c.name: c for c in planning_checks(tr, sections, PlanningLimits())}
    assert checks["small_ring_height"].value is None
    assert not checks["small_ring_height"].ok
    assert "crosses itself 0 times" in checks["small_ring_height"].note


def test_attitude_sections():
    psi = np.linspace(0, 2 * np.pi, 360, endpoint=False)
    arm = 10 + 20 * np.sin(psi)  # degrees
    pts = np.radians([0, 60, 120, 180, 240, 300])
    att = attitude_by_section(psi, arm, pts, dict(a=0, b=1, c=2, d=3, e=4, f=5))
    assert att["initial_attitude"] == pytest.approx(10)
    # ab: 0..60 deg, max of 20 sin at 60 deg (values are reported to 4 decimals)
    assert att["picking_ab"]["max"] == pytest.approx(20 * np.sin(np.radians(60)), abs=1e-4)
    assert att["sowing_angle"] == pytest.approx(20 * np.sin(np.radians(240)), abs=1e-4)


def test_speed_lower_bound_is_met_by_every_designed_train():
    """The bound L1 omega |sin(theta - phi)| is zero on the reach circles and the inverse
    design's own speeds never go below it."""
    from scipy.interpolate import CubicSpline

    from plantmech.design import load_design
    from plantmech.objectives.seeder import speed_lower_bound
    from plantmech.workflows import run_seeder_inverse

    from .conftest import EXAMPLES

    assert speed_lower_bound(754.0, 254.0, 500.0) == pytest.approx(0.0, abs=1e-12)
    assert speed_lower_bound(246.0, 254.0, 500.0) == pytest.approx(0.0, abs=1e-12)
    # arm at right angles to the carrier: rho^2 = L1^2 + L2^2, bound = L1 omega
    assert speed_lower_bound(np.hypot(254.0, 500.0), 254.0, 500.0) == pytest.approx(
        0.254 * 2 * np.pi, rel=1e-12)
    res = run_seeder_inverse(load_design(EXAMPLES / "sugarcane_seeder.toml")).result
    psi, tip = res.carrier_angle, res.tip_realized
    spl = CubicSpline(np.r_[psi, 2 * np.pi], np.vstack([tip, tip[:1]]), bc_type="periodic")
    v = np.hypot(*spl(psi, 1).T) * 2 * np.pi / 1000
    bound = speed_lower_bound(np.hypot(*tip.T), res.L1, res.L2)
    assert np.all(v >= bound - 1e-6)


def test_seeding_speed_need_is_the_least_speed_with_enough_vertical_speed():
    """Against a brute-force search over the free across-arm component: the along-arm
    component is the carrier's, L1 omega sin(phi - theta)."""
    from plantmech.objectives.seeder import seeding_speed_need

    L1, w = 254.0, 2 * np.pi  # mm, rad/s (360 deg/s)
    phi = np.radians([-40.0, 10.0, 75.0, 200.0])
    theta = np.radians([-16.0, -24.0, 80.0, 30.0])
    along, need = seeding_speed_need(L1, phi, theta, 360.0, 1.1)
    assert along == pytest.approx(L1 * w * np.sin(phi - theta) / 1000)
    across = np.linspace(-8, 8, 800001)[None, :]
    vx = along[:, None] * np.cos(theta)[:, None] - across * np.sin(theta)[:, None]
    vy = along[:, None] * np.sin(theta)[:, None] + across * np.cos(theta)[:, None]
    speed = np.where(np.abs(vy) >= 1.1, np.hypot(vx, vy), np.inf).min(axis=1)
    assert need == pytest.approx(speed, abs=1e-4)


def _old_periodic_at(psi, values, p):
    """The interpolation as it was before the table was shared (one table per call)."""
    return float(np.interp(np.mod(p, 2 * np.pi), np.r_[psi, 2 * np.pi], np.r_[values, values[0]]))


def test_shared_periodic_table_gives_identical_numbers():
    """One table per cycle (``_periodic_table``) and one interpolation for several angles
    give bit-identical values to one table per angle, at samples, between samples, at 0,
    2 pi, past 2 pi and at negative angles, and the section speeds are identical."""
    from plantmech.objectives.seeder import (
        _periodic_at,
        _periodic_table,
        section_values,
        speed_by_section,
        zero_speed_travel,
    )

    rng = np.random.default_rng(3)
    n = 360
    psi = np.linspace(0, 2 * np.pi, n, endpoint=False)
    values = rng.normal(size=n)
    angles = np.r_[psi[::7], rng.uniform(-10, 10, 50), 0.0, 2 * np.pi, -2 * np.pi, 7.5,
                   psi[-1] + 1e-9, 2 * np.pi - 1e-12]
    table = _periodic_table(psi)
    together = _periodic_at(table, values, angles)
    one_by_one = [_old_periodic_at(psi, values, p) for p in angles]
    assert together.tolist() == one_by_one  # exact, not approximate
    assert [_periodic_at(table, values, p) for p in angles] == one_by_one
    # an interpolation between two samples is the straight line between them
    assert _periodic_at(table, values, (psi[3] + psi[4]) / 2) == pytest.approx(
        (values[3] + values[4]) / 2, rel=1e-12, abs=1e-12)
    # past the last sample it closes on the first (the cycle is periodic)
    assert _periodic_at(table, values, (psi[-1] + 2 * np.pi) / 2) == pytest.approx(
        (values[-1] + values[0]) / 2, rel=1e-12, abs=1e-12)

    velocity = rng.normal(size=(n, 2))
    sec = {"d": 4.1, "e": 4.9, "f": 5.6}
    static = np.hypot(velocity[:, 0], velocity[:, 1])
    dynamic = np.hypot(velocity[:, 0] - 0.3, velocity[:, 1])

    def old_section(v, a, b):
        span = np.mod(b - a, 2 * np.pi)
        m = np.mod(psi - a, 2 * np.pi) <= span
        return np.r_[v[m], _old_periodic_at(psi, v, a), _old_periodic_at(psi, v, b)]

    assert section_values(psi, static, sec["e"], sec["f"]).tolist() == old_section(
        static, sec["e"], sec["f"]).tolist()
    s = speed_by_section(psi, velocity, 0.3, sec)
    assert s["max_speed_seeding_m_s"] == float(old_section(static, sec["d"], sec["e"]).max())
    assert s["min_speed_return_static_m_s"] == float(
        old_section(static, sec["e"], sec["f"]).min())
    assert s["min_speed_return_dynamic_m_s"] == float(
        old_section(dynamic, sec["e"], sec["f"]).min())
    assert s["max_speed_seeding_dynamic_m_s"] == float(
        old_section(dynamic, sec["d"], sec["e"]).max())
    z = zero_speed_travel(psi, velocity, 10.0, sec["e"])
    assert z["zero_speed_travel_m_s"] == _old_periodic_at(psi, velocity[:, 0], sec["e"])
    assert z["speed_at_e_m_s"] == float(np.hypot(_old_periodic_at(psi, velocity[:, 0], sec["e"]),
                                                 _old_periodic_at(psi, velocity[:, 1], sec["e"])))
