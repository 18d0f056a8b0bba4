"""A population of closed trajectories at once (arrays over designs; no Python loop
per design): the batched form of ``ClosedTrajectory`` for optimizers that move
type-value points (seed 000's layer 1).

Each row is the closed C2 cubic with chord-length knots through its points, the same
(unique) interpolant ``ClosedTrajectory`` builds with SciPy's periodic spline; here the
cyclic system for the knot second derivatives is solved for all rows with one batched
LAPACK call, and evaluation gathers each sample's segment coefficients. Lengths in mm,
parameter ``u`` in mm of chord (per row, wrapped by the row's period).
"""

from __future__ import annotations

import functools

import numpy as np


def row_searchsorted(table: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Per row p, the index k with table[p, k] <= x[p, j] < table[p, k + 1] (clipped to
    0..K-2); ``table`` (P, K) increasing along each row, ``x`` (P, m)."""
    P, K = table.shape
    lo = np.minimum(table.min(axis=1), x.min(axis=1))
    span = np.maximum(table.max(axis=1), x.max(axis=1)) - lo + 1.0
    off = np.r_[0.0, np.cumsum(span)[:-1]] - lo
    flat = (table + off[:, None]).ravel()
    k = np.searchsorted(flat, (x + off[:, None]).ravel(), side="right").reshape(x.shape) - 1
    return np.clip(k - K * np.arange(P)[:, None], 0, K - 2)


class TrajectoryBatch:
    """P closed trajectories through ``points`` (P, N, 2). ``bad`` (P,): rows whose
    consecutive points coincide (no curve; their arrays are placeholders)."""

    def __init__(self, points):
        pts = np.asarray(points, dtype=float)
        if pts.ndim != 3 or pts.shape[2] != 2 or pts.shape[1] < 4:
            raise ValueError(f"points must be P x N x 2 with N >= 4, got {pts.shape}")
        P, N, _ = pts.shape
        closed = np.concatenate([pts, pts[:, :1]], axis=1)
        diff = np.diff(closed, axis=1)
        h = np.hypot(diff[..., 0], diff[..., 1])
        self.bad = (h < 1e-9).any(axis=1) | ~np.isfinite(pts).all(axis=(1, 2))
        h = np.where(self.bad[:, None], 1.0, h)
        diff = np.where(self.bad[:, None, None], 0.0, diff)
        slope = diff / h[..., None]
        hm = np.roll(h, 1, axis=1)  # h[i - 1]
        A = np.zeros((P, N, N))
        i = np.arange(N)
        A[:, i, i] = 2.0 * (hm + h)
        A[:, i, (i - 1) % N] += hm
        A[:, i, (i + 1) % N] += h
        rhs = 6.0 * (slope - np.roll(slope, 1, axis=1))
        M = np.linalg.solve(A, rhs)  # second derivatives at the knots (P, N, 2)
        M1 = np.roll(M, -1, axis=1)
        self.points, self.P, self.N = pts, P, N
        self.knots = np.concatenate([np.zeros((P, 1)), np.cumsum(h, axis=1)], axis=1)
        self.period = self.knots[:, -1].copy()
        self.h = h
        # segment i, local t = u - knot_i: c0 + c1 t + c2 t^2 + c3 t^3
        self.coef = np.stack([pts if not self.bad.any() else np.where(
            self.bad[:, None, None], 0.0, pts),
            slope - h[..., None] * (2.0 * M + M1) / 6.0,
            0.5 * M, (M1 - M) / (6.0 * h[..., None])], axis=2)  # (P, N, 4, 2)
        # flat per-coordinate planes for gathering: [axis][power] -> (P * N,)
        self._planes = [[np.ascontiguousarray(self.coef[:, :, j, axis]).ravel()
                         for j in range(4)] for axis in (0, 1)]
        self._start = np.ascontiguousarray(self.knots[:, :-1]).ravel()
        # the rows' knots end to end (row p shifted by p (max period + 1)) for one search
        self._offset = (np.arange(P) * (self.period.max() + 1.0))[:, None]
        self._flat_knots = (self.knots + self._offset).ravel()
        self._row_base = (N + 1) * np.arange(P)[:, None]
        self._row_start = N * np.arange(P)[:, None]

    def __call__(self, u: np.ndarray, nu: int = 0) -> np.ndarray:
        """Point (nu=0) or derivative nu (1, 2) w.r.t. u at u (P, m) -> (P, m, 2)."""
        if nu not in (0, 1, 2):
            raise ValueError("nu must be 0, 1 or 2")
        return self._evaluate(u, (nu,))[0]

    def derivatives(self, u: np.ndarray):
        """(point, first, second derivative) w.r.t. u at u (P, m), each (P, m, 2)."""
        return tuple(self._evaluate(u, (0, 1, 2)))

    def _evaluate(self, u: np.ndarray, orders) -> np.ndarray:
        """Derivatives of the given orders at u (P, m) -> (len(orders), P, m, 2)."""
        u, k = self._segments(u)
        t = u - self._start[k]
        out = np.empty((len(orders),) + u.shape + (2,))
        for axis in (0, 1):
            c0, c1, c2, c3 = (plane[k] for plane in self._planes[axis])
            for i, nu in enumerate(orders):
                if nu == 0:
                    out[i, ..., axis] = c0 + t * (c1 + t * (c2 + t * c3))
                elif nu == 1:
                    out[i, ..., axis] = c1 + t * (2.0 * c2 + 3.0 * t * c3)
                else:
                    out[i, ..., axis] = 2.0 * c2 + 6.0 * t * c3
        return out

    def _segments(self, u: np.ndarray):
        """(u wrapped into each row's period, flat index row * N + segment) for u (P, m):
        one search in the rows' knots laid end to end."""
        period = self.period[:, None]
        u = u - period * np.floor(u / period)
        k = np.searchsorted(self._flat_knots, (u + self._offset).ravel(), side="right")
        k = k.reshape(u.shape) - 1 - self._row_base
        return u, np.clip(k, 0, self.N - 1) + self._row_start

    def coordinate_range(self, u0: np.ndarray, u1: np.ndarray, fused: bool = True
                         ) -> np.ndarray:
        """Exact (P, 2, 2) [[x_min, x_max], [y_min, y_max]] of each row's curve over the
        parameter span u0..u1 (P,), u0 <= u1 <= u0 + period: the span's ends and every
        stationary point of a coordinate (roots of its cubic's derivative) inside it.
        ``fused``: the stationary points in the numba kernel
        ``trajectory_kernels.coordinate_extremes`` (False: the NumPy arrays, the
        reference in the tests)."""
        if fused:
            from plantmech.geometry.trajectory_kernels import coordinate_extremes

            u0, u1 = np.asarray(u0, dtype=float), np.asarray(u1, dtype=float)
            ends = self(np.c_[u0, u1])  # (P, 2 ends, 2 coords)
            lo, hi = ends.min(axis=1), ends.max(axis=1)
            coordinate_extremes(self.coef, self.knots, self.h, self.period, u0, u1, lo, hi)
            return np.stack([lo, hi], axis=-1)
        c1, c2, c3 = self.coef[:, :, 1], self.coef[:, :, 2], self.coef[:, :, 3]  # (P, N, 2)
        a, b, c = 3.0 * c3, 2.0 * c2, c1
        disc = b * b - 4.0 * a * c
        sq = np.sqrt(np.maximum(disc, 0.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            q = -0.5 * (b + np.where(b >= 0, sq, -sq))  # stable quadratic roots
            roots = np.stack([np.where(np.abs(a) > 1e-300, q / a, np.nan),
                              np.where(np.abs(q) > 1e-300, c / q, np.nan)], axis=-1)
        roots = np.where((disc >= 0)[..., None], roots, np.nan)  # (P, N, 2 coords, 2)
        h = self.h[:, :, None, None]
        valid = (roots >= 0) & (roots <= h)
        t = np.where(valid, roots, 0.0)
        coef = self.coef[:, :, :, :, None]  # (P, N, 4, 2, 1)
        val = coef[:, :, 0] + t * (coef[:, :, 1] + t * (coef[:, :, 2] + t * coef[:, :, 3]))
        u = self.knots[:, :-1, None, None] + t
        inside = np.mod(u - u0[:, None, None, None], self.period[:, None, None, None]) <= (
            u1 - u0)[:, None, None, None]
        ok = valid & inside
        lo = np.where(ok, val, np.inf).min(axis=(1, 3))  # (P, 2)
        hi = np.where(ok, val, -np.inf).max(axis=(1, 3))
        ends = self(np.c_[u0, u1])  # (P, 2 ends, 2 coords)
        lo = np.minimum(lo, ends.min(axis=1))
        hi = np.maximum(hi, ends.max(axis=1))
        return np.stack([lo, hi], axis=-1)

    def self_crossings(self, n: int = 160):
        """Crossings of each row's n-gon inscribed at equal parameter steps: (count (P,),
        i (P,), j (P,)) with i < j the crossing segments of rows that cross exactly once
        (-1 elsewhere). Neighbouring segments are not tested (as
        ``segment_self_intersections``). Only pairs whose runs of 8 segments and whose own
        bounding boxes overlap get the exact test."""
        u = self.period[:, None] * np.arange(n)[None, :] / n
        p = self(u)
        x, y = p[..., 0], p[..., 1]
        x1, y1 = np.roll(x, -1, axis=1), np.roll(y, -1, axis=1)
        # candidate pairs: bounding boxes of runs of c segments overlap, then those of the
        # segments, then the exact test
        xl, xh, yl, yh = np.minimum(x, x1), np.maximum(x, x1), np.minimum(y, y1), np.maximum(y, y1)
        c = 8 if n % 8 == 0 else 1
        C = n // c
        bl = [v.reshape(self.P, C, c).min(axis=2) for v in (xl, yl)]
        bh = [v.reshape(self.P, C, c).max(axis=2) for v in (xh, yh)]
        near = np.triu(np.ones((C, C), bool))[None]
        for lo, hi in zip(bl, bh, strict=True):
            near = near & (lo[:, :, None] <= hi[:, None, :]) & (lo[:, None, :] <= hi[:, :, None])
        pp, ci, cj = np.nonzero(near)
        # every segment pair of the overlapping runs that is not a neighbour: (P*n) flat
        pi_, pj_ = _run_pairs(n, c)  # (C, C, k) flat pair tables per run pair
        fi = (pi_[ci, cj] + (pp * n)[:, None]).ravel()
        fj = (pj_[ci, cj] + (pp * n)[:, None]).ravel()
        ok = fi >= 0
        fi, fj = fi[ok], fj[ok]
        xl, xh, yl, yh = xl.ravel(), xh.ravel(), yl.ravel(), yh.ravel()
        keep = ((xl[fi] <= xh[fj]) & (xl[fj] <= xh[fi]) & (yl[fi] <= yh[fj])
                & (yl[fj] <= yh[fi]))
        fi, fj = fi[keep], fj[keep]
        pp, ii, jj = fi // n, fi % n, fj % n
        rx, ry = (x1 - x).ravel(), (y1 - y).ravel()
        x, y = x.ravel(), y.ravel()
        rxi, ryi, rxj, ryj = rx[fi], ry[fi], rx[fj], ry[fj]
        qx, qy = x[fj] - x[fi], y[fj] - y[fi]
        rxs = rxi * ryj - ryi * rxj
        sign = np.where(rxs < 0, -1.0, 1.0)
        den = rxs * sign  # |rxs|; t = tn / rxs, s = sn / rxs lie in [0, 1)
        tn = (qx * ryj - qy * rxj) * sign
        sn = (qx * ryi - qy * rxi) * sign
        hit = (tn >= 0) & (tn < den) & (sn >= 0) & (sn < den) & (den > 1e-12)
        count = np.bincount(pp[hit], minlength=self.P)
        one = count == 1
        first_i, first_j = np.full(self.P, -1), np.full(self.P, -1)
        first_i[pp[hit]], first_j[pp[hit]] = ii[hit], jj[hit]  # the hit, where only one
        return count, np.where(one, first_i, -1), np.where(one, first_j, -1)


@functools.lru_cache(maxsize=4)
def _run_pairs(n: int, c: int) -> tuple[np.ndarray, np.ndarray]:
    """For runs ci <= cj of c segments of a closed n-gon: the (i, j) segment pairs between
    them that ``_segment_pair_mask`` keeps, padded with (-n*n, -n*n) (two (C, C, c*c)
    tables)."""
    C = n // c
    mask = _segment_pair_mask(n)
    i = np.arange(C)[:, None, None, None] * c + np.arange(c)[None, None, :, None]
    j = np.arange(C)[None, :, None, None] * c + np.arange(c)[None, None, None, :]
    i, j = np.broadcast_to(i, (C, C, c, c)), np.broadcast_to(j, (C, C, c, c))
    keep = mask[i, j]
    pad = -n * n
    return (np.where(keep, i, pad).reshape(C, C, c * c),
            np.where(keep, j, pad).reshape(C, C, c * c))


@functools.lru_cache(maxsize=4)
def _segment_pair_mask(n: int) -> np.ndarray:
    """(n, n) True for segment pairs (i, j), i < j, of a closed n-gon that are not
    neighbours."""
    ii, jj = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    return (jj > ii + 1) & ~((ii == 0) & (jj == n - 1))
