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
def cubic_and_derivatives(c, breaks, x):
    """(3, n): the piecewise cubic with coefficients ``c`` (4, m), highest power first, on
    ``breaks`` (m + 1, increasing) and its first and second derivatives at ``x`` (n,),
    extrapolating from the end pieces (NaN at NaN), as ``PPoly.__call__(x, nu)`` with
    ``extrapolate=True`` gives them."""
    n = x.shape[0]
    m = breaks.shape[0] - 1
    out = np.empty((3, n))
    for j in range(n):
        xv = x[j]
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
