import numpy as np
import pytest

from plantmech.geometry.trajectory import (
    ClosedTrajectory,
    TrajectoryError,
    segment_self_intersections,
)


def circle_points(n, R=200.0, c=(300.0, 50.0)):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[c[0] + R * np.cos(t), c[1] + R * np.sin(t)]


def test_passes_through_points_and_closes():
    pts = circle_points(9) + np.random.default_rng(1).normal(0, 5, (9, 2))
    tr = ClosedTrajectory.through(pts)
    assert np.allclose(tr(tr.knots[:-1]), pts, atol=1e-9)
    assert np.allclose(tr(0.0), tr(tr.period), atol=1e-9)


def test_c2_continuity_at_every_knot():
    pts = circle_points(11) + np.random.default_rng(2).normal(0, 8, (11, 2))
    tr = ClosedTrajectory.through(pts)
    eps = 1e-7
    for u in tr.knots:
        for nu in (1, 2):
            assert np.allclose(tr(u - eps, nu), tr(u + eps, nu), atol=1e-4)


def test_arc_length_of_circle():
    tr = ClosedTrajectory.through(circle_points(180, R=200.0))
    assert tr.length == pytest.approx(2 * np.pi * 200.0, rel=1e-7)


def test_arc_length_sampling_is_uniform():
    pts = circle_points(12) * np.array([1.0, 0.5])
    tr = ClosedTrajectory.through(pts)
    u = tr.sample_by_arc_length(400)
    xy = tr(np.r_[u, tr.period])
    seg = np.hypot(*np.diff(xy, axis=0).T)
    assert seg.std() / seg.mean() < 1e-3


def test_curvature_of_circle():
    tr = ClosedTrajectory.through(circle_points(120, R=150.0))
    k = tr.curvature(np.linspace(0, tr.period, 50))
    assert np.allclose(k, 1 / 150.0, rtol=1e-3)  # spline 2nd derivative is O(h^2)


def test_rejects_bad_points():
    with pytest.raises(TrajectoryError, match="q2 and q3 coincide"):
        ClosedTrajectory.through([[0, 0], [1, 0], [2, 1], [2, 1], [0, 2]])
    with pytest.raises(TrajectoryError, match="q1 is not a finite"):
        ClosedTrajectory.through([[0, 0], [np.nan, 0], [2, 1], [0, 2]])


def test_figure_eight_has_one_crossing():
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False) + 0.003
    xy = np.c_[np.sin(2 * t), np.sin(t)]
    hits = segment_self_intersections(xy)
    assert len(hits) == 1
    assert np.allclose(hits[0][2], [0.0, 0.0], atol=1e-4)
    circle = np.c_[np.cos(t), np.sin(t)]
    assert segment_self_intersections(circle) == []
