import numpy as np
import pytest

from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.mechanisms.seeder_inverse import DwellSpec, InverseSettings, inverse_design
from tests.conftest import AnalyticCurve, known_motion


def wrap(a):
    return np.angle(np.exp(1j * a))


@pytest.mark.parametrize("A,B,phi0,off", [(0.35, 0.1, 0.3, 0.0), (-0.2, 0.25, 2.0, 1.1),
                                          (0.6, -0.15, -1.0, 2.5)])
def test_known_motion_is_recovered(A, B, phi0, off):
    fn, angles = known_motion(L1=110.0, L2=260.0, phi0=phi0, arm_offset=off, A=A, B=B)
    curve = AnalyticCurve(fn)
    res = inverse_design(curve, InverseSettings(samples=720))
    assert res.feasible, [d.message for d in res.diagnostics]
    assert res.L1 == pytest.approx(110.0, abs=1e-6)
    assert res.L2 == pytest.approx(260.0, abs=1e-6)
    carrier, arm = angles(res.u)
    assert np.abs(wrap(res.carrier_abs - carrier)).max() < 1e-6
    assert np.abs(wrap(res.arm_angle - arm)).max() < 1e-6
    # uniform carrier steps, clockwise
    assert np.allclose(np.diff(np.unwrap(res.carrier_abs)), -2 * np.pi / 720, atol=1e-6)
    # the gear train reproduces the planned tip
    assert np.hypot(*(res.tip_realized - res.tip).T).max() < 1e-3


def test_known_ratio_law_is_recovered():
    A, B = 0.35, 0.1
    fn, _ = known_motion(A=A, B=B)
    res = inverse_design(AnalyticCurve(fn), InverseSettings(samples=1440))
    # planet_rel as a function of the curve parameter u is u + A sin u + B sin 2u and
    # the carrier turns exactly u, so d psi4 / d psi = 1 + A cos u + 2B cos 2u
    u = np.unwrap(res.u - res.u[0]) + res.u[0]
    expected = 1 + A * np.cos(u) + 2 * B * np.cos(2 * u)
    # 1e-5: next to the reach circles the angle at O is ill-conditioned (beta_1 goes as
    # sqrt(rho_max - rho)), so a sample's planet angle carries ~1e-8 rad of round-off,
    # which the spline slope turns into ~3e-6 (1e-7 elsewhere)
    err = np.abs(res.total_ratio - expected)
    assert err.max() < 1e-5
    assert np.median(err) < 1e-7


def test_pitch_curves_close_and_split():
    fn, _ = known_motion()
    res = inverse_design(AnalyticCurve(fn), InverseSettings(samples=1440))
    assert res.closure_error["stage1"] < 1e-9
    assert res.closure_error["stage2"] < 1e-9
    assert np.allclose(res.r1 + res.r2, res.a1)
    assert np.allclose(res.r3 + res.r4, res.a2)
    # stage ratios multiply to the total (Eq. 7)
    assert np.allclose(res.stage1_ratio * res.stage2_ratio, res.total_ratio, rtol=1e-9)


def test_uniform_planet_gives_circular_gears():
    # planet_rel = psi: the arm keeps its orientation, the tip draws a circle of radius
    # L1 about (L2 cos c, L2 sin c) and every gear is a circle of radius a/2.
    L1, L2, c = 120.0, 300.0, 0.7
    fn = lambda u: np.stack([L1 * np.cos(-u) + L2 * np.cos(c),  # noqa: E731
                             L1 * np.sin(-u) + L2 * np.sin(c)], axis=-1)
    res = inverse_design(AnalyticCurve(fn), InverseSettings(samples=720))
    assert res.feasible
    for r, a in ((res.r1, res.a1), (res.r2, res.a1), (res.r3, res.a2), (res.r4, res.a2)):
        assert np.abs(r - a / 2).max() < 1e-4  # 0.1 um; arccos conditioning at rho extremes
    # and from a spline through 90 points on that circle
    t = np.linspace(0, 2 * np.pi, 90, endpoint=False)
    res2 = inverse_design(ClosedTrajectory.through(fn(t)), InverseSettings(samples=720))
    assert np.abs(res2.r1 - res2.a1 / 2).max() < 1e-3


def test_table2_as_printed_is_infeasible_at_q3(table2_points):
    res = inverse_design(ClosedTrajectory.through(table2_points), InverseSettings())
    assert not res.feasible
    assert res.L1 == pytest.approx(254, abs=1)
    assert res.L2 == pytest.approx(498, abs=1)
    errs = [d for d in res.diagnostics if d.severity == "error"]
    assert len(errs) == 1
    assert errs[0].kind == "ratio_not_positive"
    assert errs[0].between_points == [3, 4]
    assert res.r1 is None  # no pitch curves


def test_corrected_table2_is_feasible(table2_points):
    pts = table2_points.copy()
    pts[3, 1] = -299.36
    res = inverse_design(ClosedTrajectory.through(pts), InverseSettings())
    assert res.feasible
    assert res.L1 == pytest.approx(254, abs=1)
    assert res.L2 == pytest.approx(498, abs=1)
    # the initial position is the farthest point: arm collinear with the carrier
    assert res.arm_angle[0] == pytest.approx(res.carrier_abs[0], abs=1e-6)


def test_carrier_reversal_is_named():
    # a trajectory with a deep inward notch between q5 and q6 forces the carrier back
    t = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    pts = np.c_[400 + 150 * np.cos(t), 150 * np.sin(t)]
    pts[5] = [300.0, 40.0]
    pts = np.insert(pts, 6, [[380.0, 20.0]], axis=0)
    res = inverse_design(ClosedTrajectory.through(pts), InverseSettings())
    assert not res.feasible
    kinds = {d.kind for d in res.diagnostics}
    assert kinds & {"carrier_not_monotonic", "ratio_not_positive", "planet_turn"}
    located = [d for d in res.diagnostics if d.between_points]
    assert located and all(0 <= p < len(pts) for d in located for p in d.between_points)


def test_dwell_holds_the_arm_and_closes(table2_points):
    pts = table2_points.copy()
    pts[3, 1] = -299.36
    res = inverse_design(ClosedTrajectory.through(pts),
                         InverseSettings(dwell=DwellSpec(start=26, end=0, anchor=4)))
    assert res.feasible
    psi = res.carrier_angle
    d = res.dwell
    inside = (psi > d["carrier_start"] + 0.01) & (psi < d["carrier_end"] - 0.01)
    assert np.ptp(res.planet_rel_realized[inside]) < 1e-12
    assert np.all(res.total_ratio[inside] == 0)
    assert res.closure_error["stage1"] < 1e-9 and res.closure_error["stage2"] < 1e-9
    # attitude exact at the anchor (seeding point e = q4)
    k = np.argmin(np.abs(psi - res.point_carrier_angle[4]))
    assert abs(res.arm_angle_realized[k] - res.arm_angle[k]) < 2e-3
    assert np.degrees(d["theta1"]) == pytest.approx(51.7, abs=0.1)
    assert any(x.kind == "dwell_not_arc" and x.severity == "warning" for x in res.diagnostics)


def test_dwell_design_round_trips_through_the_forward_model(table2_points):
    """The intermittent train (toothless sector, gears 2-3 with a break at the lock) is
    simulated by the independent forward model to within 0.01 mm of the inverse
    design's own gear-train path (the plan itself is not reachable: cd is no arc)."""
    from plantmech.mechanisms.seeder_forward import simulate
    from plantmech.verification import train_from_inverse

    pts = table2_points.copy()
    pts[3, 1] = -299.36
    res = inverse_design(ClosedTrajectory.through(pts),
                         InverseSettings(dwell=DwellSpec(start=26, end=0, anchor=4)))
    fwd = simulate(train_from_inverse(res), samples=3600)
    assert np.hypot(*(fwd.tip - res.tip_realized).T).max() < 0.01
    assert fwd.closure_error["stage1"] < 1e-8 and fwd.closure_error["stage2"] < 1e-8
