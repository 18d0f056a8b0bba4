"""Radius functions of pitch curves over a body angle (rad -> mm).

``RadiusCurve`` wraps an interpolant of r(theta) on one turn starting at
``theta0``. Periodic curves are C2 (periodic cubic spline) or C1 (periodic
Hermite with centred-difference tangents, seed 000 §4.3); a curve with a break
(the lock point of an intermittent gear) is a plain cubic on [theta0, theta0+2pi].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicHermiteSpline, CubicSpline

TWO_PI = 2.0 * np.pi


class PitchCurveError(ValueError):
    """A pitch curve is not a valid closed radius function."""


@dataclass(frozen=True)
class RadiusCurve:
    theta0: float
    spline: object
    periodic: bool

    @classmethod
    def from_samples(cls, theta, radius, kind: str = "spline", periodic: bool = True,
                     theta0: float | None = None, name: str = "pitch curve") -> RadiusCurve:
        """Interpolate radii ``radius`` (mm) at body angles ``theta`` (rad).

        kind: "spline" (periodic cubic spline, C2) or "hermite" (periodic cubic
        Hermite, C1, tangents from centred differences).
        """
        th = np.asarray(theta, dtype=float)
        r = np.asarray(radius, dtype=float)
        if th.shape != r.shape or th.ndim != 1:
            raise PitchCurveError(f"{name}: angles and radii must be 1-D of equal length")
        if len(th) < 3:
            raise PitchCurveError(f"{name}: need at least 3 interpolation points")
        if not (np.all(np.isfinite(th)) and np.all(np.isfinite(r))):
            k = int(np.flatnonzero(~(np.isfinite(th) & np.isfinite(r)))[0])
            raise PitchCurveError(f"{name}: point {k} is not a finite number")
        if np.any(r <= 0):
            k = int(np.flatnonzero(r <= 0)[0])
            raise PitchCurveError(f"{name}: radius {r[k]:g} mm at {np.degrees(th[k]):.2f} deg "
                                  "is not positive")
        t0 = float(th.min()) if theta0 is None else float(theta0)
        x = t0 + np.mod(th - t0, TWO_PI)
        order = np.argsort(x, kind="stable")
        x, r = x[order], r[order]
        if np.any(np.diff(x) <= 1e-12):
            k = int(np.flatnonzero(np.diff(x) <= 1e-12)[0])
            raise PitchCurveError(f"{name}: two points share the angle "
                                  f"{np.degrees(np.mod(x[k], TWO_PI)):.3f} deg")
        if periodic:
            xx, rr = np.r_[x, x[0] + TWO_PI], np.r_[r, r[0]]
            if kind == "spline":
                spl = CubicSpline(xx, rr, bc_type="periodic")
            elif kind == "hermite":
                xe = np.r_[x[-1] - TWO_PI, x, x[0] + TWO_PI]
                re = np.r_[r[-1], r, r[0]]
                slope = (re[2:] - re[:-2]) / (xe[2:] - xe[:-2])
                spl = CubicHermiteSpline(xx, rr, np.r_[slope, slope[0]])
            else:
                raise PitchCurveError(f"{name}: unknown interpolation {kind!r} "
                                      "(expected 'spline' or 'hermite')")
        else:
            spl = CubicSpline(x, r)
        return cls(t0, spl, periodic)

    def __call__(self, theta, nu: int = 0) -> np.ndarray:
        x = self.theta0 + np.mod(np.asarray(theta, dtype=float) - self.theta0, TWO_PI)
        return self.spline(x, nu)

    def derivatives(self, theta) -> np.ndarray:
        """(3, n): radius r (mm), r' (mm/rad) and r'' (mm/rad^2) at body angles ``theta``
        (n,) (rad): the values of ``self(theta, nu)`` for nu = 0, 1, 2, computed in one
        pass (``pitch_kernels``, one interval search per angle) for SciPy's cubic
        piecewise polynomials, with SciPy's arithmetic."""
        from scipy.interpolate import PPoly

        spl = self.spline
        theta = np.asarray(theta, dtype=float)
        if not (isinstance(spl, PPoly) and spl.c.shape[0] == 4 and spl.c.ndim == 2
                and theta.ndim == 1 and spl.extrapolate in (True, "periodic")):
            return np.stack([self(theta, nu) for nu in (0, 1, 2)])
        from plantmech.geometry.pitch_kernels import cubic_and_derivatives

        return cubic_and_derivatives(np.ascontiguousarray(spl.c, dtype=float),
                                     np.ascontiguousarray(spl.x, dtype=float), theta,
                                     float(self.theta0), spl.extrapolate == "periodic")


def cyclic_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Contiguous True runs of a cyclic boolean array as (first, last) indices; a run
    that wraps past the end has last < first."""
    if not mask.any():
        return []
    if mask.all():
        return [(0, len(mask) - 1)]
    idx = np.flatnonzero(np.diff(np.r_[mask[-1], mask].astype(int)))
    starts = [i for i in idx if mask[i]]
    ends = [i - 1 for i in idx if not mask[i]]
    runs = []
    for s in starts:
        later = [e for e in ends if e >= s]
        e = later[0] if later else (ends[0] % len(mask) if ends else len(mask) - 1)
        runs.append((int(s), int(e)))
    return runs


def convexity(curve: RadiusCurve, samples: int = 3600, span: float = TWO_PI) -> dict:
    """Convexity of the closed polar curve r(theta) (a pitch curve).

    Radius of curvature rho = (r^2 + r'^2)^(3/2) / (r^2 + 2 r'^2 - r r''); the curve is
    concave where the denominator is negative. Returns {convex, concave_spans_deg
    ([start, end] body angles), min_concave_radius_mm, min_convex_radius_mm}.
    """
    th = curve.theta0 + np.linspace(0.0, span, samples, endpoint=span >= TWO_PI)
    if hasattr(curve, "derivatives"):
        r, r1, r2 = curve.derivatives(th)
    else:
        r, r1, r2 = curve(th), curve(th, 1), curve(th, 2)
    den = r**2 + 2 * r1**2 - r * r2
    rho = (r**2 + r1**2) ** 1.5 / np.where(den == 0, np.nan, den)
    concave = den < 0
    if span < TWO_PI:  # an open arc: runs must not wrap
        runs = cyclic_runs(np.r_[concave, False])
        runs = [(a, min(b, samples - 1)) for a, b in runs]
    else:
        runs = cyclic_runs(concave)
    spans = [[float(np.degrees(np.mod(th[a], TWO_PI))), float(np.degrees(np.mod(th[b], TWO_PI)))]
             for a, b in runs]
    return {
        "convex": not concave.any(),
        "concave_spans_deg": spans,
        "min_concave_radius_mm": float(np.nanmin(-rho[concave])) if concave.any() else None,
        "min_convex_radius_mm": float(np.nanmin(rho[~concave])) if (~concave).any() else None,
    }


#: points of (P, N) tables from which ``polar_curvature_radius`` runs its numba kernel
#: (``geometry.curvature_kernels``: bitwise the same values); smaller ones (a single
#: design's curves) stay in NumPy, keeping numba out of one-shot runs
CURVATURE_KERNEL_POINTS = 2**15


def polar_curvature_radius(rho, drho, ddrho, dphi=1.0, ddphi=0.0):
    """Signed radius of curvature (mm) of polar curves (rho(t), phi(t)) from their
    derivatives in any parameter t (arrays broadcast; vectorised over designs):
    (rho'^2 + rho^2 phi'^2)^(3/2) / (rho^2 phi'^3 + 2 rho'^2 phi' - rho rho'' phi'
    + rho rho' phi''). Positive where the curve turns towards its centre (convex seen
    from outside), negative on concave spans, inf on straight ones."""
    # cubes as products: numpy's power(x, 3) calls pow() per element, ~5x slower. The
    # products are taken in the order of the formula above, into two buffers (a (P, N)
    # temporary costs a pass and, when large, fresh pages): the same numbers as the
    # expression written out
    plain = np.ndim(dphi) == 0 and dphi == 1.0 and np.ndim(ddphi) == 0 and ddphi == 0.0
    shape = np.broadcast_shapes(*(np.shape(x) for x in (rho, drho, ddrho, dphi, ddphi)))
    tables = (rho, drho, ddrho) if plain else (rho, drho, ddrho, dphi, ddphi)
    if len(shape) == 2 and shape[0] * shape[1] >= CURVATURE_KERNEL_POINTS and all(
            isinstance(x, np.ndarray) and x.shape == shape and x.dtype == np.float64
            for x in tables):  # a population's tables: one pass (numba), the same values
        from plantmech.geometry.curvature_kernels import polar_curvature_rows

        c = [np.ascontiguousarray(x) for x in tables]
        return polar_curvature_rows(*c[:3], *(c[3:] if not plain else (c[0], c[0])), plain)
    num, work = np.empty(shape), np.empty(shape)
    np.multiply(rho, rho, out=num)
    if not plain:  # phi' = 1, phi'' = 0 (phi = t): the factors 1 and the term 0 dropped
        num *= dphi * dphi * dphi
    np.multiply(drho, 2.0, out=work)
    work *= drho
    if not plain:
        work *= dphi
    num += work
    np.multiply(rho, ddrho, out=work)
    if not plain:
        work *= dphi
    num -= work
    if not plain:
        np.multiply(rho, drho, out=work)
        work *= ddphi
        num += work
    np.multiply(rho, rho, out=work)  # speed^2 = rho'^2 + rho^2 phi'^2
    if not plain:
        work *= dphi * dphi
    work += drho * drho
    np.sqrt(work, out=work)
    speed3 = work * work
    speed3 *= work
    zero = num == 0
    num[zero] = 1.0
    speed3 /= num
    speed3[zero] = np.inf
    return speed3


def pressure_angle_proxy(curve: RadiusCurve, samples: int = 3600) -> tuple[float, float]:
    """Largest angle (rad) between the pitch-curve tangent and the normal to the radius
    vector, atan(|r'| / r), and the body angle (rad) where it occurs. Two rolling pitch
    curves share their tangent at the contact on the line of centres, so the value holds
    for the pair; the working pressure angle of a tooth is the tool's plus this."""
    th = curve.theta0 + np.linspace(0.0, TWO_PI, samples, endpoint=False)
    mu = np.arctan(np.abs(curve(th, 1)) / curve(th))
    k = int(np.argmax(mu))
    return float(mu[k]), float(np.mod(th[k], TWO_PI))


def periodic_spline_matrix(nodes: np.ndarray, at: np.ndarray, nu: int = 0,
                           kind: str = "spline") -> np.ndarray:
    """Matrix M (len(at) x len(nodes)) with M @ r = nu-th derivative of the periodic
    interpolant through (nodes, r) at angles ``at`` (rad): ``spline`` (periodic cubic
    spline) or ``hermite`` (periodic cubic Hermite, centred-difference tangents, as
    ``RadiusCurve``)."""
    nodes, at = np.asarray(nodes, dtype=float), np.asarray(at, dtype=float)
    key = (nodes.tobytes(), at.shape, hash(at.tobytes()), nu, kind)
    m = _MATRICES.get(key)
    if m is None:
        if len(_MATRICES) >= 64:
            _MATRICES.clear()
        m = _MATRICES[key] = _spline_matrix(nodes, at, nu, kind)
        m.flags.writeable = False
    return m


_MATRICES: dict = {}  # population evaluations ask for the same few matrices every call


def hermite_basis(y0, y1, d0, d1, s, h) -> tuple:
    """(value, slope) of cubic Hermite segments from y0 to y1 with end slopes d0, d1 (per
    unit of s: the slopes times the step h) at s in [0, 1), h the step (rad). The train
    model's kernels (``trains.kernels._hermite``) repeat this arithmetic term for term."""
    s2 = s * s
    s3 = s2 * s
    dyy = y0 - y1
    value = y0 + (2 * s3 - 3 * s2) * dyy + (s3 - 2 * s2 + s) * d0 + (s3 - s2) * d1
    slope = ((6 * s2 - 6 * s) * dyy + (3 * s2 - 4 * s + 1) * d0 + (3 * s2 - 2 * s) * d1) / h
    return value, slope


def periodic_interpolant_rows(nodes: np.ndarray, radii: np.ndarray,
                              at: np.ndarray, kind: str = "spline") -> tuple:
    """Values (mm) and slopes (mm/rad) of each row's periodic interpolant through
    (nodes, radii[p]) at its own angles ``at[p]`` (rad): radii (P, N), at (P, M) -> two
    (P, M). The same interpolants as ``periodic_spline_matrix`` (both are piecewise cubic
    Hermite with node slopes linear in the radii), for angles that differ per design (a
    per-design phase), where one shared matrix cannot serve."""
    nodes = np.asarray(nodes, dtype=float)
    R = np.atleast_2d(np.asarray(radii, dtype=float))
    at = np.asarray(at, dtype=float)
    n = len(nodes)
    slopes = R @ periodic_spline_matrix(nodes, nodes, 1, kind).T  # (P, N) mm/rad
    x = np.r_[nodes, nodes[0] + TWO_PI]
    u = nodes[0] + np.mod(at - nodes[0], TWO_PI)
    k = np.clip(np.searchsorted(x, u, side="right") - 1, 0, n - 1)
    h = x[k + 1] - x[k]
    s = (u - x[k]) / h
    flat = k + (np.arange(R.shape[0]) * n)[:, None]
    k1 = flat - k + (k + 1) % n
    Rf, Df = R.ravel(), slopes.ravel()
    return hermite_basis(Rf[flat], Rf[k1], Df[flat] * h, Df[k1] * h, s, h)


def _spline_matrix(nodes, at, nu, kind):
    n = len(nodes)
    eye = np.eye(n)
    x = np.r_[nodes, nodes[0] + TWO_PI]
    if kind == "spline":
        spl = CubicSpline(x, np.vstack([eye, eye[:1]]), bc_type="periodic")
        return spl(nodes[0] + np.mod(at - nodes[0], TWO_PI), nu)
    cols = [RadiusCurve.from_samples(nodes, eye[k] + 1.0, kind=kind, theta0=float(nodes[0]))(
        at, nu) - (1.0 if nu == 0 else 0.0) for k in range(n)]  # linear: shift keeps r > 0
    return np.stack(cols, axis=-1)


def _uniform_spline_moments(values: np.ndarray, step: float) -> np.ndarray:
    """Second derivatives M at the nodes of the periodic cubic spline through ``values``
    (n, ...) at uniform ``step``: the circulant system M[i-1] + 4 M[i] + M[i+1] =
    6 / h^2 (y[i-1] - 2 y[i] + y[i+1]) solved by FFT (exactly the spline SciPy's
    CubicSpline(bc_type="periodic") builds, without its per-call set-up)."""
    y = np.asarray(values, dtype=float)
    n = y.shape[0]
    c = np.cos(TWO_PI * np.arange(n // 2 + 1) / n)
    gain = (6.0 / step**2) * (2.0 * c - 2.0) / (4.0 + 2.0 * c)
    shape = (-1,) + (1,) * (y.ndim - 1)
    return np.fft.irfft(np.fft.rfft(y, axis=0) * gain.reshape(shape), n=n, axis=0)


def periodic_spline_node_slopes(values: np.ndarray, step: float) -> np.ndarray:
    """Slopes at the nodes of the periodic cubic spline through ``values`` (n, ...)
    sampled at uniform ``step``: s'(x_i) = (y[i+1] - y[i]) / h - h (2 M[i] + M[i+1]) / 6."""
    y = np.asarray(values, dtype=float)
    m = _uniform_spline_moments(y, step)
    return (np.roll(y, -1, axis=0) - y) / step - step * (2.0 * m + np.roll(m, -1, axis=0)) / 6.0


def periodic_spline_running_integral(values: np.ndarray, step: float) -> np.ndarray:
    """Running integral (n + 1 values from 0, along the first axis) of the periodic cubic
    spline through ``values`` (n, ...) at uniform ``step``: per interval
    h (y[i] + y[i+1]) / 2 - h^3 (M[i] + M[i+1]) / 24."""
    y = np.asarray(values, dtype=float)
    m = _uniform_spline_moments(y, step)
    part = (0.5 * step * (y + np.roll(y, -1, axis=0))
            - step**3 * (m + np.roll(m, -1, axis=0)) / 24.0)
    return np.concatenate([np.zeros((1,) + y.shape[1:]), np.cumsum(part, axis=0)])
