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


def test_section_speeds_and_zero_speed_of_a_known_velocity():
    """One design's section speeds (the section table with P = 1) against the velocity
    law v = (1.2 cos psi, 0.8 sin psi) m/s, the ends of each section interpolated linearly
    between samples (np.interp as the independent reference), at uniform and at
    non-uniform carrier samples (interval lookup)."""
    from plantmech.objectives.seeder import speed_by_section, zero_speed_travel

    rng = np.random.default_rng(3)
    for psi in (np.linspace(0, 2 * np.pi, 720, endpoint=False),
                np.r_[0.0, np.sort(rng.uniform(0.0, 2 * np.pi, 1500))]):
        velocity = np.c_[1.2 * np.cos(psi), 0.8 * np.sin(psi)]
        sec = {"d": 4.1, "e": 4.9, "f": 5.6}

        def at(v, p, psi=psi):
            return np.interp(p, np.r_[psi, 2 * np.pi], np.r_[v, v[0]])

        def section(v, a, b, psi=psi):
            m = (psi >= a) & (psi <= b)
            return np.r_[v[m], at(v, a), at(v, b)]

        static = np.hypot(velocity[:, 0], velocity[:, 1])
        dynamic = np.hypot(velocity[:, 0] - 0.3, velocity[:, 1])
        s = speed_by_section(psi, velocity, 0.3, sec)
        assert s["max_speed_seeding_m_s"] == pytest.approx(section(static, 4.1, 4.9).max(),
                                                           abs=1e-12)
        assert s["min_speed_return_static_m_s"] == pytest.approx(
            section(static, 4.9, 5.6).min(), abs=1e-12)
        assert s["min_speed_return_dynamic_m_s"] == pytest.approx(
            section(dynamic, 4.9, 5.6).min(), abs=1e-12)
        assert s["max_speed_seeding_dynamic_m_s"] == pytest.approx(
            section(dynamic, 4.1, 4.9).max(), abs=1e-12)
        assert s["max_speed_static_m_s"] == pytest.approx(static.max(), abs=1e-12)
        assert s["min_speed_static_m_s"] == pytest.approx(static.min(), abs=1e-12)
        # the ellipse's speed over ef (4.9..5.6 rad, sin^2 growing) is least at e
        assert s["min_speed_return_static_m_s"] == pytest.approx(
            np.hypot(1.2 * np.cos(4.9), 0.8 * np.sin(4.9)), abs=2e-5)
        z = zero_speed_travel(psi, velocity, 10.0, 4.9)
        assert z["zero_speed_travel_m_s"] == pytest.approx(1.2 * np.cos(4.9), abs=2e-5)
        assert z["speed_at_e_m_s"] == pytest.approx(
            np.hypot(at(velocity[:, 0], 4.9), at(velocity[:, 1], 4.9)), abs=1e-12)
        assert z["velocity_direction_at_e_deg"] == pytest.approx(np.degrees(np.arctan2(
            0.8 * np.sin(4.9), 1.2 * np.cos(4.9))), abs=1e-3)
        assert z["eq18_as_printed_m_s"] == pytest.approx(
            z["speed_at_e_m_s"] * np.sin(np.radians(10.0)), rel=1e-12)


def test_attitude_table_at_non_uniform_samples():
    """arm = 10 + 20 sin(psi) deg at 2,000 random carrier angles: start, end, min, max,
    change and the signed swing of each section are the law's (to the interpolation's
    error), and a section that wraps through 0 (ea) is one section."""
    rng = np.random.default_rng(5)
    psi = np.r_[0.0, np.sort(rng.uniform(0.0, 2 * np.pi, 1999))]
    arm = 10 + 20 * np.sin(psi)
    pts = np.radians([0, 60, 120, 180, 240, 300])
    att = attitude_by_section(psi, arm, pts, dict(a=0, b=1, c=2, d=3, e=4, f=5))
    law = lambda deg: 20 * np.sin(np.radians(deg))  # noqa: E731  (relative to psi = 0)
    tol = 2e-3  # linear interpolation between samples <= 1.3 deg apart
    assert att["initial_attitude"] == pytest.approx(10)
    ab, de, ea = att["picking_ab"], att["seeding_de"], att["return_efca"]
    assert ab["start"] == pytest.approx(0.0, abs=1e-12)
    assert ab["end"] == pytest.approx(law(60), abs=tol)
    assert ab["max"] == pytest.approx(law(60), abs=tol) and ab["min"] == pytest.approx(0, abs=tol)
    assert ab["change"] == pytest.approx(law(60), abs=tol)
    # de (180..240 deg): falls from 0 to -17.32, swing negative
    assert de["swing_from_start"] == pytest.approx(law(240), abs=tol)
    assert de["min"] == pytest.approx(law(240), abs=tol)
    # ea (240..360 deg): from -17.32 down to -20 at 270 and back up to 0
    assert ea["min"] == pytest.approx(-20.0, abs=tol) and ea["max"] == pytest.approx(0, abs=tol)
    assert ea["swing_from_start"] == pytest.approx(-law(240), abs=tol)
    assert att["sowing_angle"] == pytest.approx(law(240), abs=tol)
    assert att["sowing_angle_to_horizontal"] == pytest.approx(10 + law(240), abs=tol)


def test_speeds_where_the_tip_passes_points():
    """A tip on a 300 mm circle at 720 samples, speed 300 omega: points 310 mm out at
    40.05 and 80 deg are passed at the nearest samples (40 and 80 deg), 10 mm away; only
    the samples within the section [30, 90] deg count."""
    from plantmech.objectives.seeder import speeds_at_points

    psi = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    tip = np.c_[300 * np.cos(psi), 300 * np.sin(psi)]
    w = 2 * np.pi  # rad/s
    vel = np.c_[-300 * np.sin(psi), 300 * np.cos(psi)] * w / 1000  # m/s
    where = np.radians([40.05, 80.0])
    pts = np.c_[310 * np.cos(where), 310 * np.sin(where)]
    got = speeds_at_points(psi, tip, vel, pts, np.radians(30), np.radians(90), 0.5)
    assert got["carrier_angle_deg"] == pytest.approx([40.0, 80.0], abs=1e-9)
    assert got["miss_mm"][1] == pytest.approx(10.0, abs=1e-9)
    assert got["speed_m_s"] == pytest.approx([0.3 * w, 0.3 * w], rel=1e-12)
    k = np.radians(80.0)
    assert got["dynamic_speed_m_s"][1] == pytest.approx(
        np.hypot(-0.3 * w * np.sin(k) - 0.5, 0.3 * w * np.cos(k)), rel=1e-12)
    # outside the section the nearer samples are not used
    far = speeds_at_points(psi, tip, vel, pts[:1], np.radians(50), np.radians(90), 0.0)
    assert far["carrier_angle_deg"][0] == pytest.approx(50.0, abs=1e-9)
