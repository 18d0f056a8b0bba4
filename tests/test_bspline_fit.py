"""geometry.bspline: least-squares B-spline fits of cut outlines (the STEP writer's
edges), checked against curves whose shape is known exactly."""

import numpy as np
import shapely
from scipy.interpolate import BSpline

from plantmech.geometry.bspline import (
    corner_indices,
    deviations,
    fit_ring,
    fit_run,
)


def _dense(curves, per_span=64):
    return np.vstack([c.sample(per_span) for c in curves])


def _distance(points, polyline):
    """Largest distance of ``points`` from the polyline (its segments in an R-tree)."""
    segs = shapely.linestrings(np.stack([polyline[:-1], polyline[1:]], axis=1))
    _, d = shapely.STRtree(segs).query_nearest(shapely.points(points), return_distance=True,
                                                all_matches=False)
    return d.max()


def _hausdorff_to_polyline(curves, points, per_span=100):
    """Largest distance of the curves (sampled densely) from the polyline ``points``,
    and of every point from the curves (sampled densely): shapely, independent of the
    fit's own measure."""
    dense = _dense(curves, per_span)
    return max(_distance(dense, points), _distance(points, dense))


def test_an_exact_cubic_is_reproduced():
    """Points on one cubic Bezier segment at their known parameters: the fit is that cubic
    (its 4 poles) to round-off, without a knot; from chord-length parameters (unevenly
    spaced points) it is within the tolerance with a few more poles."""
    poles = np.array([[0.0, 0.0], [3.0, 4.0], [7.0, -2.0], [10.0, 1.0]])
    exact = BSpline(np.r_[[0.0] * 4, [1.0] * 4], poles, 3)
    u = np.linspace(0, 1, 1001) ** 1.3
    pts = exact(u)
    (curve,) = fit_run(pts, 1e-4, parameters=u)
    assert curve.degree == 3 and len(curve.control_points) == 4
    assert np.abs(curve.control_points - poles).max() < 1e-9
    (curve,) = fit_run(pts, 1e-3)
    assert curve.degree == 3 and len(curve.control_points) <= 12
    assert _hausdorff_to_polyline([curve], pts) <= 1e-3


def test_a_circle_arc_within_tolerance_with_few_poles():
    """A 90 deg arc of radius 10 mm, 200 points: within 1 um of the circle with a handful of
    poles (a cubic Bezier is within 2.7e-4 R of a quarter circle, 2.7 um here, so one knot
    is needed and a few suffice)."""
    t = np.linspace(0, np.pi / 2, 200)
    pts = 10 * np.c_[np.cos(t), np.sin(t)]
    (curve,) = fit_run(pts, 1e-3)
    assert 5 <= len(curve.control_points) <= 8
    r = np.hypot(*curve.sample(200).T)
    assert np.abs(r - 10).max() < 1e-3
    assert _hausdorff_to_polyline([curve], pts) < 1e-3


def test_an_involute_within_tolerance_with_few_poles():
    """The involute of a 20 mm base circle from 0 to 40 deg of roll, 300 points: within 1 um
    of the exact involute (distance to a dense exact polyline) with at most 10 poles."""
    rb = 20.0

    def involute(t):
        return rb * np.c_[np.cos(t) + t * np.sin(t), np.sin(t) - t * np.cos(t)]

    pts = involute(np.linspace(0, np.radians(40), 300))
    curves = fit_run(pts, 1e-3)
    assert len(curves) == 1 and len(curves[0].control_points) <= 10
    exact = shapely.LineString(involute(np.linspace(0, np.radians(40), 20000)))
    assert shapely.distance(exact, shapely.points(curves[0].sample(200))).max() < 1e-3


def test_no_overshoot_at_a_corner():
    """A square of side 10 mm (four 90 deg corners, 40 points a side): split at its four
    corners, every run a straight line; the curves never leave the square's outline by
    more than the tolerance (a spline through a corner overshoots it)."""
    s = np.linspace(0, 10, 41)[:-1]
    ring = np.vstack([np.c_[s, 0 * s], np.c_[10 + 0 * s, s], np.c_[10 - s, 10 + 0 * s],
                      np.c_[0 * s, 10 - s]])
    assert sorted(corner_indices(ring).tolist()) == [0, 40, 80, 120]
    curves = fit_ring(ring, 1e-3)
    assert len(curves) == 4
    dense = _dense(curves)
    assert dense[:, 0].min() > -1e-6 and dense[:, 0].max() < 10 + 1e-6
    assert dense[:, 1].min() > -1e-6 and dense[:, 1].max() < 10 + 1e-6
    closed = np.vstack([ring, ring[:1]])
    assert _hausdorff_to_polyline(curves, closed) < 1e-3


def test_a_rounded_tooth_corner_overshoots_without_the_split():
    """The overshoot check works: one cubic forced through a 90 deg corner (no split)
    is measured far outside the tolerance by ``deviations``."""
    s = np.linspace(0, 5, 51)
    pts = np.vstack([np.c_[s, 0 * s], np.c_[5 + 0 * s[1:], s[1:]]])
    (curve,) = fit_run(pts[:51], 1e-3)  # the straight half alone: exact
    assert max(d.max() for d in deviations(curve, pts[:51])) < 1e-9
    from plantmech.geometry.bspline import BSplineCurve

    bezier = BSplineCurve(np.r_[[0.0] * 4, [1.0] * 4],
                          3, np.array([[0, 0], [5, 0], [5, 0], [5, 5]], dtype=float))
    point_dev, curve_dev = deviations(bezier, pts)
    assert max(point_dev.max(), curve_dev.max()) > 0.1


def test_the_ring_is_closed_and_follows_a_wavy_outline():
    """A wavy ring (r = 20 + 1.5 cos 12t, 2,400 points): the curves join end to end around
    the ring, stay within the tolerance both ways and need far fewer poles than points."""
    t = np.linspace(0, 2 * np.pi, 2400, endpoint=False)
    r = 20 + 1.5 * np.cos(12 * t)
    ring = np.c_[r * np.cos(t), r * np.sin(t)]
    curves = fit_ring(ring, 5e-3)
    for a, b in zip(curves, curves[1:] + curves[:1], strict=True):
        assert np.array_equal(a.control_points[-1], b.control_points[0])
    assert _hausdorff_to_polyline(curves, np.vstack([ring, ring[:1]])) <= 5e-3
    assert sum(len(c.control_points) for c in curves) < len(ring) / 5


def test_a_real_envelope_cut_gear_outline_within_tolerance_with_far_fewer_poles():
    """The manufacturable transplanter's planet as `plantmech gears --teeth simulated`
    cuts it (16,000 outline vertices with micrometre saw teeth from the cutter's
    positions): within 5 um of the cut outline both ways (shapely, dense samples) with
    < 1/10 as many poles. As `plantmech gears` makes it by default (by the envelope since
    issue 16: 4,000 vertices, no saw teeth): within 5 um with < 1/5 as many poles."""
    from plantmech.design import load_design
    from plantmech.workflows import gear_pairs

    design = load_design("examples/rice_transplanter_manufacturable.toml")
    for method, fewer in (("simulated", 10), ("envelope", 5)):
        ((pair, _spec),) = gear_pairs(design, None, 0.1, method=method)
        ring = np.asarray(pair.gear_b.exterior.coords)
        curves = fit_ring(ring, 5e-3)
        poles = sum(len(c.control_points) for c in curves)
        assert poles < len(ring) / fewer, method
        assert sum(c.degree == 3 for c in curves) > 0.9 * len(curves)
        assert _hausdorff_to_polyline(curves, ring) <= 5e-3
