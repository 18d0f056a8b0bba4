"""Kernel (numba) of ``periodic.RadiusCurve.derivatives``: a cubic piecewise polynomial
(SciPy's ``PPoly``: ``CubicSpline``, ``CubicHermiteSpline``) and its first and second
derivatives at many angles in one pass: one interval search per angle instead of three,
with SciPy's own interval rule and arithmetic (the power sum of ``evaluate_poly1`` with its
derivative prefactors), so the values are SciPy's to the last bit
(tests/test_periodic.py). Imported lazily: numba stays out of the CLI's start-up; its
compilation is cached on disk (``cache=True``). Radius mm, angle rad.
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
def cubic_and_derivatives(c, breaks, theta, theta0, periodic):
    """(3, n): the piecewise cubic with coefficients ``c`` (4, m), highest power first, on
    ``breaks`` (m + 1, increasing) and its first and second derivatives at the body
    angles ``theta`` (n,) mapped onto the turn from ``theta0`` (``RadiusCurve``'s rule)
    and, when ``periodic``, onto the breaks' span (``PPoly``'s periodic extrapolation);
    else extrapolating from the end pieces; NaN at NaN: as ``PPoly.__call__(x, nu)``
    gives them."""
    n = theta.shape[0]
    m = breaks.shape[0] - 1
    two_pi = 2.0 * np.pi
    out = np.empty((3, n))
    for j in range(n):
        xv = theta0 + _mod(theta[j] - theta0, two_pi)
        if periodic:
            xv = breaks[0] + _mod(xv - breaks[0], breaks[m] - breaks[0])
        if not (xv == xv):
            out[0, j] = out[1, j] = out[2, j] = np.nan
            continue
        if xv < breaks[0]:
            i = 0
        elif xv >= breaks[m]:
            i = m - 1
        else:
            lo, hi = 0, m  # breaks[lo] <= xv < breaks[hi]
            while hi - lo > 1:
                mid = (lo + hi) >> 1
                if xv >= breaks[mid]:
                    lo = mid
                else:
                    hi = mid
            i = lo
        s = xv - breaks[i]
        s2 = s * s
        c0, c1, c2, c3 = c[0, i], c[1, i], c[2, i], c[3, i]
        # SciPy's sums: res += c[k - kp] * z * prefactor, z = s^(kp - nu)
        out[0, j] = ((0.0 + c3 * 1.0 * 1.0) + c2 * s * 1.0) + c1 * s2 * 1.0 + c0 * (s2 * s) * 1.0
        out[1, j] = ((0.0 + c2 * 1.0 * 1.0) + c1 * s * 2.0) + c0 * s2 * 3.0
        out[2, j] = (0.0 + c1 * 1.0 * 2.0) + c0 * s * 6.0
    return out
