"""Kernels (numba) of the seeder's inverse design (seed 000, sections 3.2-3.3) and of its
layer-1 geometry, for P designs at once (one design is P = 1).

- ``dense_carrier``: the carrier direction on each design's dense parameter grid for both
  assembly branches (Eq. 2-3), unwrapped as ``np.unwrap`` does;
- ``invert_carrier``: the tip at uniform carrier angle by the Illinois method, every
  sample of every design stepping together until all carrier angle errors are below
  1e-10 rad;
- ``refine_extremes`` / ``refine_crossings``: the Newton refinements of the extreme
  radii (``seeder_inverse.extreme_radii``) and of the "8"'s self-crossing
  (``objectives.seeder_inverse_population.loop_spans``), for one design or a population.

The spline is evaluated on its own cubic pieces in the kernels (``TrajectoryBatch``'s
coefficients and arithmetic); the two arctan2 of Eq. 2-3 are NumPy's vectorized ones,
several times faster per element than a scalar libm call inside a kernel. The same model
and arithmetic, step for step, as the NumPy path of ``seeder_inverse`` (``fused=False``,
also the path of curve objects without spline coefficients), which stays as the reference
(tests/test_seeder_inverse_kernel.py: the bundled seeder examples give the same numbers).
Imported lazily: numba stays out of the CLI's start-up; its compilation is cached on disk
(``cache=True``).

Lengths mm, parameter u in mm of chord, angles rad (conventions of ``seeder_inverse``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

TWO_PI = 2.0 * np.pi
ILLINOIS_ITERATIONS = 30


@njit(cache=True, error_model="numpy")
def _piece(knots, u):
    """Index i of the cubic piece with knots[i] <= u < knots[i + 1] (clipped to the
    pieces), as SciPy's PPoly finds it; u already wrapped into the period."""
    n = knots.shape[0] - 1
    lo, hi = 0, n
    while hi - lo > 1:  # knots[lo] <= u < knots[hi]
        mid = (lo + hi) >> 1
        if u >= knots[mid]:
            lo = mid
        else:
            hi = mid
    return lo


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
def _on_inner(u, u_min, inner_len, period):
    """Whether u lies on the arc of length ``inner_len`` from u_min (traversal order)."""
    return _mod(u - u_min, period) < inner_len


@njit(cache=True, error_model="numpy")
def _interval(knots, period, u):
    """(i, t): the cubic piece i of a ``TrajectoryBatch`` row holding parameter u (mm of
    chord) and the offset t = u - knots[i] (mm) into it, as ``TrajectoryBatch`` finds them:
    u wrapped into the period by floor, the piece clipped to the last (N pieces, knots
    (N + 1))."""
    n = knots.shape[0] - 1
    w = u - period * np.floor(u / period)
    i = _piece(knots, w)
    if i > n - 1:
        i = n - 1
    return i, w - knots[i]


@njit(cache=True, error_model="numpy")
def _point(coef, knots, period, u):
    """(x, y) of one row of a ``TrajectoryBatch`` at parameter u: its coefficients ``coef``
    (N, 4, 2) (lowest power first), knots (N + 1), evaluated as ``TrajectoryBatch``
    evaluates them (``_interval``, Horner's rule)."""
    i, t = _interval(knots, period, u)
    x = coef[i, 0, 0] + t * (coef[i, 1, 0] + t * (coef[i, 2, 0] + t * coef[i, 3, 0]))
    y = coef[i, 0, 1] + t * (coef[i, 1, 1] + t * (coef[i, 2, 1] + t * coef[i, 3, 1]))
    return x, y


@njit(cache=True, error_model="numpy")
def spline_polar(coef, knots, period, u, L1, L2, alive):
    """At parameters u (P, n) of the rows of a ``TrajectoryBatch`` (``coef`` (P, N, 4, 2),
    ``knots`` (P, N + 1), ``period`` (P,)): the tip x, y (mm) and the two arguments (sin,
    cos) of the angle beta_1 at O between the carrier of length L1 (P,) and the tip for an
    arm L2 (P,) (Eq. 2-3), each (P, n): the formulas of ``seeder_inverse._carrier_geometry``
    up to its arctan2 calls, which ``tip_angles`` makes with NumPy's vectorized arctan2
    (several times faster per element than a scalar libm call in a kernel). Rows not
    ``alive`` are left at 0."""
    P, n = u.shape
    x, y = np.zeros((P, n)), np.zeros((P, n))
    sin_b1, cos_b1 = np.zeros((P, n)), np.ones((P, n))
    for p in range(P):
        if not alive[p]:
            continue
        a, b = L1[p], L2[p]
        for j in range(n):
            xj, yj = _point(coef[p], knots[p], period[p], u[p, j])
            rho = np.hypot(xj, yj)
            c = min(1.0, max(-1.0, (a * a + rho * rho - b * b) / (2.0 * a * rho)))
            x[p, j], y[p, j] = xj, yj
            sin_b1[p, j] = np.sqrt(max(1.0 - c * c, 0.0))
            cos_b1[p, j] = c
    return x, y, sin_b1, cos_b1


def tip_angles(coef, knots, period, u, L1, L2, alive):
    """(beta_3, beta_1, x, y), each (P, n), at parameters u (P, n): ``spline_polar`` and
    two arctan2."""
    x, y, sin_b1, cos_b1 = spline_polar(coef, knots, period, u, L1, L2, alive)
    return np.arctan2(y, x), np.arctan2(sin_b1, cos_b1), x, y


@njit(cache=True, error_model="numpy")
def _branches(u, beta3, beta1, u_min, u_max, period):
    """phi_1 (2, P, m + 1) for sigma_inner = +1, -1, each row unwrapped as ``np.unwrap``
    does (jumps of at least pi replaced by their 2 pi complement, corrections summed)."""
    P, m1 = u.shape
    out = np.empty((2, P, m1))
    for q in range(P):
        inner_len = _mod(u_max[q] - u_min[q], period[q])
        for k in range(m1):
            s = 1.0 if _on_inner(u[q, k], u_min[q], inner_len, period[q]) else -1.0
            out[0, q, k] = beta3[q, k] + s * beta1[q, k]
            out[1, q, k] = beta3[q, k] + (-s) * beta1[q, k]
        for row in range(2):
            p = out[row, q]
            corr = 0.0
            prev = p[0]
            for k in range(1, m1):
                d = p[k] - prev
                prev = p[k]
                if abs(d) >= np.pi:
                    dm = np.fmod(d + np.pi, TWO_PI)
                    if dm < 0.0:
                        dm += TWO_PI
                    dm -= np.pi
                    if dm == -np.pi and d > 0:
                        dm = np.pi
                    corr += dm - d
                p[k] += corr
    return out


def dense_carrier(coef, knots, period, u_dense, L1, L2, u_min, u_max, alive):
    """Unwrapped carrier angle phi_1 (2, P, m + 1) on the dense grids ``u_dense`` (P, m + 1)
    for the assembly branches sigma_inner = +1 (first) and -1 (second): phi_1 = beta_3 +
    sigma beta_1, sigma = sigma_inner on the arc from u_min to u_max, else -sigma_inner."""
    beta3, beta1, _, _ = tip_angles(coef, knots, period, u_dense, L1, L2, alive)
    return _branches(u_dense, beta3, beta1, u_min, u_max, period)


@njit(cache=True, error_model="numpy")
def _illinois_start(psi, psi_dense):
    """Brackets of the Illinois method: the dense-grid interval k (P, n) holding each psi
    (psi_dense[p, k] <= psi < psi_dense[p, k + 1], clipped to the grid; psi increasing)."""
    n = psi.shape[0]
    P, m1 = psi_dense.shape
    m = m1 - 1
    ks = np.empty((P, n), np.int64)
    for p in range(P):
        k = 0
        for j in range(n):
            while k < m and psi_dense[p, k + 1] <= psi[j]:
                k += 1
            ks[p, j] = min(k, m - 1)
    return ks


@njit(cache=True, error_model="numpy")
def _illinois_trial(lo, hi, f_lo, f_hi, u):
    """The regula falsi point of each bracket (bisection where the values do not
    bracket), written into u (P, n)."""
    P, n = u.shape
    for p in range(P):
        for j in range(n):
            den = f_hi[p, j] - f_lo[p, j]
            if den > 0:
                u[p, j] = lo[p, j] - f_lo[p, j] * (hi[p, j] - lo[p, j]) / den
            else:
                u[p, j] = 0.5 * (lo[p, j] + hi[p, j])


@njit(cache=True, error_model="numpy")
def _illinois_update(u, beta3, beta1, u_min, inner_len, period, sigma_inner, phi0, phi_k,
                     psi, lo, hi, f_lo, f_hi, side, alive):
    """One Illinois step from the carrier angle at the trial points: the carrier angle
    error f (rad), the bracket kept on its sign change, the value kept on the side that
    stayed twice in a row halved. Returns the largest |f| of the ``alive`` rows."""
    P, n = u.shape
    worst = 0.0
    for p in range(P):
        for j in range(n):
            s = sigma_inner[p] if _on_inner(u[p, j], u_min[p], inner_len[p], period[p]) \
                else -sigma_inner[p]
            d = (beta3[p, j] + s * beta1[p, j]) - phi_k[p, j]
            f = phi0[p] - (phi_k[p, j] + (d - TWO_PI * np.round(d / TWO_PI))) - psi[j]
            if f > 0:
                hi[p, j] = u[p, j]
                if side[p, j] > 0:
                    f_lo[p, j] = 0.5 * f_lo[p, j]
                f_hi[p, j] = f
                side[p, j] = 1.0
            else:
                lo[p, j] = u[p, j]
                f_lo[p, j] = f
                if side[p, j] < 0:
                    f_hi[p, j] = 0.5 * f_hi[p, j]
                side[p, j] = -1.0
            if alive[p]:
                worst = max(worst, abs(f))
    return worst


def invert_carrier(psi, u_dense, phi_dense, psi_dense, coef, knots, period, L1, L2, u_min,
                   u_max, sigma_inner, alive):
    """Curve parameters u (P, n) where the carrier of each row has turned ``psi`` (n,
    increasing) clockwise, by the Illinois method (modified regula falsi) on the bracket of
    the dense grid (P, m + 1) that holds each psi; all samples step together until every
    carrier angle error of the ``alive`` rows is below 1e-10 rad (at most 30 iterations),
    as ``seeder_inverse.invert_carrier`` does. Also the carrier angle phi_1 unwrapped by
    the dense grid and the tip (P, n, 2). The bookkeeping runs in kernels, the angles in
    NumPy (``tip_angles``)."""
    k = _illinois_start(psi, psi_dense)
    rows = np.arange(len(k))[:, None]
    lo, hi = u_dense[rows, k], u_dense[rows, k + 1]
    f_lo, f_hi = psi_dense[rows, k] - psi, psi_dense[rows, k + 1] - psi
    phi_k = phi_dense[rows, k]
    side = np.zeros(k.shape)
    u = lo.copy()
    inner_len = np.mod(u_max - u_min, period)
    phi0 = np.ascontiguousarray(phi_dense[:, 0])
    for _ in range(ILLINOIS_ITERATIONS):
        _illinois_trial(lo, hi, f_lo, f_hi, u)
        beta3, beta1, _, _ = tip_angles(coef, knots, period, u, L1, L2, alive)
        worst = _illinois_update(u, beta3, beta1, u_min, inner_len, period, sigma_inner,
                                 phi0, phi_k, psi, lo, hi, f_lo, f_hi, side, alive)
        if worst < 1e-10:  # rad of carrier angle (round-off floor ~4e-11)
            break
    beta3, beta1, x, y = tip_angles(coef, knots, period, u, L1, L2, alive)
    on_inner = np.mod(u - u_min[:, None], period[:, None]) < inner_len[:, None]
    phi = beta3 + np.where(on_inner, sigma_inner[:, None], -sigma_inner[:, None]) * beta1
    d = phi - phi_k
    return u, phi_k + (d - TWO_PI * np.round(d / TWO_PI)), np.stack([x, y], axis=-1)


@njit(cache=True, error_model="numpy")
def _point_and_derivatives(coef, knots, period, u):
    """(x, y, x', y', x'', y'') of one row of a ``TrajectoryBatch`` at parameter u: its
    coefficients ``coef`` (N, 4, 2) (lowest power first), knots (N + 1), evaluated as
    ``TrajectoryBatch`` evaluates them (``_interval``, Horner's rule)."""
    i, t = _interval(knots, period, u)
    out = np.empty(6)
    for a in range(2):
        c0, c1, c2, c3 = coef[i, 0, a], coef[i, 1, a], coef[i, 2, a], coef[i, 3, a]
        out[a] = c0 + t * (c1 + t * (c2 + t * c3))
        out[2 + a] = c1 + t * (2.0 * c2 + 3.0 * t * c3)
        out[4 + a] = 2.0 * c2 + 6.0 * t * c3
    return out


@njit(cache=True, error_model="numpy")
def refine_extremes(coef, knots, period, lo, hi, x, done, largest):
    """Safeguarded Newton on d(rho^2)/du / 2 = p . p' = 0 for each row's candidate
    extremes (P, c) of the distance to O (``seeder_inverse.extreme_radii``): the
    bracket [lo, hi] kept on the side where the slope changes sign (+ to - through a
    maximum when ``largest``, - to + through a minimum), a step leaving it replaced by
    bisection, until the step or the bracket is below 1e-9 mm of parameter (40 steps at
    most). ``done`` candidates keep their x. Returns x refined (P, c)."""
    P, c = x.shape
    out = x.copy()
    for p in range(P):
        for q in range(c):
            if done[p, q]:
                continue
            a, b, xq = lo[p, q], hi[p, q], x[p, q]
            for _ in range(40):
                v = _point_and_derivatives(coef[p], knots[p], period[p], xq)
                f = v[0] * v[2] + v[1] * v[3]
                fp = (v[2] * v[2] + v[3] * v[3]) + (v[0] * v[4] + v[1] * v[5])
                rising = f > 0 if largest else f < 0
                if rising:
                    a = xq
                else:
                    b = xq
                step = f / fp
                nx = xq - step
                if not (np.isfinite(nx) and nx >= a and nx <= b):
                    nx = 0.5 * (a + b)
                xq = nx
                if abs(step) < 1e-9 or b - a < 1e-9:
                    break
            out[p, q] = xq
    return out


@njit(cache=True, error_model="numpy")
def refine_crossings(coef, knots, period, ui, uj, one):
    """Newton's method on traj(u_i) = traj(u_j) for each row's self-crossing (P,) of a
    ``TrajectoryBatch`` (``objectives.seeder_inverse_population.loop_spans``), every row
    stepping until the steps of the rows that cross once (``one``) are all below 1e-12
    mm (20 steps at most); a row whose Jacobian turns singular (a tangential crossing)
    stops moving. Returns (u_i, u_j, stuck) (P,)."""
    P = ui.shape[0]
    ui, uj = ui.copy(), uj.copy()
    stuck = np.zeros(P, np.bool_)
    for _ in range(20):
        settled = True
        for p in range(P):
            vi = _point_and_derivatives(coef[p], knots[p], period[p], ui[p])
            vj = _point_and_derivatives(coef[p], knots[p], period[p], uj[p])
            f0, f1 = vi[0] - vj[0], vi[1] - vj[1]
            a, b, c, d = vi[2], -vj[2], vi[3], -vj[3]
            det = a * d - b * c
            if det == 0.0:
                stuck[p] = True
                det = 1.0
            s0 = (d * f0 - b * f1) / det
            s1 = (a * f1 - c * f0) / det
            if not stuck[p]:
                ui[p] -= s0
                uj[p] -= s1
                if one[p] and not (max(abs(s0), abs(s1)) < 1e-12):
                    settled = False
        if settled:
            break
    return ui, uj, stuck
