"""Pitch curves of the general train model, tabulated for P designs on one grid.

A pitch curve is a radius function r(theta) (mm) of the gear's body angle theta (rad,
counter-clockwise in the gear's own frame). Every family is tabulated on a uniform grid of
N body angles over one turn, with its exact slope dr/dtheta (mm/rad), for P designs at
once: ``Curve.r`` and ``Curve.dr`` are (P, N). Between the grid points the curve is the
cubic Hermite interpolant of those values and slopes (error O(h^4), h = 2 pi / N), so a
mate derived by rolling (``trains.pairs``) and a family given in closed form are used
the same way.

Families (the design file's ``family``):

- ``ellipse`` turning about a focus: r = A (1 - e^2) / (1 - e cos theta), theta from the
  far end of the major axis (r(0) = A (1 + e), the largest radius);
- ``eccentric`` circle of radius R turning about a point E off its centre:
  r = E cos theta + sqrt(R^2 - E^2 sin^2 theta) (r(0) = R + E);
- ``fourier`` series r = r0 + sum_k (c_k cos k theta + s_k sin k theta);
- ``radii``: control radii at body angles joined by a periodic cubic Hermite (C1, seed
  000 §4.3) or periodic cubic spline (C2) (``geometry.periodic``), optionally repeated
  over ``lobes`` identical lobes (r(theta) = interpolant(lobes * theta)).

An *open* curve (``Curve.r_end``, ``interpolated(..., open_turn=True)``) has a break at body
angle 0: its radius's right limit there (``r[:, 0]``, the start of the open turn) and its
left limit (``r_end``, the end of the turn at 2 pi) differ, and it is smooth elsewhere (the
inverse-designed gears 2 and 3 of seed 000's seeder with a toothless dwell: their ratio
jumps at the lock point, where meshing stops and restarts). The table's last interval
[2 pi - h, 2 pi) is read with the left limits, so the Hermite reading never interpolates
across the break; the value at body angle 0 (mod 2 pi) is the right limit.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

TWO_PI = 2.0 * np.pi


class CurveError(ValueError):
    """A pitch curve that is not a valid closed radius function (message names the
    design and body angle)."""


def _column(v, P: int | None = None) -> np.ndarray:
    """A scalar or (P,) parameter as a (P or 1, 1) column."""
    v = np.asarray(v, dtype=float)
    v = v.reshape(-1, 1) if v.ndim else v.reshape(1, 1)
    if P is not None and v.shape[0] not in (1, P):
        raise ValueError(f"a per-design parameter has {v.shape[0]} values for {P} designs")
    return v


#: angles (designs x angles) from which a table is interpolated or inverted by the numba
#: kernels (``trains.kernels``; the same values to the last bit): a population's full
#: grids; a single design's tables (8192-16384 points) and a population's 720 samples
#: stay in NumPy, so numba (~0.5 s to import) stays out of one-shot runs
KERNEL_POINTS = 2**15


def use_kernels(points: int) -> bool:
    """Whether a table of ``points`` angles goes through ``trains.kernels``."""
    return points >= KERNEL_POINTS


def hermite_periodic(y: np.ndarray, dy: np.ndarray, x: np.ndarray) -> tuple:
    """Value and slope at angles ``x`` (rad) of each row's periodic cubic Hermite
    interpolant through values ``y`` (P, N) and slopes ``dy`` (P, N) on the uniform grid
    2 pi k / N. ``x`` has shape (P, ...) or (1, ...) (shared by every row)."""
    P, N = y.shape
    h = TWO_PI / N
    x = np.asarray(x, dtype=float)
    shape = (P,) + x.shape[1:]
    points = P * (int(np.prod(shape[1:])) if len(shape) > 1 else 1)
    if use_kernels(points):
        from plantmech.trains.kernels import hermite_rows

        flat = x.reshape(x.shape[0], -1)
        value, slope = hermite_rows(np.ascontiguousarray(y, dtype=float),
                                    np.ascontiguousarray(dy, dtype=float),
                                    np.ascontiguousarray(flat), flat.shape[0] == 1 and P > 1)
        return value.reshape(shape), slope.reshape(shape)
    u = np.broadcast_to(x, shape).reshape(P, -1) * (1.0 / h)
    kf = np.floor(u)
    s = u - kf
    k = kf.astype(np.intp) % N
    base = (np.arange(P) * N)[:, None]  # flat indices: one gather per table
    i0 = k + base
    i1 = np.where(k == N - 1, base, i0 + 1)
    yf, df = y.ravel(), dy.ravel()
    y0, y1 = yf.take(i0), yf.take(i1)
    d0, d1 = df.take(i0) * h, df.take(i1) * h
    from plantmech.geometry.periodic import hermite_basis  # (SciPy: not at import)

    value, slope = hermite_basis(y0, y1, d0, d1, s, h)
    return value.reshape(shape), slope.reshape(shape)


def hermite_open(y: np.ndarray, dy: np.ndarray, y_end: np.ndarray, dy_end: np.ndarray,
                 x: np.ndarray) -> tuple:
    """As ``hermite_periodic`` for an open table: the last interval [2 pi - h, 2 pi) ends
    at the left limits ``y_end``, ``dy_end`` (P,) instead of wrapping to column 0, so a
    break at body angle 0 is never interpolated across (angles taken mod 2 pi; the value
    at 0 is the right limit ``y[:, 0]``)."""
    P, N = y.shape
    h = TWO_PI / N
    x = np.asarray(x, dtype=float)
    shape = (P,) + x.shape[1:]
    u = np.broadcast_to(x, shape).reshape(P, -1) * (1.0 / h)
    kf = np.floor(u)
    s = u - kf
    k = kf.astype(np.intp) % N
    i0 = k + (np.arange(P) * (N + 1))[:, None]  # flat indices in the (P, N + 1) tables
    yf = np.concatenate([y, np.reshape(y_end, (P, 1))], axis=1).ravel()
    df = np.concatenate([dy, np.reshape(dy_end, (P, 1))], axis=1).ravel()
    y0, y1 = yf.take(i0), yf.take(i0 + 1)
    d0, d1 = df.take(i0) * h, df.take(i0 + 1) * h
    from plantmech.geometry.periodic import hermite_basis  # (SciPy: not at import)

    value, slope = hermite_basis(y0, y1, d0, d1, s, h)
    return value.reshape(shape), slope.reshape(shape)


@dataclass
class Curve:
    """P pitch curves tabulated on the uniform grid theta_k = 2 pi k / N (rad):
    radii ``r`` (P, N) mm and slopes ``dr`` (P, N) mm/rad. An open curve (a break at
    body angle 0, module docstring) also has its left limits at 2 pi: ``r_end`` (P,) mm and
    ``dr_end`` (P,) mm/rad; None: periodic."""

    r: np.ndarray
    dr: np.ndarray
    name: str = "pitch curve"
    r_end: np.ndarray | None = None
    dr_end: np.ndarray | None = None

    @property
    def open(self) -> bool:
        """Whether the curve breaks at body angle 0 (``r_end`` given)."""
        return self.r_end is not None

    @property
    def theta(self) -> np.ndarray:
        return TWO_PI * np.arange(self.r.shape[1]) / self.r.shape[1]

    @property
    def designs(self) -> int:
        return self.r.shape[0]

    def __call__(self, theta) -> tuple[np.ndarray, np.ndarray]:
        """(r, dr/dtheta) at body angles ``theta`` (rad), shape (P, ...) or (1, ...); an
        open curve's right limit at its break (0 mod 2 pi)."""
        if self.open:
            return hermite_open(self.r, self.dr, self.r_end, self.dr_end, theta)
        return hermite_periodic(self.r, self.dr, theta)

    def take(self, k: int) -> Curve:
        if self.open:
            return Curve(self.r[k:k + 1], self.dr[k:k + 1], self.name, self.r_end[k:k + 1],
                         self.dr_end[k:k + 1])
        return Curve(self.r[k:k + 1], self.dr[k:k + 1], self.name)

    def check_positive(self, min_radius: float = 0.0) -> None:
        if self.open and np.any(self.r_end <= min_radius):
            d = int(np.argmax(self.r_end <= min_radius))
            raise CurveError(f"{self.name}: radius {self.r_end[d]:.4g} mm at the end of its "
                             "open turn (body angle 360 deg, the left side of its break)"
                             + (f" (design {d})" if self.designs > 1 else "")
                             + f" is not above {min_radius:g} mm")
        if self.r.min() > min_radius or np.isnan(self.r.min()):  # one reduction, no mask
            return
        bad = self.r <= min_radius
        if bad.any():
            d, k = (int(i) for i in np.argwhere(bad)[0])
            raise CurveError(f"{self.name}: radius {self.r[d, k]:.4g} mm at body angle "
                             f"{np.degrees(self.theta[k]):.2f} deg"
                             + (f" (design {d})" if self.designs > 1 else "")
                             + f" is not above {min_radius:g} mm")


def ellipse(semi_major, eccentricity, grid: int, name: str = "ellipse") -> Curve:
    """Ellipse turning about a focus: r = A (1 - e^2) / (1 - e cos theta) (mm), theta
    from the far end of the major axis; A = ``semi_major`` (mm), e = ``eccentricity``
    (0 <= e < 1), scalars or (P,)."""
    A, e = _column(semi_major), _column(eccentricity)
    if np.any(A <= 0) or np.any((e < 0) | (e >= 1)):
        raise CurveError(f"{name}: needs a positive semi-major axis and 0 <= e < 1")
    th = TWO_PI * np.arange(grid) / grid
    p = A * (1 - e**2)
    den = 1 - e * np.cos(th)
    r = p / den
    dr = -p * e * np.sin(th) / den**2
    r, dr = np.broadcast_arrays(r, dr)
    return Curve(np.array(r), np.array(dr), name)


def eccentric_circle(radius, offset, grid: int, name: str = "eccentric circle") -> Curve:
    """Circle of radius R (mm) turning about a point at distance E < R (mm) from its
    centre: r = E cos theta + sqrt(R^2 - E^2 sin^2 theta), theta from the far side."""
    R, E = _column(radius), _column(offset)
    if np.any(E < 0) or np.any(E >= R):
        raise CurveError(f"{name}: the offset must be >= 0 and below the radius")
    th = TWO_PI * np.arange(grid) / grid
    root = np.sqrt(R**2 - (E * np.sin(th)) ** 2)
    r = E * np.cos(th) + root
    dr = -E * np.sin(th) - E**2 * np.sin(th) * np.cos(th) / root
    r, dr = np.broadcast_arrays(r, dr)
    return Curve(np.array(r), np.array(dr), name)


def fourier(mean_radius, cos_mm, sin_mm, grid: int, name: str = "fourier") -> Curve:
    """r = r0 + sum_k (c_k cos k theta + s_k sin k theta), k = 1.. (mm); r0 scalar or (P,),
    c and s (K,) or (P, K)."""
    r0 = _column(mean_radius)
    c = np.atleast_2d(np.asarray(cos_mm, dtype=float))
    s = np.atleast_2d(np.asarray(sin_mm, dtype=float))
    K = max(c.shape[1], s.shape[1])
    c = np.pad(c, ((0, 0), (0, K - c.shape[1])))
    s = np.pad(s, ((0, 0), (0, K - s.shape[1])))
    th = TWO_PI * np.arange(grid) / grid
    k = np.arange(1, K + 1)
    cos, sin = np.cos(np.outer(k, th)), np.sin(np.outer(k, th))  # (K, N)
    r = r0 + rows_matmul(c, cos) + rows_matmul(s, sin)
    dr = rows_matmul(s * k, cos) - rows_matmul(c * k, sin)
    r, dr = np.broadcast_arrays(r, dr)
    curve = Curve(np.array(r), np.array(dr), name)
    curve.check_positive()
    return curve


#: multiply-adds of one BLAS call below which OpenBLAS keeps to one thread (its
#: GEMM_MULTITHREAD_THRESHOLD 4 x 65536)
_ONE_THREAD_MACS = 4 * 65536


def rows_matmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a (P, K) @ b (K, N), a few rows per BLAS call: each call small enough for one
    thread, the product of a (P, K) table of parameters and a fixed basis. Measured on this
    shared 2-core machine (P = 32, K = 8, N = 16384): 16 ms as one threaded call under
    load, 0.35 ms on one thread (its threads wait for each other when the cores are
    busy). A row equals its single design's (P = 1, BLAS's matrix-vector kernel) to
    rounding (tests/test_trains_population.py)."""
    P, K = a.shape
    rows = max(1, _ONE_THREAD_MACS // max(K * b.shape[1], 1))
    if P <= rows:
        return a @ b
    out = np.empty((P, b.shape[1]))
    for i in range(0, P, rows):
        np.matmul(a[i:i + rows], b, out=out[i:i + rows])
    return out


@functools.lru_cache(maxsize=32)
def _interpolation_matrix(nodes: tuple, grid: int, lobes: int, kind: str, nu: int
                          ) -> np.ndarray:
    """(K, grid) matrix M with radii (P, K) @ M = the nu-th derivative of the periodic
    ``kind`` interpolant through the nodes at phases lobes * theta_k (``geometry.periodic
    .periodic_spline_matrix``, transposed). Built once per (nodes, grid, lobes, kind, nu):
    a population of P curves, and every later design of the same structure, reuse it
    (it is read-only)."""
    from plantmech.geometry.periodic import periodic_spline_matrix

    at = lobes * (TWO_PI * np.arange(grid) / grid)
    m = np.ascontiguousarray(periodic_spline_matrix(np.asarray(nodes), at, nu, kind).T)
    m.flags.writeable = False
    return m


def interpolated(angles, radii, grid: int, kind: str = "hermite", lobes: int = 1,
                 name: str = "radii", open_turn: bool = False) -> Curve:
    """Control radii (P, K) or (K,) mm at phases ``angles`` (K,) rad joined by a periodic
    ``kind`` interpolant f (``hermite``: C1, tangents from centred differences; ``spline``:
    C2), as ``geometry.periodic``. With ``lobes`` n the curve is n identical lobes,
    r(theta) = f(n theta): the phases are body angles times n (for n = 1, body angles).

    ``open_turn``: an open curve (module docstring) over one turn from its break at body
    angle 0: ``angles`` run from 0 to 2 pi (both ends given), the first radius is the
    right limit at the break and the last the left limit; joined by SciPy's not-a-knot
    cubic spline (``spline``, seed 000's inverse-designed gears with a dwell,
    ``mechanisms.seeder_trains.train_from_inverse``) or a cubic Hermite with centred
    slopes and one-sided ones at the two ends (``hermite``); one lobe."""
    radii = np.atleast_2d(np.asarray(radii, dtype=float))
    if open_turn:
        th = TWO_PI * np.arange(grid) / grid
        return _open_interpolated(np.asarray(angles, dtype=float), radii, th, kind, lobes,
                                  name)
    nodes = tuple(float(v) for v in np.asarray(angles, dtype=float).ravel())
    r = rows_matmul(radii, _interpolation_matrix(nodes, grid, lobes, kind, 0))
    dr = lobes * rows_matmul(radii, _interpolation_matrix(nodes, grid, lobes, kind, 1))
    curve = Curve(r, dr, name)
    curve.check_positive()
    return curve


def _open_interpolated(nodes: np.ndarray, radii: np.ndarray, th: np.ndarray, kind: str,
                       lobes: int, name: str) -> Curve:
    """The open curve of ``interpolated(..., open_turn=True)``: radii (P, K) mm at
    ``nodes`` (K,) rad from 0 to 2 pi, tabulated at ``th`` (N,) rad, left limits at 2 pi."""
    from scipy.interpolate import CubicHermiteSpline, CubicSpline

    if lobes != 1:
        raise CurveError(f"{name}: an open curve (a break at body angle 0) has one lobe, "
                         f"got lobes = {lobes}")
    if nodes.ndim != 1 or nodes.size < 4 or nodes.size != radii.shape[1]:
        raise CurveError(f"{name}: an open curve needs at least 4 radii, one per angle")
    if abs(nodes[0]) > 1e-12 or abs(nodes[-1] - TWO_PI) > 1e-9 or np.any(np.diff(nodes) <= 0):
        raise CurveError(f"{name}: an open curve's angles run from 0 deg (its break, the "
                         "right limit) to 360 deg (the left limit), increasing")
    x = nodes.copy()
    x[-1] = TWO_PI
    if kind == "spline":
        f = CubicSpline(x, radii.T, axis=0)  # not-a-knot, as the seeder's open curves
    elif kind == "hermite":
        slope = np.empty_like(radii.T)
        slope[1:-1] = (radii.T[2:] - radii.T[:-2]) / (x[2:] - x[:-2])[:, None]
        slope[0] = (radii.T[1] - radii.T[0]) / (x[1] - x[0])
        slope[-1] = (radii.T[-1] - radii.T[-2]) / (x[-1] - x[-2])
        f = CubicHermiteSpline(x, radii.T, slope, axis=0)
    else:
        raise CurveError(f"{name}: unknown interpolation {kind!r} (expected 'hermite' or "
                         "'spline')")
    curve = Curve(np.ascontiguousarray(f(th).T), np.ascontiguousarray(f(th, 1).T), name,
                  np.asarray(f(TWO_PI), dtype=float).reshape(-1),
                  np.asarray(f(TWO_PI, 1), dtype=float).reshape(-1))
    curve.check_positive()
    return curve


def second_derivative(curve: Curve) -> np.ndarray:
    """d^2 r / d theta^2 (P, N) from the tabulated slopes' centred differences; an open
    curve's one-sided at body angle 0 (right) and at the last grid angle (towards its left
    limit at 2 pi), never across its break."""
    h = TWO_PI / curve.r.shape[1]
    r2 = (np.roll(curve.dr, -1, axis=1) - np.roll(curve.dr, 1, axis=1)) / (2 * h)
    if curve.open:
        r2[:, 0] = (curve.dr[:, 1] - curve.dr[:, 0]) / h
        r2[:, -1] = (curve.dr_end - curve.dr[:, -2]) / (2 * h)
    return r2


def convexity(curve: Curve) -> dict:
    """Per design: is the polar curve convex (r^2 + 2 r'^2 - r r'' >= 0 everywhere), and
    its smallest radius of curvature (mm, negative where concave). r'' from the slopes'
    centred differences (an open curve's one-sided at its break, never across it)."""
    r, r1 = curve.r, curve.dr
    r2 = second_derivative(curve)
    den = r**2 + 2 * r1**2 - r * r2
    rho = (r**2 + r1**2) ** 1.5 / np.where(den == 0, np.nan, den)
    return {"convex": np.all(den >= 0, axis=1),
            "min_radius_of_curvature_mm": np.nanmin(np.where(den > 0, rho, np.inf), axis=1),
            "min_concave_radius_mm": np.nanmin(np.where(den < 0, -rho, np.inf), axis=1)}
