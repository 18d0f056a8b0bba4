"""Kernels (numba) of the general train model's large tables: the periodic cubic Hermite
interpolant (``curves.hermite_periodic``) and the inversion of a pair's law
(``pairs.PairLaw.invert``), one pass per angle instead of NumPy's ~35 passes over (P, M)
temporaries. The arithmetic is the NumPy version's, term by term in the same order (no
fast-math: no reassociation, no fused multiply-add), so the values are the same to the
last bit (tests/test_trains_population.py). Used above ``curves.KERNEL_POINTS`` angles only
(``curves.use_kernels``): a single design keeps NumPy and numba stays out of the CLI's start-up
and of the app's first frame; the compilation is cached on disk (``cache=True``).
Angles rad, radii mm.
"""

from __future__ import annotations

import numpy as np
from numba import njit

TWO_PI = 2.0 * np.pi


@njit(cache=True, error_model="numpy", inline="always")
def _hermite(y0, y1, d0, d1, s, h):
    """(value, slope) of the cubic Hermite segment from y0 to y1 with end slopes d0, d1
    (per unit of s, i.e. times h) at s in [0, 1): the arithmetic of
    ``geometry.periodic.hermite_basis``."""
    s2 = s * s
    s3 = s2 * s
    dyy = y0 - y1
    value = y0 + (2 * s3 - 3 * s2) * dyy + (s3 - 2 * s2 + s) * d0 + (s3 - s2) * d1
    slope = ((6 * s2 - 6 * s) * dyy + (3 * s2 - 4 * s + 1) * d0 + (3 * s2 - 2 * s) * d1) / h
    return value, slope


@njit(cache=True, error_model="numpy", nogil=True)
def hermite_rows(y, dy, x, shared):
    """(value, slope) (P, M) of each row's periodic cubic Hermite interpolant through values
    ``y`` (P, N) and slopes ``dy`` (P, N) on the uniform grid 2 pi k / N, at angles ``x``
    (P, M), or (1, M) shared by every row when ``shared``."""
    P, N = y.shape
    M = x.shape[1]
    h = TWO_PI / N
    inv = 1.0 / h
    value = np.empty((P, M))
    slope = np.empty((P, M))
    for p in range(P):
        row = 0 if shared else p
        for j in range(M):
            u = x[row, j] * inv
            if not np.isfinite(u):  # NumPy's version gives NaN there too
                value[p, j] = slope[p, j] = np.nan
                continue
            kf = np.floor(u)
            s = u - kf
            k = int(kf) % N
            k1 = 0 if k == N - 1 else k + 1
            value[p, j], slope[p, j] = _hermite(y[p, k], y[p, k1], dy[p, k] * h,
                                                dy[p, k1] * h, s, h)
    return value, slope


@njit(cache=True, error_model="numpy", nogil=True)
def invert_rows(Fp, gq, q, target, newton):
    """Body angles theta (P, M) with Fp(theta) + q theta = ``target`` (P, M) (rad): ``Fp``
    (P, N) the law's periodic part and ``gq`` (P, N) its slope (g - q) on the uniform grid,
    ``q`` (P,) the turns per turn. Per angle: the whole turns w, the interval of the
    rising table Fp + q theta_k holding the rest (a walk from the previous angle's, or a
    bisection), its linear inverse, then
    ``newton`` Newton steps on the Hermite interpolant of Fp (``PairLaw.invert``)."""
    P, N = Fp.shape
    M = target.shape[1]
    h = TWO_PI / N
    inv = 1.0 / h
    out = np.empty((P, M))
    for p in range(P):
        k_last, last = 0, 0.0
        qp = q[p]
        period = TWO_PI * qp
        for j in range(M):
            F = target[p, j]
            if not np.isfinite(F):
                out[p, j] = np.nan
                continue
            w = np.floor(F / period)
            yv = F - w * period
            # k: the last i with table[i] <= yv (0 if none), table[i] = Fp[i] + q i h rising
            # over i = 0..N - 1; a target near the previous one (a mate's grid, either
            # way) walks from the previous angle's interval, up to 8 steps, others bisect:
            # the same k either way
            lo, hi = 0, N
            if j > 0 and yv >= last:  # table[k_last] <= yv: walk up
                lo = k_last
                steps = 0
                while lo + 1 < N and Fp[p, lo + 1] + qp * ((lo + 1) * h) <= yv and steps < 8:
                    lo += 1
                    steps += 1
                if steps < 8:
                    hi = lo + 1
            elif j > 0:  # table[k_last + 1] > yv (or k_last = N - 1): walk down
                hi = k_last + 1
                steps = 0
                while hi > 1 and Fp[p, hi - 1] + qp * ((hi - 1) * h) > yv and steps < 8:
                    hi -= 1
                    steps += 1
                if steps < 8:
                    lo = hi - 1
            while hi - lo > 1:
                mid = (lo + hi) // 2
                if Fp[p, mid] + qp * (mid * h) <= yv:
                    lo = mid
                else:
                    hi = mid
            k = lo
            k_last, last = k, yv
            f0 = Fp[p, k] + qp * (k * h)
            f1 = (Fp[p, k + 1] if k + 1 < N else Fp[p, 0]) + qp * ((k + 1) * h)
            theta = k * h + h * (yv - f0) / (f1 - f0 if f1 > f0 else 1.0)
            for _ in range(newton):
                u = theta * inv
                if not np.isfinite(u):
                    break
                kf = np.floor(u)
                s = u - kf
                i0 = int(kf) % N
                i1 = 0 if i0 == N - 1 else i0 + 1
                fp, dfp = _hermite(Fp[p, i0], Fp[p, i1], gq[p, i0] * h, gq[p, i1] * h, s, h)
                step = theta - (fp + qp * theta - yv) / (dfp + qp)
                if step == theta:  # settled: the steps left would give it again
                    break
                theta = step
            out[p, j] = theta + TWO_PI * w
    return out
