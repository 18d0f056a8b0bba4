"""Kernels (numba) of the seeder's inverse design (seed 000, sections 3.2-3.3) and of its
layer-1 geometry.

- ``dense_carrier``: the carrier direction on the dense parameter grid for both assembly
  branches (Eq. 2-3), unwrapped as ``np.unwrap`` does;
- ``invert_carrier``: the tip at uniform carrier angle by the Illinois method, every
  sample stepping together until all carrier angle errors are below 1e-10 rad;
- ``refine_extremes`` / ``refine_crossings``: the Newton refinements of the extreme
  radii (``seeder_inverse_batch.extreme_radii``) and of the "8"'s self-crossing
  (``objectives.seeder_inverse_population.loop_spans``), for one design or a population.

The spline is evaluated on its own cubic pieces in the kernels (SciPy's coefficients
and arithmetic for ``ClosedTrajectory``, ``TrajectoryBatch``'s for a population); the
two arctan2 of Eq. 2-3 are NumPy's vectorized ones, several times faster per element
than a scalar libm call inside a kernel. The same model and arithmetic, step for step,
as the NumPy paths, which stay as the reference (tests/test_seeder_inverse_kernel.py:
the bundled seeder examples give identical numbers). Imported lazily: numba stays out
of the CLI's start-up; its compilation is cached on disk (``cache=True``).

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
def spline_polar(coef, knots, period, u, L1, L2):
    """At parameters u (n,): the tip x, y (mm) on the periodic cubic spline (SciPy's
    coefficients ``coef`` (4, N, 2), highest power first, evaluated as SciPy does), and
    the two arguments (sin, cos) of the angle beta_1 at O between the carrier and the
    tip (Eq. 2-3): the formulas of ``seeder_inverse._carrier_geometry`` up to its
    arctan2 calls, which ``tip_angles`` makes with NumPy's vectorized arctan2 (several
    times faster per element than a scalar libm call in a kernel)."""
    n = u.shape[0]
    x, y = np.empty(n), np.empty(n)
    sin_b1, cos_b1 = np.empty(n), np.empty(n)
    for j in range(n):
        w = _mod(u[j], period)  # np.mod's own rule (exact), then SciPy's power sum
        i = _piece(knots, w)
        t = w - knots[i]
        t2 = t * t
        t3 = t2 * t
        xj = coef[3, i, 0] + coef[2, i, 0] * t + coef[1, i, 0] * t2 + coef[0, i, 0] * t3
        yj = coef[3, i, 1] + coef[2, i, 1] * t + coef[1, i, 1] * t2 + coef[0, i, 1] * t3
        rho = np.hypot(xj, yj)
        c = min(1.0, max(-1.0, (L1 * L1 + rho * rho - L2 * L2) / (2.0 * L1 * rho)))
        x[j], y[j] = xj, yj
        sin_b1[j] = np.sqrt(max(1.0 - c * c, 0.0))
        cos_b1[j] = c
    return x, y, sin_b1, cos_b1


def tip_angles(coef, knots, period, u, L1, L2):
    """(beta_3, beta_1, x, y) at parameters u: ``spline_polar`` and two arctan2."""
    x, y, sin_b1, cos_b1 = spline_polar(coef, knots, period, u, L1, L2)
    return np.arctan2(y, x), np.arctan2(sin_b1, cos_b1), x, y


@njit(cache=True, error_model="numpy")
def _branches(u, beta3, beta1, u_min, u_max, period):
    """phi_1 (2, m + 1) for sigma_inner = +1, -1, each unwrapped as ``np.unwrap`` does
    (jumps of at least pi replaced by their 2 pi complement, corrections summed)."""
    m1 = u.shape[0]
    inner_len = _mod(u_max - u_min, period)
    out = np.empty((2, m1))
    for k in range(m1):
        s = 1.0 if _on_inner(u[k], u_min, inner_len, period) else -1.0
        out[0, k] = beta3[k] + s * beta1[k]
        out[1, k] = beta3[k] + (-s) * beta1[k]
    for row in range(2):
        p = out[row]
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


def dense_carrier(coef, knots, period, u_dense, L1, L2, u_min, u_max):
    """Unwrapped carrier angle phi_1 (2, m + 1) on the dense grid ``u_dense`` for the
    assembly branches sigma_inner = +1 (row 0) and -1 (row 1): phi_1 = beta_3 +
    sigma beta_1, sigma = sigma_inner on the arc from u_min to u_max, else -sigma_inner."""
    beta3, beta1, _, _ = tip_angles(coef, knots, period, u_dense, L1, L2)
    return _branches(u_dense, beta3, beta1, u_min, u_max, period)


@njit(cache=True, error_model="numpy")
def _illinois_start(psi, u_dense, psi_dense):
    """Brackets of the Illinois method: the dense-grid interval k (n,) holding each psi
    (psi_dense[k] <= psi < psi_dense[k + 1], clipped to the grid; psi increasing)."""
    n = psi.shape[0]
    m = u_dense.shape[0] - 1
    ks = np.empty(n, np.int64)
    k = 0
    for j in range(n):
        while k < m and psi_dense[k + 1] <= psi[j]:
            k += 1
        ks[j] = min(k, m - 1)
    return ks


@njit(cache=True, error_model="numpy")
def _illinois_trial(lo, hi, f_lo, f_hi, u):
    """The regula falsi point of each bracket (bisection where the values do not
    bracket), written into u."""
    for j in range(u.shape[0]):
        den = f_hi[j] - f_lo[j]
        if den > 0:
            u[j] = lo[j] - f_lo[j] * (hi[j] - lo[j]) / den
        else:
            u[j] = 0.5 * (lo[j] + hi[j])


@njit(cache=True, error_model="numpy")
def _illinois_update(u, beta3, beta1, u_min, inner_len, period, sigma_inner, phi0, phi_k,
                     psi, lo, hi, f_lo, f_hi, side):
    """One Illinois step from the carrier angle at the trial points: the carrier angle
    error f (rad), the bracket kept on its sign change, the value kept on the side that
    stayed twice in a row halved. Returns the largest |f|."""
    worst = 0.0
    for j in range(u.shape[0]):
        s = sigma_inner if _on_inner(u[j], u_min, inner_len, period) else -sigma_inner
        d = (beta3[j] + s * beta1[j]) - phi_k[j]
        f = phi0 - (phi_k[j] + (d - TWO_PI * np.round(d / TWO_PI))) - psi[j]
        if f > 0:
            hi[j] = u[j]
            if side[j] > 0:
                f_lo[j] = 0.5 * f_lo[j]
            f_hi[j] = f
            side[j] = 1.0
        else:
            lo[j] = u[j]
            f_lo[j] = f
            if side[j] < 0:
                f_hi[j] = 0.5 * f_hi[j]
            side[j] = -1.0
        worst = max(worst, abs(f))
    return worst


def invert_carrier(psi, u_dense, phi_dense, psi_dense, coef, knots, period, L1, L2, u_min,
                   u_max, sigma_inner):
    """Curve parameter u (n,) where the carrier has turned ``psi`` (n, increasing)
    clockwise, by the Illinois method (modified regula falsi) on the bracket of the dense
    grid that holds each psi; all samples step together until every carrier angle error
    is below 1e-10 rad (at most 30 iterations), as ``seeder_inverse.invert_carrier``
    does. Also the carrier angle phi_1 unwrapped by the dense grid and the tip (n, 2).
    The bookkeeping runs in kernels, the angles in NumPy (``tip_angles``)."""
    k = _illinois_start(psi, u_dense, psi_dense)
    lo, hi = u_dense[k], u_dense[k + 1]
    f_lo, f_hi = psi_dense[k] - psi, psi_dense[k + 1] - psi
    phi_k = phi_dense[k]
    side = np.zeros(len(psi))
    u = lo.copy()
    inner_len = float(np.mod(u_max - u_min, period))
    for _ in range(ILLINOIS_ITERATIONS):
        _illinois_trial(lo, hi, f_lo, f_hi, u)
        beta3, beta1, _, _ = tip_angles(coef, knots, period, u, L1, L2)
        worst = _illinois_update(u, beta3, beta1, u_min, inner_len, period, sigma_inner,
                                 phi_dense[0], phi_k, psi, lo, hi, f_lo, f_hi, side)
        if worst < 1e-10:  # rad of carrier angle (round-off floor ~4e-11)
            break
    beta3, beta1, x, y = tip_angles(coef, knots, period, u, L1, L2)
    on_inner = np.mod(u - u_min, period) < inner_len
    phi = beta3 + np.where(on_inner, sigma_inner, -sigma_inner) * beta1
    d = phi - phi_k
    return u, phi_k + (d - TWO_PI * np.round(d / TWO_PI)), np.c_[x, y]


@njit(cache=True, error_model="numpy")
def _point_and_derivatives(coef, knots, period, u):
    """(x, y, x', y', x'', y'') of one row of a ``TrajectoryBatch`` at parameter u: its
    coefficients ``coef`` (N, 4, 2) (lowest power first), knots (N + 1), evaluated as
    ``TrajectoryBatch`` evaluates them (u wrapped by floor, Horner's rule)."""
    n = coef.shape[0]
    w = u - period * np.floor(u / period)
    i = _piece(knots, w)
    if i > n - 1:
        i = n - 1
    t = w - knots[i]
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
    extremes (P, c) of the distance to O (``seeder_inverse_batch.extreme_radii``): the
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
