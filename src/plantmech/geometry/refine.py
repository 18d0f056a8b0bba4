"""Extremes and crossings located on the continuous curve, not read off the sample grid
(issue 34).

A quantity sampled at uniform carrier angles (a ratio law, a tip coordinate) is the sample
of a curve the model defines between the samples too: the periodic cubic spline of a law
(``periodic_law``), or the cubic Hermite segment of a motion whose rate is known exactly
(``geometry.periodic.hermite_basis``). Its minimum or maximum lies between samples and a
crossing of a level (zero, the ground) likewise; a grid of 0.1 deg reads them up to half a
step late and the extreme up to the curvature times the step squared. Scalars are refined
with Brent's methods (``scipy.optimize``: bounded minimisation, ``brentq``); populations
(P rows at once) with the Illinois method on each row's bracketing segment.
"""

from __future__ import annotations

import numpy as np

TWO_PI = 2.0 * np.pi


def periodic_law(values: np.ndarray):
    """The periodic cubic spline through ``values`` (n,) at uniform angles 2 pi k / n over
    one turn; the callable evaluates it (``nu`` = derivative order) at any angle (rad), the
    turn repeating."""
    from scipy.interpolate import CubicSpline

    v = np.asarray(values, dtype=float)
    n = len(v)
    return CubicSpline(TWO_PI * np.arange(n + 1) / n, np.r_[v, v[:1]], bc_type="periodic")


def minimum_between(f, lo: float, hi: float) -> tuple[float, float]:
    """(x, f(x)) of the smallest value of the scalar function ``f`` on [lo, hi] (Brent's
    bounded method; the bracket is a sample either side of the smallest sample)."""
    from scipy.optimize import minimize_scalar

    r = minimize_scalar(f, bounds=(lo, hi), method="bounded",
                        options={"xatol": 1e-12 * max(1.0, abs(hi))})
    x = float(r.x)
    # never worse than the bracket's ends (the bounded method does not evaluate them)
    best = min((float(f(x)), x), (float(f(lo)), lo), (float(f(hi)), hi))
    return best[1], best[0]


def crossing_between(f, lo: float, hi: float, level: float = 0.0) -> float:
    """x in [lo, hi] where the scalar function ``f`` crosses ``level`` (Brent's root
    finder); ``f(lo) - level`` and ``f(hi) - level`` must differ in sign (else the end
    nearer the level is returned)."""
    from scipy.optimize import brentq

    a, b = float(f(lo)) - level, float(f(hi)) - level
    if a == 0.0:
        return float(lo)
    if b == 0.0 or a * b > 0:
        return float(hi if abs(b) <= abs(a) else lo)
    return float(brentq(lambda x: float(f(x)) - level, lo, hi, xtol=1e-14, rtol=1e-14))


def run_of_law(law, psi: np.ndarray, first: int, last: int, level: float = 0.0) -> dict:
    """A run of samples ``first..last`` (cyclic: last < first wraps) of the periodic law
    ``law`` (callable of the angle, rad) below ``level``, refined: {start, end (rad, the
    crossings of the level between the run's outer samples and their neighbours; start
    may be negative when the run wraps), x_min, minimum (the law's smallest value within
    the run, between samples)}."""
    n = len(psi)
    step = TWO_PI / n
    x0 = float(psi[first])
    x1 = x0 + ((last - first) % n) * step
    start = crossing_between(law, x0 - step, x0, level)
    end = crossing_between(law, x1, x1 + step, level)
    k = np.arange(first, first + (last - first) % n + 1) % n
    xs = x0 + np.arange(len(k)) * step
    j = int(np.argmin(law(xs)))
    x_min, minimum = minimum_between(law, xs[j] - step, xs[j] + step)
    return {"start": start, "end": end, "x_min": x_min, "minimum": minimum}


def hermite_crossing(y0, y1, d0, d1, level, iterations: int = 60) -> np.ndarray:
    """s in [0, 1] where the cubic Hermite segments from y0 to y1 with end slopes d0, d1
    (per unit of s) cross ``level`` (arrays broadcast; the samples y0, y1 must bracket it,
    else the end nearer the level): the Illinois method, every segment at once."""
    from plantmech.geometry.periodic import hermite_basis

    y0, y1, d0, d1, level = np.broadcast_arrays(*(np.asarray(v, dtype=float)
                                                  for v in (y0, y1, d0, d1, level)))
    lo, hi = np.zeros(y0.shape), np.ones(y0.shape)
    f_lo, f_hi = y0 - level, y1 - level
    ok = f_lo * f_hi < 0
    f_lo, f_hi = np.where(ok, f_lo, -1.0), np.where(ok, f_hi, 1.0)
    side = np.zeros(y0.shape)
    s = lo
    for _ in range(iterations):
        s = lo - f_lo * (hi - lo) / (f_hi - f_lo)
        f = np.where(ok, hermite_basis(y0, y1, d0, d1, s, 1.0)[0] - level, 0.0)
        same = f * f_lo > 0  # the root lies above s
        lo, hi = np.where(same, s, lo), np.where(same, hi, s)
        f_hi = np.where(same, np.where(side > 0, 0.5 * f_hi, f_hi), f)
        f_lo = np.where(same, f, np.where(side < 0, 0.5 * f_lo, f_lo))
        side = np.where(same, 1.0, -1.0)
        if np.abs(f).max(initial=0.0) < 1e-12:
            break
    nearer = np.where(np.abs(y1 - level) < np.abs(y0 - level), 1.0, 0.0)
    return np.where(ok, s, nearer)


def hermite_extreme(y0, y1, d0, d1, largest: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """(s, value): the largest (``largest``) or smallest value of the cubic Hermite
    segments over s in [0, 1] (closed form: the roots of its quadratic derivative and the
    ends; arrays broadcast)."""
    from plantmech.geometry.periodic import hermite_basis

    y0, y1, d0, d1 = np.broadcast_arrays(*(np.asarray(v, dtype=float)
                                           for v in (y0, y1, d0, d1)))
    dyy = y0 - y1
    # slope(s) = a s^2 + b s + c (per unit of s)
    a = 6 * dyy + 3 * d0 + 3 * d1
    b = -6 * dyy - 4 * d0 - 2 * d1
    c = d0
    cands = [np.zeros(y0.shape), np.ones(y0.shape)]
    disc = b * b - 4 * a * c
    root = np.sqrt(np.where(disc >= 0, disc, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        quad = np.abs(a) > 1e-14 * (np.abs(b) + np.abs(c) + 1e-300)
        for sign in (1.0, -1.0):
            r = np.where(quad, (-b + sign * root) / (2 * a), -c / np.where(b == 0, np.inf, b))
            cands.append(np.where((disc >= 0) & (r > 0) & (r < 1), r, 0.0))
    s = np.stack(cands)
    v = hermite_basis(y0[None], y1[None], d0[None], d1[None], s, 1.0)[0]
    k = np.argmax(v, axis=0) if largest else np.argmin(v, axis=0)
    take = np.take_along_axis
    return take(s, k[None], axis=0)[0], take(v, k[None], axis=0)[0]


def cyclic_extreme(values, rates, step: float, largest: bool = True) -> np.ndarray:
    """The largest (``largest``) or smallest value of closed sampled curves, between the
    samples: ``values`` (..., S) at S uniform steps of ``step`` (rad) around a turn,
    ``rates`` their exact derivatives per rad; the cubic Hermite segments on either side
    of each row's extreme sample (closed form, ``hermite_extreme``), never less extreme
    than that sample."""
    v = np.asarray(values, dtype=float)
    r = np.asarray(rates, dtype=float) * step
    S = v.shape[-1]
    k = (np.argmax(v, axis=-1) if largest else np.argmin(v, axis=-1))[..., None]
    best = np.take_along_axis(v, k, axis=-1)[..., 0]
    pick = (np.maximum if largest else np.minimum)
    for a, b in ((k - 1) % S, k), (k, (k + 1) % S):
        y0, y1 = (np.take_along_axis(v, i, axis=-1)[..., 0] for i in (a, b))
        d0, d1 = (np.take_along_axis(r, i, axis=-1)[..., 0] for i in (a, b))
        best = pick(best, hermite_extreme(y0, y1, d0, d1, largest=largest)[1])
    return best


__all__ = ["crossing_between", "cyclic_extreme", "hermite_crossing", "hermite_extreme",
           "minimum_between", "periodic_law", "run_of_law"]
