import numpy as np
import pytest

from plantmech.geometry.trajectory import ClosedTrajectory, segment_self_intersections
from plantmech.geometry.trajectory_batch import TrajectoryBatch, row_searchsorted

from .conftest import EXAMPLES


def _table2_points():
    from plantmech.design import load_design

    return np.asarray(load_design(EXAMPLES / "sugarcane_seeder.toml").trajectory.points)


@pytest.fixture(scope="module")
def population():
    rng = np.random.default_rng(11)
    pts = _table2_points()
    X = pts[None] + rng.uniform(-10.0, 10.0, (12,) + pts.shape)
    return X, TrajectoryBatch(X)


def test_each_row_is_scipys_periodic_spline(population):
    X, tb = population
    rng = np.random.default_rng(1)
    u = rng.uniform(-500.0, 4000.0, (tb.P, 300))  # outside one period too: wrapped
    for nu in (0, 1, 2):
        got = tb(u, nu)
        for p in range(tb.P):
            ref = ClosedTrajectory.through(X[p])(u[p], nu)
            assert np.abs(got[p] - ref).max() < 1e-9 * max(1.0, np.abs(ref).max())
    p, d1, d2 = tb.derivatives(u)
    assert np.array_equal(p, tb(u)) and np.allclose(d1, tb(u, 1)) and np.allclose(d2, tb(u, 2))
    assert np.allclose(tb.knots[0], ClosedTrajectory.through(X[0]).knots)


def test_coordinate_range_is_exact(population):
    """Stationary points of the cubics: the dense-sampled range never exceeds it and
    comes within the sampling error."""
    X, tb = population
    u0 = np.linspace(0.0, 900.0, tb.P)
    u1 = np.minimum(u0 + np.linspace(100.0, 1900.0, tb.P), u0 + tb.period)
    got = tb.coordinate_range(u0, u1)
    for p in range(tb.P):
        xy = ClosedTrajectory.through(X[p])(np.linspace(u0[p], u1[p], 400001))
        ref = np.array([[xy[:, 0].min(), xy[:, 0].max()], [xy[:, 1].min(), xy[:, 1].max()]])
        assert np.all(got[p][:, 0] <= ref[:, 0] + 1e-9)
        assert np.all(got[p][:, 1] >= ref[:, 1] - 1e-9)
        assert np.abs(got[p] - ref).max() < 1e-6


def test_circle_range_is_its_radius():
    t = np.linspace(0, 2 * np.pi, 72, endpoint=False)
    tb = TrajectoryBatch(np.c_[300 + 100 * np.cos(t), -50 + 100 * np.sin(t)][None])
    r = tb.coordinate_range(np.zeros(1), tb.period)[0]
    # the C2 cubic through 72 points of a circle is within 1e-5 mm of it
    assert np.allclose(r, [[200.0, 400.0], [-150.0, 50.0]], atol=1e-5)


def test_self_crossings_match_the_single_curve_function(population):
    X, tb = population
    count, i, j = tb.self_crossings(160)
    for p in range(tb.P):
        tr = ClosedTrajectory.through(X[p])
        hits = segment_self_intersections(tr(np.linspace(0, tr.period, 160, endpoint=False)))
        assert count[p] == len(hits)
        assert (i[p], j[p]) == (hits[0][:2] if len(hits) == 1 else (-1, -1))
    # an ellipse does not cross itself, a lemniscate once, (cos t, sin 3t) twice
    t = np.linspace(0, 2 * np.pi, 60, endpoint=False) + 0.013
    curves = np.stack([np.c_[100 * np.cos(t), 50 * np.sin(t)],
                       np.c_[100 * np.sin(t), 60 * np.sin(2 * t)],
                       np.c_[100 * np.cos(t), 60 * np.sin(3 * t)]])
    c, _, _ = TrajectoryBatch(curves).self_crossings(160)
    assert c.tolist() == [0, 1, 2]


def test_coincident_points_flag_the_row_only():
    pts = _table2_points()
    X = np.stack([pts, pts.copy()])
    X[1, 5] = X[1, 4]
    tb = TrajectoryBatch(X)
    assert tb.bad.tolist() == [False, True]
    assert np.isfinite(tb(np.zeros((2, 3)))).all()
    with pytest.raises(ValueError, match="P x N x 2"):
        TrajectoryBatch(pts)


def test_row_searchsorted():
    rng = np.random.default_rng(3)
    table = np.sort(rng.uniform(-5, 50, (4, 9)), axis=1)
    x = rng.uniform(table[:, :1], table[:, -1:], (4, 30))
    k = row_searchsorted(table, x)
    for p in range(4):
        ref = np.clip(np.searchsorted(table[p], x[p], side="right") - 1, 0, 7)
        assert np.array_equal(k[p], ref)


def test_coordinate_range_kernel_is_the_numpy_path(population):
    """The numba kernel (default) against the NumPy arrays (the reference): the same
    stationary points, so the same extents, over short, long, wrapped and full spans."""
    X, tb = population
    rng = np.random.default_rng(5)
    for _ in range(20):
        u0 = rng.uniform(-300.0, 3000.0, tb.P)
        u1 = u0 + rng.uniform(0.0, 1.0, tb.P) * tb.period
        ref = tb.coordinate_range(u0, u1, fused=False)
        assert np.array_equal(tb.coordinate_range(u0, u1), ref)
    full = tb.coordinate_range(np.zeros(tb.P), tb.period.copy())
    assert np.array_equal(full, tb.coordinate_range(np.zeros(tb.P), tb.period.copy(),
                                                    fused=False))
