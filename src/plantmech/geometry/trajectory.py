"""Closed C2 trajectory through type-value points (seed 000, section 3.1).

The paper fits a closed cubic non-uniform B-spline through the 27 type-value
points q_i. The closed C2 cubic interpolant with chord-length knots is unique,
so we build it directly as a periodic cubic spline in the chord-length
parameter ``u`` (mm of chord). Arc length is computed by Gauss-Legendre
quadrature per knot span.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline


class TrajectoryError(ValueError):
    """The type-value points cannot define a closed trajectory."""


@dataclass(frozen=True)
class ClosedTrajectory:
    """Closed C2 cubic curve through ``points`` (N x 2, mm), traversed in point order."""

    points: np.ndarray
    knots: np.ndarray  # chord-length parameter of each point, plus the closing knot (N+1)
    spline: CubicSpline

    @classmethod
    def through(cls, points) -> ClosedTrajectory:
        pts = np.asarray(points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise TrajectoryError(f"type-value points must be N x 2 (x, y), got shape {pts.shape}")
        if pts.shape[0] < 4:
            raise TrajectoryError(f"need at least 4 type-value points, got {pts.shape[0]}")
        if not np.all(np.isfinite(pts)):
            bad = np.argwhere(~np.isfinite(pts))[0][0]
            raise TrajectoryError(f"type-value point q{bad} is not a finite number")
        closed = np.vstack([pts, pts[:1]])
        chords = np.hypot(*np.diff(closed, axis=0).T)
        if np.any(chords < 1e-9):
            i = int(np.argmin(chords))
            raise TrajectoryError(
                f"type-value points q{i} and q{(i + 1) % len(pts)} coincide; "
                "a closed curve needs distinct consecutive points"
            )
        knots = np.r_[0.0, np.cumsum(chords)]
        spline = CubicSpline(knots, closed, bc_type="periodic")
        return cls(pts, knots, spline)

    @functools.cached_property
    def batch(self):
        """This curve as a one-row ``TrajectoryBatch`` (the population form of the same
        interpolant, whose exact extents and Newton refinements the single-design checks
        share), built once per curve."""
        from plantmech.geometry.trajectory_batch import TrajectoryBatch

        return TrajectoryBatch(self.points[None])

    @property
    def period(self) -> float:
        """Total chord-length parameter range (mm)."""
        return float(self.knots[-1])

    def __call__(self, u, nu: int = 0) -> np.ndarray:
        """Point (nu=0) or nu-th derivative w.r.t. u at parameter(s) ``u`` (wrapped)."""
        return self.spline(np.mod(u, self.period), nu)

    def point_parameter(self, index: int) -> float:
        """Parameter u of type-value point q_index."""
        return float(self.knots[index % len(self.points)])

    def point_index_of(self, u) -> np.ndarray:
        """Fractional type-value-point index of parameter(s) u (q_i at i.0)."""
        return np.interp(np.mod(u, self.period), self.knots, np.arange(len(self.knots)))

    def arc_length_table(self, per_span: int = 64) -> tuple[np.ndarray, np.ndarray]:
        """(u, s): arc length s(u) tabulated on a fine grid (Gauss-Legendre per sub-span)."""
        u = np.linspace(0.0, self.period, per_span * len(self.points) + 1)
        xg, wg = np.polynomial.legendre.leggauss(5)
        a, b = u[:-1, None], u[1:, None]
        uq = 0.5 * (b - a) * xg[None, :] + 0.5 * (a + b)
        d = self.spline(uq, 1)
        speed = np.hypot(d[..., 0], d[..., 1])
        ds = 0.5 * (b - a)[:, 0] * (speed * wg).sum(axis=1)
        return u, np.r_[0.0, np.cumsum(ds)]

    @property
    def length(self) -> float:
        """Total arc length of the closed curve (mm)."""
        return float(self.arc_length_table()[1][-1])

    def arc_length_samples(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """(s, u): ``n`` arc lengths equally spaced from q0 (mm) and their parameters."""
        u_tab, s_tab = self.arc_length_table()
        s = np.linspace(0.0, s_tab[-1], n, endpoint=False)
        return s, np.interp(s, s_tab, u_tab)

    def sample_by_arc_length(self, n: int) -> np.ndarray:
        """Parameters u of ``n`` points equally spaced in arc length (start at q0)."""
        return self.arc_length_samples(n)[1]

    def curvature(self, u) -> np.ndarray:
        """Signed curvature (1/mm), positive where the curve turns counter-clockwise."""
        d1 = self(u, 1)
        d2 = self(u, 2)
        num = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
        return num / np.hypot(d1[..., 0], d1[..., 1]) ** 3


def segment_self_intersections(xy: np.ndarray) -> list[tuple[int, int, np.ndarray]]:
    """Crossings of the closed polyline ``xy`` (N x 2): list of (i, j, point), i < j.

    Segment k joins xy[k] and xy[k+1] (wrapping). Neighbouring segments are not
    tested. Vectorised; intended for N up to a few thousand.
    """
    p = xy
    q = np.roll(xy, -1, axis=0)
    n = len(p)
    r = q - p
    # Solve p_i + t r_i = p_j + s r_j for all pairs.
    rxs = r[:, None, 0] * r[None, :, 1] - r[:, None, 1] * r[None, :, 0]
    qp = p[None, :, :] - p[:, None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (qp[..., 0] * r[None, :, 1] - qp[..., 1] * r[None, :, 0]) / rxs
        s = (qp[..., 0] * r[:, None, 1] - qp[..., 1] * r[:, None, 0]) / rxs
    ii, jj = np.nonzero((t >= 0) & (t < 1) & (s >= 0) & (s < 1) & (np.abs(rxs) > 1e-12))
    out = []
    for i, j in zip(ii, jj, strict=True):
        if j <= i + 1 or (i == 0 and j == n - 1):
            continue
        out.append((int(i), int(j), p[i] + t[i, j] * r[i]))
    return out
