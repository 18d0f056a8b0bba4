"""Smooth curves through a cut gear outline, for STEP files (``outputs.gear_files``).

A cut outline is a dense closed polyline (mm). Written as straight edges it becomes
thousands of planar faces (a CAD import takes minutes); here each ring is split at its
corners (tooth tip and root corners, where a flank meets a fillet without a common
tangent) into smooth runs, and each run is fitted with a clamped B-spline by least squares:

- parameters: chord length, then corrected by projecting every data point onto the curve
  (Newton steps on the foot-point condition (C(u) - P) . C'(u) = 0);
- knots: none at first (one Bezier segment), then one more in every knot span where the
  fit is off, at the mean parameter of the data points there, until both deviations are
  below the tolerance:
  * every data point's distance from the curve (its foot point), and
  * the curve's distance from the outline polyline, sampled densely between the data
    points (catches a curve that overshoots between them, e.g. at a corner);
- a run that cannot be fitted that way (a knot span with too few data points left, or
  too many iterations) is split at its worst point, and a run of a few points is the
  polyline itself (degree 1): the result is always within the tolerance.

Pure numpy/scipy (``scipy.interpolate.BSpline``); no CAD kernel is needed, so the fit is
tested everywhere (tests/test_bspline_fit.py)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

CORNER_DEG = 20.0  # a ring is split where its tangent turns by more than this (deg)
CORNER_WINDOW_MM = 0.05  # the length over which a corner's turn is measured (mm)
SAMPLES_PER_INTERVAL = 8
PARAMETER_ROUNDS = 8  # at most this many parameter corrections per knot vector
MIN_KNOT_GAP = 1e-5  # distinct knots of a fitted curve are at least this far apart (of 1)


@dataclass(frozen=True)
class BSplineCurve:
    """A clamped planar B-spline: ``knots`` (full knot vector, the first and last
    ``degree + 1`` repeated), ``degree`` and ``control_points`` ((n, 2) mm); the curve runs
    from ``control_points[0]`` (u = knots[0]) to ``control_points[-1]`` (u = knots[-1])."""

    knots: np.ndarray
    degree: int
    control_points: np.ndarray

    def _spline(self):
        from scipy.interpolate import BSpline

        return BSpline(self.knots, self.control_points, self.degree, extrapolate=False)

    def __call__(self, u) -> np.ndarray:
        """Points (m, 2) mm at parameters ``u`` (clipped to the knot range)."""
        u = np.clip(np.asarray(u, dtype=float), self.knots[0], self.knots[-1])
        return self._spline()(u)

    def sample(self, per_span: int = 16) -> np.ndarray:
        """Points (m, 2) mm along the whole curve, ``per_span`` per non-empty knot span,
        both ends included."""
        t = np.unique(self.knots)
        u = np.concatenate([np.linspace(a, b, per_span, endpoint=False)
                            for a, b in zip(t[:-1], t[1:], strict=True)] + [t[-1:]])
        return self(u)


def corner_indices(ring: np.ndarray, corner_deg: float = CORNER_DEG,
                   window: float = CORNER_WINDOW_MM) -> np.ndarray:
    """Indices of the corners of the closed ring ``ring`` ((n, 2) mm, first point not
    repeated): where the direction turns by more than ``corner_deg`` degrees between the
    chord arriving from the point ``window`` mm back along the ring and the chord leaving
    to the point ``window`` mm ahead (one vertex, the sharpest, per stretch above the
    threshold). The window looks past the saw teeth a cut outline carries (micrometre
    scallops of the cutter's positions, turning by 70 deg from one tiny segment to the
    next); a smooth curve of radius R turns by about 2 window / R over it."""
    n = len(ring)
    s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(np.vstack([ring, ring[:1]]), axis=0).T))]
    length = s[-1]
    s_ext = np.r_[s[:-1] - length, s[:-1], s[:-1] + length]
    xy_ext = np.vstack([ring, ring, ring])
    h = min(window, length / 8)

    def at(q):
        return np.c_[np.interp(q, s_ext, xy_ext[:, 0]), np.interp(q, s_ext, xy_ext[:, 1])]

    d_in = ring - at(s[:-1] - h)
    d_out = at(s[:-1] + h) - ring
    cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
    dot = np.einsum("ij,ij->i", d_in, d_out)
    turn = np.abs(np.arctan2(cross, dot))
    above = turn > np.radians(corner_deg)
    if not above.any():
        return np.empty(0, dtype=int)
    if above.all():
        return np.arange(n)
    # stretches above the threshold, read around the ring from a vertex below it
    start = int(np.flatnonzero(~above)[0])
    order = (start + np.arange(n)) % n
    a = above[order]
    edges = np.diff(np.r_[0, a.astype(int), 0])
    first, last = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    out = [order[i + np.argmax(turn[order[i:j]])] for i, j in zip(first, last, strict=True)]
    return np.sort(np.asarray(out, dtype=int))


def _clean(points: np.ndarray) -> np.ndarray:
    """``points`` without consecutive duplicates (zero-length segments)."""
    keep = np.r_[True, np.any(np.diff(points, axis=0) != 0.0, axis=1)]
    return points[keep]


def _chord_parameters(points: np.ndarray) -> np.ndarray:
    s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(points, axis=0).T))]
    return s / s[-1]


def polyline_curve(points: np.ndarray) -> BSplineCurve:
    """The polyline through ``points`` as a degree-1 B-spline (exact)."""
    u = np.arange(len(points), dtype=float)  # any increasing knots: the same polyline
    return BSplineCurve(np.r_[0.0, u, u[-1]], 1, points.copy())


def _least_squares(points, u, knots, degree):
    """Control points of the clamped B-spline closest to ``points`` at ``u`` (least
    squares), its first and last control points fixed on the run's end points."""
    from scipy.interpolate import BSpline

    a = BSpline.design_matrix(u, knots, degree).toarray()
    rhs = points - np.outer(a[:, 0], points[0]) - np.outer(a[:, -1], points[-1])
    inner, *_ = np.linalg.lstsq(a[:, 1:-1], rhs, rcond=None)
    return np.vstack([points[0], inner, points[-1]])


def _project(curve: BSplineCurve, points, u, steps: int = 3):
    """Parameters of the foot points of ``points`` on ``curve``, by Newton steps from
    ``u`` (ends stay at 0 and 1)."""
    spl = curve._spline()
    d1, d2 = spl.derivative(1), spl.derivative(2)
    for _ in range(steps):
        r = spl(u) - points
        c1, c2 = d1(u), d2(u)
        num = np.einsum("ij,ij->i", r, c1)
        den = np.einsum("ij,ij->i", c1, c1) + np.einsum("ij,ij->i", r, c2)
        step = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
        u = np.clip(u - step, 0.0, 1.0)
        u[0], u[-1] = 0.0, 1.0
    return u


def _segment_distance(q, a, b):
    """Distance (m,) of points q (m, 2) from segments a -> b (m, 2)."""
    ab = b - a
    den = np.einsum("ij,ij->i", ab, ab)
    s = np.clip(np.einsum("ij,ij->i", q - a, ab) / np.where(den > 0, den, 1.0), 0.0, 1.0)
    return np.hypot(*(a + s[:, None] * ab - q).T)


def deviations(curve: BSplineCurve, points: np.ndarray, u: np.ndarray | None = None,
               samples: int = SAMPLES_PER_INTERVAL):
    """How far ``curve`` is from the polyline ``points`` ((m, 2) mm): (per data point,
    its distance from the curve (m,); per polyline segment, the largest distance of the
    curve, sampled ``samples`` times between the segment's two data points' foot points,
    from the polyline's segments nearby (m - 1,)). At the points and the samples both are
    upper bounds of the true distances (a local foot point; three segments on each side);
    between the samples the curve can stray a little further (``fit_run`` keeps a 10 %
    margin, the STEP writer measures the written file 0.02 mm apart). ``u``: the data
    points' parameters (default: chord length, projected)."""
    if u is None:
        u = _project(curve, points, _chord_parameters(points), steps=6)
    point_dev = np.hypot(*(curve(u) - points).T)
    u = np.maximum.accumulate(u)  # a folded parametrization shows up as a large distance
    frac = np.linspace(0.0, 1.0, samples + 1)[1:-1]
    us = u[:-1, None] + (u[1:] - u[:-1])[:, None] * frac[None, :]  # (m-1, s-1)
    q = curve(us.ravel())
    seg = np.repeat(np.arange(len(points) - 1), len(frac))
    best = np.full(len(q), np.inf)
    for off in range(-3, 4):  # the segment the sample belongs to and three on each side
        j = np.clip(seg + off, 0, len(points) - 2)
        best = np.minimum(best, _segment_distance(q, points[j], points[j + 1]))
    curve_dev = best.reshape(len(points) - 1, len(frac)).max(axis=1) if len(frac) else \
        np.zeros(len(points) - 1)
    return point_dev, curve_dev


def fit_run(points: np.ndarray, tolerance: float, degree: int = 3,
            max_iterations: int = 30, parameters: np.ndarray | None = None
            ) -> list[BSplineCurve]:
    """Clamped B-splines of ``degree`` through the ends of the open polyline ``points``
    ((m, 2) mm), following it within ``tolerance`` mm (``deviations``): usually one curve;
    more, joined end to end, where the run had to be split at its worst point.
    ``parameters``: the points' curve parameters in 0..1, increasing, if known (default:
    chord length)."""
    points = np.asarray(points, dtype=float)
    if parameters is None:
        points = _clean(points)
    if len(points) <= degree + 1:
        return [polyline_curve(_clean(points))]
    u = _chord_parameters(points) if parameters is None else \
        np.asarray(parameters, dtype=float).copy()
    interior = np.empty(0)
    for _ in range(max_iterations):
        knots = np.r_[np.zeros(degree + 1), interior, np.ones(degree + 1)]
        last = np.inf
        for _ in range(PARAMETER_ROUNDS):  # fit, move the parameters to the foot points
            curve = BSplineCurve(knots, degree, _least_squares(points, u, knots, degree))
            u = _project(curve, points, u)
            err = np.hypot(*(curve(u) - points).T).max()
            if err < 0.1 * tolerance or err > 0.8 * last:  # fitted, or no longer improving
                break
            last = err
        point_dev, curve_dev = deviations(curve, points, u)
        target = 0.9 * tolerance  # margin for the curve between the samples
        bad = np.r_[point_dev > target] | np.r_[curve_dev > target, False] \
            | np.r_[False, curve_dev > target]
        if not bad.any():
            return [curve]
        # one more knot in every span holding a bad point, at the mean parameter of the
        # data points in that span, if the span keeps enough points on each side
        span = np.searchsorted(interior, u, side="right")
        new = []
        for s in np.unique(span[bad]):
            us = u[span == s]
            k = us.mean()
            gap = np.abs(np.r_[0.0, interior, 1.0] - k).min()
            if np.sum(us < k) >= 2 and np.sum(us > k) >= 2 and gap > MIN_KNOT_GAP:
                new.append(k)
        if not new:
            break
        interior = np.sort(np.r_[interior, new])
    # not fitted: split at the worst point (kept as a corner, C0) and fit each side
    worst = int(np.argmax(np.maximum(np.r_[point_dev], np.r_[curve_dev, 0.0])))
    worst = min(max(worst, 1), len(points) - 2)
    return fit_run(points[:worst + 1], tolerance, degree, max_iterations) \
        + fit_run(points[worst:], tolerance, degree, max_iterations)


def fit_ring(ring: np.ndarray, tolerance: float, degree: int = 3,
             corner_deg: float = CORNER_DEG,
             window: float = CORNER_WINDOW_MM) -> list[BSplineCurve]:
    """Clamped B-splines, joined end to end (C0 at the corners), following the closed
    ring ``ring`` ((n, 2) mm; a repeated closing point is dropped) within ``tolerance``
    mm: split at its corners (``corner_indices``), each smooth run fitted with
    ``fit_run``. A ring without corners is split into two runs at opposite vertices."""
    ring = np.asarray(ring, dtype=float)[:, :2]
    if np.array_equal(ring[0], ring[-1]):
        ring = ring[:-1]
    ring = _clean(ring)
    if len(ring) > 1 and np.array_equal(ring[0], ring[-1]):
        ring = ring[:-1]
    n = len(ring)
    if n < 3:
        raise ValueError(f"a ring needs at least 3 distinct vertices, got {n}")
    corners = np.union1d(corner_indices(ring, corner_deg, window), kinks(ring, tolerance))
    if len(corners) < 2:  # two runs, never one closed curve (a CAD kernel makes it periodic)
        c0 = int(corners[0]) if len(corners) else 0
        corners = np.sort(np.array([c0, (c0 + n // 2) % n]))
    ends = np.r_[corners, corners[0] + n]
    closed = np.vstack([ring, ring])
    curves = []
    for a, b in zip(ends[:-1], ends[1:], strict=True):
        for c in fit_run(closed[a:b + 1], tolerance, degree):
            if c.degree == 1 and curves and curves[-1].degree == 1:  # one polyline
                curves[-1] = polyline_curve(np.vstack([curves[-1].control_points,
                                                       c.control_points[1:]]))
            else:
                curves.append(c)
    return curves


def kinks(ring: np.ndarray, tolerance: float) -> np.ndarray:
    """Indices of the vertices of the closed ring ``ring`` ((n, 2) mm) that a smooth curve
    cannot pass within ``tolerance`` mm of the polyline: where the turn theta (rad) between
    the two segments, of lengths L1 and L2, cuts off more than the tolerance,
    min(L1, L2) theta / 8 > tolerance / 2 (the sagitta of the circle through the vertex and
    its neighbours, L^2 / (8 R) with theta = L / R, against half the tolerance). A coarse
    polyline's own corners (a root scalloped by the cutter's discrete positions); a
    finely sampled outline has none (micrometre saw teeth cut off far less)."""
    d_in = ring - np.roll(ring, 1, axis=0)
    d_out = np.roll(ring, -1, axis=0) - ring
    cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
    turn = np.abs(np.arctan2(cross, np.einsum("ij,ij->i", d_in, d_out)))
    short = np.minimum(np.hypot(*d_in.T), np.hypot(*d_out.T))
    return np.flatnonzero(short * turn / 8 > tolerance / 2)
