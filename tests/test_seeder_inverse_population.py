"""The inverse design of P trajectories at once (seed 000 §3.2-3.3): each row of a population
equals the same design alone (P = 1, with its diagnostics), the grading of infeasible rows
reads like the diagnostics, and the toothless dwell (Eq. 5) is a per-design step of the same
path."""

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.mechanisms.seeder_inverse import (
    DwellSpec,
    InverseSettings,
    extreme_radii,
    inverse_design,
    inverse_population,
)

from .conftest import EXAMPLES


def _grading(res) -> float:
    """The single-design diagnostics' grading (errors + carrier angle covered / 30 deg),
    as ``workflows.seeder_inverse_checks`` computes it."""
    if res.feasible:
        return 0.0
    from plantmech.objectives.layer1 import _span_deg

    errs = [d for d in res.diagnostics if d.severity == "error"]
    return max(len(errs) + sum(_span_deg(d) for d in errs) / 30.0, 1.0)


@pytest.fixture(scope="module")
def candidates():
    """Table 2 (corrected) and its layer-1 optimum, each with 11 random perturbations of
    up to 3 or 12 mm per coordinate: feasible ones and each kind of infeasibility."""
    out = []
    rng = np.random.default_rng(7)
    for name in ("sugarcane_seeder.toml", "sugarcane_seeder_optimized.toml"):
        pts = np.asarray(load_design(EXAMPLES / name).trajectory.points)
        amp = np.where(np.arange(12) % 2, 12.0, 3.0)[:, None, None]
        X = pts[None] + amp * rng.uniform(-1.0, 1.0, (12,) + pts.shape)
        X[0] = pts
        out.append(X)
    return np.concatenate(out)


def test_population_equals_single_designs(candidates):
    samples, margin = 360, 6.5
    pop = inverse_population(candidates, samples, min_pitch_radius=margin)
    kinds = set()
    for p, pts in enumerate(candidates):
        res = inverse_design(ClosedTrajectory.through(pts),
                             InverseSettings(samples=samples, min_pitch_radius=margin))
        kinds |= {d.kind for d in res.diagnostics if d.severity == "error"}
        assert pop.feasible[p] == res.feasible
        assert pop.error_score[p] == pytest.approx(_grading(res), abs=1e-9)
        if not res.feasible:
            continue
        assert pop.L1[p] == pytest.approx(res.L1, abs=1e-9)
        assert pop.L2[p] == pytest.approx(res.L2, abs=1e-9)
        # the angle at O is ill-conditioned next to the reach circles (beta_1 goes as
        # sqrt(rho_max - rho)): 1e-13 mm of round-off there is ~1e-8 rad
        assert np.abs(pop.carrier_abs[p] - res.carrier_abs).max() < 1e-6
        assert np.abs(pop.arm_angle_realized[p] - res.arm_angle_realized).max() < 1e-6
        assert np.abs(pop.tip_realized[p] - res.tip_realized).max() < 1e-4
        assert np.abs(pop.point_carrier_angle[p] - res.point_carrier_angle).max() < 1e-6
        radii = np.array([np.nanmin(r) for r in (res.r1, res.r2, res.r3, res.r4)])
        assert np.allclose(pop.pitch_radius_min[p], radii, atol=1e-6)
        assert pop.closure_error[p].max() < 1e-9
    assert pop.feasible.sum() >= 4 and (~pop.feasible).sum() >= 4
    assert {"carrier_not_monotonic", "ratio_not_positive"} <= kinds


def test_pitch_radius_limit_grades_like_the_single_design():
    pts = np.asarray(load_design(EXAMPLES / "sugarcane_seeder.toml").trajectory.points)
    res = inverse_design(ClosedTrajectory.through(pts), InverseSettings(samples=360,
                                                                        min_pitch_radius=60))
    pop = inverse_population(pts[None], 360, min_pitch_radius=60.0)
    assert "pitch_radius" in {d.kind for d in res.diagnostics}
    assert not pop.feasible[0]
    assert pop.error_score[0] == pytest.approx(_grading(res), abs=1e-9)


def test_broken_rows_do_not_spoil_the_others():
    pts = np.asarray(load_design(EXAMPLES / "sugarcane_seeder.toml").trajectory.points)
    t = np.linspace(0, 2 * np.pi, len(pts), endpoint=False)
    coincident = pts.copy()
    coincident[3] = coincident[2]
    circle = np.c_[300 * np.cos(t), 300 * np.sin(t)]  # constant radius: no carrier length
    pop = inverse_population(np.stack([pts, coincident, circle]), 360)
    assert pop.feasible.tolist() == [True, False, False]
    assert pop.error_score[1] == 10.0  # no curve at all (as a fitting failure)
    assert pop.error_score[2] == 1.0  # degenerate
    alone = inverse_population(pts[None], 360)
    assert np.array_equal(alone.tip_realized[0], pop.tip_realized[0])


def test_extreme_radii_of_an_ellipse_about_its_centre():
    """Farthest and nearest points of an ellipse (a, b) about its centre: a and b, at the
    ends of its axes."""
    t = np.linspace(0, 2 * np.pi, 48, endpoint=False) + 0.05
    from plantmech.geometry.trajectory_batch import TrajectoryBatch

    tb = TrajectoryBatch(np.c_[300 * np.cos(t), 180 * np.sin(t)][None])
    (u_max, r_max), (u_min, r_min) = extreme_radii(tb)
    assert r_max[0] == pytest.approx(300.0, abs=5e-3)  # the spline through 48 points
    assert r_min[0] == pytest.approx(180.0, abs=5e-3)
    for u in (u_max, u_min):  # a stationary point of rho
        p, d1, _ = tb.derivatives(u[:, None])
        assert abs(float((p * d1).sum())) < 1e-6


def test_pitch_tangent_angle_matches_the_single_design_manufacturability_rows():
    """The population's largest mu of each pair (on the carrier grid) against the working
    pressure angle of the single design's pitch curves (gears.manufacturability, 3600 body
    angles of the re-interpolated curves): two independent discretisations."""
    from plantmech.workflows import run_seeder_inverse

    for name in ("sugarcane_seeder.toml", "sugarcane_seeder_optimized.toml"):
        d = load_design(EXAMPLES / name)
        d.train = None
        gt = d.gear_train
        pts = np.asarray(d.trajectory.points)[None]
        from plantmech.geometry.trajectory_batch import TrajectoryBatch

        inv = inverse_population(TrajectoryBatch(pts), 3600, gt.a1_mm, gt.a2_mm,
                                 gt.split_exponent, gt.min_pitch_radius_mm)
        rows = {c["name"]: c["value"] for c in run_seeder_inverse(d).summary[
            "manufacturing_checks"]}
        work = d.gear_checks.tool_pressure_angle_deg + np.degrees(inv.pitch_tangent_angle[0])
        assert work[0] == pytest.approx(rows["working_pressure_angle_sun_gear2"], abs=0.5)
        assert work[1] == pytest.approx(rows["working_pressure_angle_gear3_planet"], abs=0.5)


def _dwell_candidates(table2_points, count=6, amp=2.0):
    """Corrected Table 2 and ``count - 1`` copies moved by up to ``amp`` mm per coordinate."""
    pts = table2_points.copy()
    pts[3, 1] = -299.36
    rng = np.random.default_rng(5)
    X = pts[None] + amp * rng.uniform(-1.0, 1.0, (count,) + pts.shape)
    X[0] = pts
    return X


def test_dwell_rows_hold_the_arm_close_and_keep_the_anchor(table2_points):
    """Each row's dwell from its own carrier law: inside the toothless sector (carrier
    angles between the carrier angles of the dwell's points, per row) the planet does not
    turn relative to the carrier, gears idle (ratio 0, no pitch radii), both pairs close,
    and the realized attitude at the anchor point equals the planned one."""
    X = _dwell_candidates(table2_points)
    dwell = DwellSpec(start=26, end=0, anchor=4)
    pop = inverse_population(X, 720, dwell=dwell, full=True)
    assert pop.feasible.sum() >= 4
    for p in np.flatnonzero(pop.feasible):
        info = pop.dwell[p]
        start, end = pop.point_carrier_angle[p, [26, 0]]
        assert info["carrier_start"] == start and info["carrier_end"] == end
        assert info["theta1"] == pytest.approx(np.mod(end - start, 2 * np.pi), abs=1e-12)
        psi = pop.psi
        inside = (np.mod(psi - start, 2 * np.pi) > 0.01) & (
            np.mod(psi - start, 2 * np.pi) < info["theta1"] - 0.01)
        assert inside.sum() > 50
        assert np.ptp(pop.planet_rel_realized[p, inside]) < 1e-12
        assert np.all(pop.total_ratio[p, inside] == 0)
        assert np.isnan(pop.radii[p][:, inside]).all()
        assert pop.closure_error[p].max() < 1e-9
        k = np.argmin(np.abs(np.angle(np.exp(1j * (psi - pop.point_carrier_angle[p, 4])))))
        assert abs(pop.arm_angle_realized[p, k] - pop.arm_angle[p, k]) < 2e-3
        # the realized tip is the three-bar of the realized angles (mm)
        tip = pop.L1[p] * np.c_[np.cos(pop.carrier_abs[p]), np.sin(pop.carrier_abs[p])] + \
            pop.L2[p] * np.c_[np.cos(pop.arm_angle_realized[p]), np.sin(pop.arm_angle_realized[p])]
        assert np.abs(tip - pop.tip_realized[p]).max() < 1e-9


def test_dwell_population_rows_equal_the_designs_alone(table2_points):
    """A row's dwell design in a population of six equals the design alone (P = 1) to
    round-off: verdict, grading, the dwell's numbers, pitch radii and realized motion."""
    X = _dwell_candidates(table2_points)
    dwell = DwellSpec(start=26, end=0, anchor=4)
    pop = inverse_population(X, 720, dwell=dwell, full=True)
    for p, pts in enumerate(X):
        res = inverse_design(ClosedTrajectory.through(pts),
                             InverseSettings(samples=720, dwell=dwell))
        assert pop.feasible[p] == res.feasible
        assert pop.error_score[p] == pytest.approx(_grading(res), abs=1e-9)
        if res.r1 is None:
            continue
        for key in ("theta1", "theta2", "ratio_scale", "edge_radius", "max_tip_deviation"):
            assert pop.dwell[p][key] == pytest.approx(res.dwell[key], abs=1e-9), key
        for a, b in zip(pop.radii[p], (res.r1, res.r2, res.r3, res.r4), strict=True):
            assert np.array_equal(np.isnan(a), np.isnan(b))
            assert np.nanmax(np.abs(a - b)) < 1e-6  # mm
        assert np.abs(pop.arm_angle_realized[p] - res.arm_angle_realized).max() < 1e-6
        assert np.abs(pop.tip_realized[p] - res.tip_realized).max() < 1e-4


def test_a_dwell_anchor_inside_the_dwell_stops_that_row(table2_points):
    """An anchor point inside the toothless sector cannot keep its attitude: the row is
    infeasible with one error (the single design names it 'dwell'), the others are not
    touched by it."""
    X = _dwell_candidates(table2_points, count=2, amp=0.5)
    bad = DwellSpec(start=20, end=2, anchor=0)  # q0 lies between q20 and q2
    pop = inverse_population(X, 360, dwell=bad, full=True)
    assert not pop.feasible.any()
    assert list(pop.failure) == ["dwell", "dwell"]
    assert np.all(pop.error_score == 1.0)
    res = inverse_design(ClosedTrajectory.through(X[0]), InverseSettings(samples=360,
                                                                         dwell=bad))
    assert [d.kind for d in res.diagnostics] == ["dwell"]
    assert res.r1 is None


def test_one_design_is_a_population_of_one():
    """inverse_design's arrays are the row of inverse_population(P = 1) exactly (one code
    path), and a curve object is taken as such a population too."""
    pts = np.asarray(load_design(EXAMPLES / "sugarcane_seeder.toml").trajectory.points)
    traj = ClosedTrajectory.through(pts)
    res = inverse_design(traj, InverseSettings(samples=720))
    pop = inverse_population(pts[None], 720, full=True)
    assert res.feasible and pop.feasible[0]
    assert np.array_equal(res.tip_realized, pop.tip_realized[0])
    assert np.array_equal(res.r4, pop.radii[0, 3])
    assert res.L1 == pop.L1[0] and res.u_start == pop.u_start[0]
