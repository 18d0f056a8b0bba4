"""The population inverse design against the single-design one (seed 000 §3.2-3.3)."""

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.mechanisms.seeder_inverse import InverseSettings, inverse_design
from plantmech.mechanisms.seeder_inverse_batch import extreme_radii, inverse_population

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
