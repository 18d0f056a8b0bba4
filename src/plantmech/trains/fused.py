"""Fused population passes (numba) of the general train model: one loop per design where
the NumPy path makes a dozen passes over (P, N) temporaries.

- ``pair_extremes``: every quantity the pitch-curve manufacturability rules read of one
  pair (``trains.gearing.pair_shapes`` + ``gears.manufacturability.assess_pair``), reduced
  per design in one pass over the driver's grid: both gears' smallest convex and concave
  radius of curvature, smallest pitch radius and perimeter, each with where it is; the
  largest contact angle |mu|; a ring pair's smallest internal difference. The per-point
  arithmetic is the NumPy path's, term by term (``geometry.curvature_kernels``); the
  minima and their first places are therefore the same numbers, the perimeters a sum in
  another order (1e-15 relative) (tests/test_trains_fused.py).
- ``crossings``: the proper self-crossings of closed polylines
  (``objectives.planetary.self_crossings``): per design its segments sorted by their
  smallest x and swept (a crossing pair overlaps in x), then the exact orientation test
  of the NumPy version: the same counts.

Imported lazily, for populations of at least ``curves.KERNEL_POINTS`` grid points only:
numba stays out of the CLI's start-up and of single designs; compilation cached on disk.
Radii mm, angles rad.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: columns of ``pair_extremes``' value table
(CONVEX_D, CONCAVE_D, RADIUS_D, PERIMETER_D, CONVEX_F, CONCAVE_F, RADIUS_F, PERIMETER_F,
 MU_RATIO, DIFFERENCE, PHI_CONVEX_F, PHI_CONCAVE_F, PHI_RADIUS_F) = range(13)
#: columns of its index table (the first grid index of each extreme)
(AT_CONVEX_D, AT_CONCAVE_D, AT_RADIUS_D, AT_CONVEX_F, AT_CONCAVE_F, AT_RADIUS_F, AT_MU,
 AT_DIFFERENCE) = range(8)


@njit(cache=True, error_model="numpy", inline="always")
def _curvature(r, d, dd, f, ff, plain):
    """``geometry.curvature_kernels.polar_curvature_rows`` at one point."""
    num = r * r
    if plain:
        num = num + d * 2.0 * d
        num = num - r * dd
        speed2 = r * r + d * d
    else:
        num = num * (f * f * f)
        num = num + d * 2.0 * d * f
        num = num - r * dd * f
        num = num + r * d * ff
        speed2 = r * r * (f * f) + d * d
    speed = np.sqrt(speed2)
    cube = speed * speed * speed
    return np.inf if num == 0 else cube / num


@njit(cache=True, error_model="numpy")
def pair_extremes(r, r1, r2, a, kappa, c, ring_d, ring_f, t0, h):
    """(values (P, 13), indices (P, 8)) of P pairs from the driver's tables r, r', r''
    (P, N) on the grid t_i = i h and the centre distances ``a`` (P,): the driver's and
    the follower's (rho = kappa r + c a at body-angle rate phi' = r / rho, phi'' = c a r'
    / rho^2) smallest convex and concave radius of curvature on the material side (signs
    flipped for a ring: ``ring_d``, ``ring_f``), smallest pitch radius, perimeter sum
    (times h: the perimeter), the largest |r'| / r (tan mu) and the smallest internal
    difference 2 (-rho_ring - rho_planet) where the ring wraps the planet (inf: none);
    the follower's body angle phi = t0 + h (sum of phi' up to i) - h phi'_i at its
    extremes. Indices: the first grid index of each extreme (0 where none, as argmin of
    an all-inf row)."""
    P, N = r.shape
    vals = np.empty((P, 13))
    idx = np.zeros((P, 8), dtype=np.int64)
    inf = np.inf
    for p in range(P):
        ca = c * a[p]
        cvx_d = ccv_d = rad_d = cvx_f = ccv_f = rad_f = diff = inf
        i_cvx_d = i_ccv_d = i_rad_d = i_cvx_f = i_ccv_f = i_rad_f = i_mu = i_diff = 0
        per_d = per_f = 0.0
        mu = -inf
        cum = 0.0
        phi_cvx = phi_ccv = phi_rad = 0.0
        for i in range(N):
            rr, d, dd = r[p, i], r1[p, i], r2[p, i]
            rho = kappa * rr + ca
            f = rr / rho
            ff = ca * d / (rho * rho)
            kd, kdd = kappa * d, kappa * dd
            cd = _curvature(rr, d, dd, 1.0, 0.0, True)
            cf = _curvature(rho, kd, kdd, f, ff, False)
            if ring_d:
                cd = -cd
            if ring_f:
                cf = -cf
            cum += f
            phi = t0 + cum * h - f * h
            if i == 0:  # an extreme never found is at index 0, as argmin of an inf row
                phi_cvx = phi_ccv = phi_rad = phi
            if cd > 0 and cd < cvx_d:
                cvx_d, i_cvx_d = cd, i
            if cd < 0 and -cd < ccv_d:
                ccv_d, i_ccv_d = -cd, i
            if rr < rad_d:
                rad_d, i_rad_d = rr, i
            if cf > 0 and cf < cvx_f:
                cvx_f, i_cvx_f, phi_cvx = cf, i, phi
            if cf < 0 and -cf < ccv_f:
                ccv_f, i_ccv_f, phi_ccv = -cf, i, phi
            if rho < rad_f:
                rad_f, i_rad_f, phi_rad = rho, i, phi
            per_d += np.sqrt(d * d + rr * rr)
            rf = rho * f
            per_f += np.sqrt(kd * kd + rf * rf)
            m = abs(d) / rr
            if m > mu:
                mu, i_mu = m, i
            if ring_d or ring_f:
                ring, planet = (cd, cf) if ring_d else (cf, cd)
                gap = 2 * (-ring - planet) if ring < 0 else inf
                if gap < diff:
                    diff, i_diff = gap, i
        vals[p, CONVEX_D], vals[p, CONCAVE_D], vals[p, RADIUS_D] = cvx_d, ccv_d, rad_d
        vals[p, PERIMETER_D], vals[p, PERIMETER_F] = per_d * h, per_f * h
        vals[p, CONVEX_F], vals[p, CONCAVE_F], vals[p, RADIUS_F] = cvx_f, ccv_f, rad_f
        vals[p, MU_RATIO], vals[p, DIFFERENCE] = mu, diff
        vals[p, PHI_CONVEX_F], vals[p, PHI_CONCAVE_F], vals[p, PHI_RADIUS_F] = (
            phi_cvx, phi_ccv, phi_rad)
        idx[p, AT_CONVEX_D], idx[p, AT_CONCAVE_D], idx[p, AT_RADIUS_D] = (
            i_cvx_d, i_ccv_d, i_rad_d)
        idx[p, AT_CONVEX_F], idx[p, AT_CONCAVE_F], idx[p, AT_RADIUS_F] = (
            i_cvx_f, i_ccv_f, i_rad_f)
        idx[p, AT_MU], idx[p, AT_DIFFERENCE] = i_mu, i_diff
    return vals, idx


@njit(cache=True, error_model="numpy")
def crossings(ax, ay):
    """Proper crossings (P,) of each closed polyline through the points (ax, ay) (P, n):
    ``objectives.planetary.self_crossings``' count (its docstring), per design by a sweep
    over the segments sorted by their smallest x."""
    P, n = ax.shape
    out = np.zeros(P, dtype=np.int64)
    xlo = np.empty(n)
    xhi = np.empty(n)
    for p in range(P):
        for i in range(n):
            j = i + 1 if i + 1 < n else 0
            xlo[i] = min(ax[p, i], ax[p, j])
            xhi[i] = max(ax[p, i], ax[p, j])
        order = np.argsort(xlo, kind="mergesort")
        count = 0
        for u in range(n):
            i = order[u]
            i1 = i + 1 if i + 1 < n else 0
            yilo, yihi = min(ay[p, i], ay[p, i1]), max(ay[p, i], ay[p, i1])
            dxi, dyi = ax[p, i1] - ax[p, i], ay[p, i1] - ay[p, i]
            for v in range(u + 1, n):
                j = order[v]
                if xlo[j] > xhi[i]:
                    break
                gap = abs(i - j)
                if gap <= 1 or gap >= n - 1:
                    continue
                j1 = j + 1 if j + 1 < n else 0
                if yilo > max(ay[p, j], ay[p, j1]) or min(ay[p, j], ay[p, j1]) > yihi:
                    continue
                dxj, dyj = ax[p, j1] - ax[p, j], ay[p, j1] - ay[p, j]
                s1 = dxj * (ay[p, i] - ay[p, j]) - dyj * (ax[p, i] - ax[p, j])
                s2 = dxj * (ay[p, i1] - ay[p, j]) - dyj * (ax[p, i1] - ax[p, j])
                s3 = dxi * (ay[p, j] - ay[p, i]) - dyi * (ax[p, j] - ax[p, i])
                s4 = dxi * (ay[p, j1] - ay[p, i]) - dyi * (ax[p, j1] - ax[p, i])
                if s1 * s2 < 0 and s3 * s4 < 0:
                    count += 1
        out[p] = count
    return out
