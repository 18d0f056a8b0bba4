"""Kernel (numba) of ``periodic.polar_curvature_radius`` for large (P, N) tables (a
population's pitch curves in the manufacturability rules): one pass per point instead of
NumPy's dozen passes over (P, N) buffers, with the NumPy version's products in the same
order (no fast-math: no reassociation, no fused multiply-add), so the values are the same
to the last bit (tests/test_periodic.py). Imported lazily, above
``periodic.CURVATURE_KERNEL_POINTS`` points only: numba stays out of the CLI's start-up
and of single designs; the compilation is cached on disk (``cache=True``). Radii mm,
angles rad.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy", nogil=True)
def polar_curvature_rows(rho, drho, ddrho, dphi, ddphi, plain):
    """Signed radius of curvature (P, N) of polar curves from (P, N) tables of rho, rho',
    rho'' and phi', phi'' (``plain``: phi' = 1, phi'' = 0, the tables not read):
    ``periodic.polar_curvature_radius``'s formula and order of operations."""
    P, N = rho.shape
    out = np.empty((P, N))
    for p in range(P):
        for i in range(N):
            r, d, dd = rho[p, i], drho[p, i], ddrho[p, i]
            num = r * r
            if plain:
                num = num + d * 2.0 * d
                num = num - r * dd
                speed2 = r * r + d * d
            else:
                f, ff = dphi[p, i], ddphi[p, i]
                num = num * (f * f * f)
                num = num + d * 2.0 * d * f
                num = num - r * dd * f
                num = num + r * d * ff
                speed2 = r * r * (f * f) + d * d
            speed = np.sqrt(speed2)
            cube = speed * speed * speed
            out[p, i] = np.inf if num == 0 else cube / num
    return out
