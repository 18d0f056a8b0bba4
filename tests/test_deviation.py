"""geometry/deviation.py: distances of tip paths from a closed polyline and the plan (the
plan-against-tips measures are also tested in tests/test_workflows.py)."""

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.geometry.deviation import (
    _distance_to_closed_polyline,
    trajectory_deviation,
    trajectory_deviation_batch,
)
from plantmech.geometry.trajectory import ClosedTrajectory

from .conftest import EXAMPLES


def test_distance_to_a_unit_square_point_to_segment():
    """Inside the square the nearest side, outside the side or the corner (Pythagoras)."""
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    points = np.array([[0.5, 0.5], [0.5, 0.1], [2.0, 0.5], [2.0, 2.0], [0.5, 0.0],
                       [-3.0, -4.0]])
    assert _distance_to_closed_polyline(points, square) == pytest.approx(
        [0.5, 0.1, 1.0, np.sqrt(2.0), 0.0, 5.0], abs=1e-15)


def test_batch_rows_are_independent_and_the_plan_is_at_zero():
    """P tip paths at once give each path's own deviation, bit for bit; the plan's own
    samples are on the plan: within 3.4e-6 mm with the plan at 80000 points (as
    ``trajectory_deviation``), within 0.08 mm at the optimizer's default 20000 (measured;
    the "8"'s tight turn)."""
    design = load_design(EXAMPLES / "sugarcane_seeder.toml")
    traj = ClosedTrajectory.through(np.asarray(design.trajectory.points, dtype=float))
    _, u = traj.arc_length_samples(720)
    plan = traj(u)
    tips = np.stack([plan, plan * 1.01, plan + [3.0, -2.0]])
    together = trajectory_deviation_batch(design, tips)
    alone = [trajectory_deviation_batch(design, t[None])[0] for t in tips]
    assert together.tolist() == alone
    assert together[0] < 0.1
    assert trajectory_deviation_batch(design, plan[None], samples=80000)[0] < 1e-5
    assert trajectory_deviation(traj, plan)["max_tip_to_plan"] < 1e-5
    # a rigid shift by (3, -2) moves no point farther than its length from the plan
    assert 0.5 < together[2] <= np.hypot(3.0, 2.0) + 1e-9
    single = trajectory_deviation(traj, tips[2])
    assert single["max_tip_to_plan"] == pytest.approx(together[2], abs=1e-3)
