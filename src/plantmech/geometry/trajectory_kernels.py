"""Kernels (numba) of ``trajectory_batch.TrajectoryBatch``: the exact coordinate range of
each row's closed cubic over a parameter span (Table 1's ring sizes and trench depth of
seed 000), one pass over the pieces without (P, N, 2, 2) temporaries. The same formulas
and arithmetic as the NumPy path of ``TrajectoryBatch.coordinate_range``, which stays as
the reference (tests/test_trajectory_batch.py). Imported lazily: numba stays out of the
CLI's start-up; its compilation is cached on disk (``cache=True``). Lengths mm,
parameters mm of chord.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def _mod(a, b):
    """np.mod(a, b) for b > 0, exactly as NumPy computes it (fmod, then + b where
    negative), without the fmod call for |a| < 2 b (where it is a, a - b or a + b:
    fmod's exact result, or NumPy's own rounded addition). Each kernel module keeps its
    own copy: numba's disk cache of a kernel does not notice a change in another
    module's function that it inlined."""
    if 0.0 <= a < b:
        return a
    if b <= a < 2.0 * b:
        return a - b  # exact (Sterbenz), as fmod is
    if -b <= a < 0.0:
        return a + b  # fmod(a, b) = a, then NumPy adds b
    r = np.fmod(a, b)
    if r < 0.0:
        r += b
    return r


@njit(cache=True, error_model="numpy")
def coordinate_extremes(coef, knots, h, period, u0, u1, lo, hi):
    """Lower ``lo`` and upper ``hi`` (P, 2) bounds of x and y updated with every
    stationary point of each row's cubics (roots of the derivative 3 c3 t^2 + 2 c2 t + c1,
    the numerically stable quadratic formula) that lies in its piece (0 <= t <= h) and
    in the parameter span u0..u1 (P,) (wrapped by the period). ``coef`` (P, N, 4, 2),
    lowest power first; ``knots`` (P, N + 1); ``h`` (P, N)."""
    P, N = coef.shape[0], coef.shape[1]
    for p in range(P):
        span = u1[p] - u0[p]
        for i in range(N):
            for axis in range(2):
                c0, c1 = coef[p, i, 0, axis], coef[p, i, 1, axis]
                c2, c3 = coef[p, i, 2, axis], coef[p, i, 3, axis]
                a, b, c = 3.0 * c3, 2.0 * c2, c1
                disc = b * b - 4.0 * a * c
                if not disc >= 0:
                    continue
                sq = np.sqrt(max(disc, 0.0))
                q = -0.5 * (b + (sq if b >= 0 else -sq))
                for which in range(2):
                    if which == 0:
                        if not abs(a) > 1e-300:
                            continue
                        t = q / a
                    else:
                        if not abs(q) > 1e-300:
                            continue
                        t = c / q
                    if not (t >= 0 and t <= h[p, i]):
                        continue
                    if not _mod((knots[p, i] + t) - u0[p], period[p]) <= span:
                        continue
                    val = c0 + t * (c1 + t * (c2 + t * c3))
                    lo[p, axis] = min(lo[p, axis], val)
                    hi[p, axis] = max(hi[p, axis], val)
