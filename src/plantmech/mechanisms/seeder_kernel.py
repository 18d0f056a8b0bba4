"""The fused per-design kernel of the seeder's population forward kinematics (numba).

One pass per design, no (P, dense) temporaries: the pitch radii of gears 2 and 3 along
``dense`` body-angle steps (the periodic piecewise-cubic interpolant through the node
radii and node slopes, seed 000 section 4.3), the centre distances that close each pair
(seed 000 Eq. 8, the Newton iteration of ``gears.closure.solve_centre_distances``), the
rolling integrals psi(psi_2) = int r2 / (a1 - r2) and psi_4(psi_2) = int r3 / (a2 - r3)
(the running integral of the cubic spline through the dense samples that SciPy's
``CubicSpline(...).antiderivative()`` gave: one tridiagonal sweep per design, no spline
objects), the inversion of psi(psi_2) at the carrier samples (a merge walk,
then Newton on the Hermite cubic of each interval), the tip (Eq. 12-16) and the angular
play. Imported only by ``seeder_batch.simulate_population``: numba stays out of the CLI's
start-up; its compilation is cached on disk (``cache=True``).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

TWO_PI = 2.0 * np.pi
# below this many designs the kernels run on one thread (starting the others costs more)
PARALLEL_MIN_DESIGNS = 64


@njit(cache=True, error_model="numpy", inline="always")
def _hermite_span(y0, y1, d0, d1, inv, xk, u0, h, j0, j1, value, slope):
    """``_along``'s cubic of one knot interval (x[k], values y0, y1, slopes times the width
    d0, d1, 1 / width ``inv``) at the body angles u0 + j h, j0 <= j < j1: a loop without
    branches (SIMD)."""
    dy = y0 - y1
    for j in range(j0, j1):
        t = (u0 + j * h - xk) * inv
        t2 = t * t
        t3 = t2 * t
        value[j] = y0 + (2 * t3 - 3 * t2) * dy + (t3 - 2 * t2 + t) * d0 + (t3 - t2) * d1
        slope[j] = ((6 * t2 - 6 * t) * dy + (3 * t2 - 4 * t + 1) * d0
                    + (3 * t2 - 2 * t) * d1) * inv


@njit(cache=True, error_model="numpy")
def _along(x, radii, slopes, n, c, h, D, value, slope):
    """Values (mm) and slopes (mm/rad) of the piecewise cubic Hermite over one turn through
    (x, radii) with node ``slopes`` (x, radii, slopes: n + 1 knots, the last x[0] + 2 pi;
    radii[n], slopes[n] the left limits there: radii[0], slopes[0] for a periodic curve,
    others at a break) at the body angles c + j h, j = 0..D (rad): one march through the
    knots, each interval's samples in one branch-free loop (a sample on a knot belongs to
    the interval it starts; the last angle, a turn after the first, takes the left limit
    at the end knot)."""
    u0 = c - x[0]
    u0 = x[0] + (u0 - TWO_PI * np.floor(u0 / TWO_PI))
    k = 0
    while k < n - 1 and x[k + 1] <= u0:
        k += 1
    j0 = 0
    while j0 < D:
        xk1 = x[k + 1]
        # j1: the first sample at or beyond the interval's end (at most D)
        j1 = int(np.ceil((xk1 - u0) / h))
        j1 = min(max(j1, j0), D)
        while j1 > j0 and u0 + (j1 - 1) * h >= xk1:
            j1 -= 1
        while j1 < D and u0 + j1 * h < xk1:
            j1 += 1
        hk = xk1 - x[k]
        _hermite_span(radii[k], radii[k + 1], slopes[k] * hk, slopes[k + 1] * hk, 1.0 / hk,
                      x[k], u0, h, j0, j1, value, slope)
        j0 = j1
        if j0 < D:
            k += 1
            if k == n:
                k = 0
                u0 -= TWO_PI
    # the closing angle: a turn after the first, the left limit at the end knot
    u = u0 + TWO_PI
    while u > x[k + 1] or (u == x[k + 1] and k + 1 < n):
        k += 1
        if k == n:
            k = 0
            u0 -= TWO_PI
            u -= TWO_PI
    hk = x[k + 1] - x[k]
    _hermite_span(radii[k], radii[k + 1], slopes[k] * hk, slopes[k + 1] * hk, 1.0 / hk,
                  x[k], u - D * h, h, D, D + 1, value, slope)


@njit(cache=True, error_model="numpy", fastmath={"reassoc", "nsz"})
def _turn_sums(r, D, a):
    """sum_k r_k / (a - r_k)^j for j = 1, 2, 3 over r[:D] (reassociated: SIMD)."""
    f = 0.0
    df = 0.0
    ddf = 0.0
    for j in range(D):
        q = 1.0 / (a - r[j])
        rq = r[j] * q
        f += rq
        df += rq * q
        ddf += rq * q * q
    return f, df, ddf


@njit(cache=True, error_model="numpy")
def _closing_centre_distance(r, D, turn):
    """a with mean_k r_k / (a - r_k) * 2 pi = turn over r[:D] (the root
    ``gears.closure.solve_centre_distances`` finds, to the same 1e-12 relative step):
    Halley's iteration (Newton's where Halley's correction is large) from a point left of
    the root, where the convex decreasing left side is positive. The circle's centre
    distance at the mean radius, rbar (1 + 2 pi / turn), is such a point (Jensen:
    mean r / (a - r) >= rbar / (a - rbar)) when it lies beyond max r; else the gap to
    max r is halved from 2 rbar until the side is positive."""
    rmax = r[0]
    tot = 0.0
    for j in range(D):
        tot += r[j]
        if r[j] > rmax:
            rmax = r[j]
    w = TWO_PI / D
    a = tot / D * (1.0 + TWO_PI / turn)
    if not a > rmax:
        a = 2.0 * tot / D
        for _ in range(60):
            if a > rmax:
                f, _df, _ddf = _turn_sums(r, D, a)
                if f * w - turn > 0:
                    break
            a = rmax + 0.5 * (a - rmax)
    for _ in range(100):
        f, df, ddf = _turn_sums(r, D, a)
        f = f * w - turn
        df = -df * w
        ddf = 2.0 * ddf * w
        step = -f / df
        den = 1.0 + 0.5 * step * ddf / df  # Halley: step / (1 - f f'' / (2 f'^2))
        if den > 0.5:
            step = step / den
        a = a + step
        if abs(step) <= 1e-12 * a:
            break
    return a


@njit(cache=True, error_model="numpy", fastmath={"contract"})
def _running_integrals(ya, yb, D, h, cp, piv, sa, sb, outa, outb):
    """Running integrals outa, outb [0..D] (from 0) of the not-a-knot cubic splines through
    the D + 1 samples ya, yb at uniform step h (the splines SciPy's ``CubicSpline(t, y)``
    builds, whose ``antiderivative()`` the population code used): node slopes s from the
    tridiagonal system s[i-1] + 4 s[i] + s[i+1] = 3 (q[i-1] + q[i]) (q the chord slopes),
    s[0] + 2 s[1] = (5 q[0] + q[1]) / 2 and 2 s[D-1] + s[D] = (q[D-2] + 5 q[D-1]) / 2 at
    the ends, by the Thomas sweep with the shared factors ``cp``, ``piv``
    (``spline_factors``); per interval h (y[i] + y[i+1]) / 2 + h^2 (s[i] - s[i+1]) / 12,
    whose running sum is the trapezoid's plus h^2 (s[0] - s[k]) / 12 (the slope terms
    telescope). Two rows at once: each sweep is a chain of dependent multiply-adds, two
    independent chains (and the trapezoid sums) side by side keep the core busy. sa, sb:
    scratch rows (D + 1)."""
    n = D + 1
    three_over_h = 3.0 / h
    half = 0.5 * h
    sa[0] = (0.5 * (5.0 * ((ya[1] - ya[0]) / h) + (ya[2] - ya[1]) / h)) * piv[0]
    sb[0] = (0.5 * (5.0 * ((yb[1] - yb[0]) / h) + (yb[2] - yb[1]) / h)) * piv[0]
    for i in range(1, n - 1):  # right-hand sides times the pivots (SIMD)
        sa[i] = ((ya[i] - ya[i - 1]) + (ya[i + 1] - ya[i])) * three_over_h * piv[i]
        sb[i] = ((yb[i] - yb[i - 1]) + (yb[i + 1] - yb[i])) * three_over_h * piv[i]
    outa[0] = outb[0] = 0.0
    # forward sweep s[i] -= piv[i] s[i-1] over 1..n-2 in two halves at once (four chains
    # of multiply-adds): the second half starts from zero and then takes the first half's
    # last slope, propagated by the product of -piv, until that product is below 1e-20
    # (piv -> 2 - sqrt 3: about 35 steps); the trapezoid sums likewise, the second half's
    # shifted by the first half's total
    half_n = (n - 2) // 2
    m = 1 + half_n  # the second half: m..n-2
    ta = tb = ua = ub = 0.0
    sa_prev = sa[0]
    sb_prev = sb[0]
    ua_prev = ub_prev = 0.0
    for k in range(half_n):
        i = 1 + k
        j = m + k
        sa_prev = sa[i] - sa_prev * piv[i]
        sb_prev = sb[i] - sb_prev * piv[i]
        ua_prev = sa[j] - ua_prev * piv[j]
        ub_prev = sb[j] - ub_prev * piv[j]
        sa[i] = sa_prev
        sb[i] = sb_prev
        sa[j] = ua_prev
        sb[j] = ub_prev
        ta += half * (ya[i - 1] + ya[i])
        tb += half * (yb[i - 1] + yb[i])
        ua += half * (ya[j - 1] + ya[j])
        ub += half * (yb[j - 1] + yb[j])
        outa[i] = ta
        outb[i] = tb
        outa[j] = ua
        outb[j] = ub
    for j in range(m + half_n, n - 1):  # the second half's extra sample (n - 2 odd)
        ua_prev = sa[j] - ua_prev * piv[j]
        ub_prev = sb[j] - ub_prev * piv[j]
        sa[j] = ua_prev
        sb[j] = ub_prev
        ua += half * (ya[j - 1] + ya[j])
        ub += half * (yb[j - 1] + yb[j])
        outa[j] = ua
        outb[j] = ub
    prod = 1.0
    for j in range(m, n - 1):
        prod = -prod * piv[j]
        sa[j] += prod * sa[m - 1]
        sb[j] += prod * sb[m - 1]
        if abs(prod) < 1e-20:
            break
    for j in range(m, n - 1):
        outa[j] += ta
        outb[j] += tb
    outa[n - 1] = outa[n - 2] + half * (ya[n - 2] + ya[n - 1])
    outb[n - 1] = outb[n - 2] + half * (yb[n - 2] + yb[n - 1])
    for y, s_ in ((ya, sa), (yb, sb)):
        qa = (y[n - 2] - y[n - 3]) / h
        qb = (y[n - 1] - y[n - 2]) / h
        s_[n - 1] = (0.5 * (qa + 5.0 * qb) - 2.0 * s_[n - 2]) * piv[n - 1]
    # backward sweep s[i] -= cp[i] s[i+1] over n-2..0 in two halves the same way: the
    # lower half (m-1..0) starts as if s[m] were zero, then takes s[m]'s propagation
    va = sa[n - 1]
    vb = sb[n - 1]
    wa = wb = 0.0
    for k in range(n - 1 - m):  # upper: n-2..m; lower: m-1..
        i = n - 2 - k
        va = sa[i] - cp[i] * va
        vb = sb[i] - cp[i] * vb
        sa[i] = va
        sb[i] = vb
        j = m - 1 - k
        if j >= 0:
            wa = sa[j] - cp[j] * wa
            wb = sb[j] - cp[j] * wb
            sa[j] = wa
            sb[j] = wb
    for j in range(m - 1 - (n - 1 - m), -1, -1):  # the lower half's rest (if longer)
        wa = sa[j] - cp[j] * wa
        wb = sb[j] - cp[j] * wb
        sa[j] = wa
        sb[j] = wb
    prod = 1.0
    for j in range(m - 1, -1, -1):
        prod = -prod * cp[j]
        sa[j] += prod * sa[m]
        sb[j] += prod * sb[m]
        if abs(prod) < 1e-20:
            break
    hh = h * h / 12.0
    s0a = sa[0]
    s0b = sb[0]
    for i in range(1, n):
        outa[i] += hh * (s0a - sa[i])
        outb[i] += hh * (s0b - sb[i])


def kernel_threads() -> int:
    """Threads the ``*_rows`` kernels may use: ``PLANTMECH_KERNEL_THREADS`` (a whole number
    >= 1, at most numba's ``NUMBA_NUM_THREADS``), 1 when unset. One by default: on this
    shared 2-core machine two threads measured slower in wall time than one (a thread that
    loses its core holds the others at the join; docs/architecture.md), and the optimizer's
    and Dask's worker processes already fill the cores."""
    import os

    raw = os.environ.get("PLANTMECH_KERNEL_THREADS", "1").strip() or "1"
    try:
        n = int(raw)
    except ValueError:
        n = 0
    if n < 1:
        raise ValueError(f"environment variable PLANTMECH_KERNEL_THREADS: {raw!r} is not a "
                         "whole number >= 1")
    if n == 1:
        return 1
    import numba

    return min(n, numba.config.NUMBA_NUM_THREADS)


def chunks_for(P: int) -> int:
    """Spans of designs the ``*_rows`` kernels split P designs into: one (a single thread)
    below ``PARALLEL_MIN_DESIGNS`` designs or with one kernel thread (``kernel_threads``),
    else four per thread (spans of unequal cost balance out), numba's thread count set to
    ``kernel_threads()``."""
    threads = kernel_threads()
    if P < PARALLEL_MIN_DESIGNS or threads == 1:
        return 1
    import numba

    numba.set_num_threads(threads)
    return min(P, 4 * threads)


def spline_factors(D: int):
    """Shared factors of the not-a-knot system of ``_running_integrals`` on D + 1 uniform
    samples: the Thomas sweep's modified super-diagonal ``cp`` and reciprocal pivots."""
    n = D + 1
    sub = np.ones(n)
    sub[-1] = 2.0
    diag = np.full(n, 4.0)
    diag[0] = diag[-1] = 1.0
    sup = np.ones(n)
    sup[0] = 2.0
    cp, piv = np.zeros(n), np.zeros(n)
    piv[0] = 1.0 / diag[0]
    cp[0] = sup[0] * piv[0]
    for i in range(1, n):
        piv[i] = 1.0 / (diag[i] - sub[i] * cp[i - 1])
        cp[i] = sup[i] * piv[i]
    return cp, piv


# pi / 2 in three parts of 33 significant bits (fdlibm's split: q times each is exact for
# |q| < 2^20) and the minimax polynomials of sin and cos on [-pi / 4, pi / 4] (fdlibm's
# __kernel_sin / __kernel_cos coefficients)
_PIO2_1 = 1.57079632673412561417e+00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_3 = 2.02226624871116645580e-21
_INV_PIO2 = 6.36619772367581382433e-01
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, \
    -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, \
    1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, \
    2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, \
    -1.13596475577881948265e-11


@njit(cache=True, error_model="numpy")
def sincos_rows(x, cos_out, sin_out, n):
    """cos and sin of the angles x[:n] (rad) in one branch-free loop (SIMD; libm's scalar
    calls were a quarter of the simulation): x = q pi / 2 + r with |r| <= pi / 4 (the
    three-part reduction, exact to 1e-16 rad for |x| < 1e5), the polynomials of sin r and
    cos r, and the quadrant q mod 4 swapping and negating them. Within 2.3e-16 of numpy's
    cos and sin (tests/test_seeder_kernel.py)."""
    for i in range(n):
        v = x[i]
        q = np.floor(v * _INV_PIO2 + 0.5)
        r = ((v - q * _PIO2_1) - q * _PIO2_2) - q * _PIO2_3
        z = r * r
        sn = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
        cs = 1.0 - 0.5 * z + z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (
            _C5 + z * _C6)))))
        m = q - 4.0 * np.floor(q * 0.25)
        odd = (m == 1.0) or (m == 3.0)
        a = cs if odd else sn
        b = sn if odd else cs
        sin_out[i] = -a if m >= 2.0 else a
        cos_out[i] = -b if (m == 1.0 or m == 2.0) else b


@njit(cache=True, error_model="numpy", inline="always")
def _hermite(y0, y1, d0, d1, h, s):
    """Cubic Hermite value at fraction s of an interval of width h."""
    s2 = s * s
    s3 = s2 * s
    return ((2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * h * d0 + (3 * s2 - 2 * s3) * y1
            + (s3 - s2) * h * d1)


@njit(cache=True, error_model="numpy", inline="always")
def _hermite_slope(y0, y1, d0, d1, h, s):
    """d/ds of ``_hermite``."""
    s2 = s * s
    return ((6 * s2 - 6 * s) * (y0 - y1) + (3 * s2 - 4 * s + 1) * h * d0
            + (3 * s2 - 2 * s) * h * d1)


@njit(cache=True, error_model="numpy")
def _simulate_rows_span(lo, hi, x2, R2, S2, x3, R3, S3, c2, c3, a1_in, a2_in, solve1, solve2,
                        turn1, D, psi, cos_psi, sin_psi, target, in_dwell, theta1, L1, L2,
                        carrier0, arm0, play, has_play, rescale, cp, piv, tip, arm, ratio,
                        rate, gear2, closure, a1_out, a2_out):
    """Designs lo..hi - 1 of the population, one after the other with one set of scratch
    rows (``simulate_rows`` runs spans of designs on numba's threads): node radii R2,
    R3 (P, N2 + 1), (P, N3 + 1) with node slopes S2, S3 at knots x2 (N2 + 1), x3 (N3 + 1)
    (the last column the left limit at x[0] + 2 pi, ``_along``), contact angles c2, c3 (P,),
    centre distances a*_in (P,) or solved (``solve1``/``solve2``: for turns turn1 and
    2 pi), ``D`` dense steps (``rescale``: the sun's integral scaled to the meshing span,
    closing stage 1 exactly; else an unclosed pair rolls on periodically); carrier
    samples ``psi`` (S,) (their cos and sin) with their meshing targets and dwell mask;
    per-design L1, L2, carrier0, arm0, play (P,). Writes tip, rate (P, S, 2), arm, ratio,
    gear2 (P, S), closure (P, 2), a1_out, a2_out (P,)."""
    N2, N3 = x2.shape[0] - 1, x3.shape[0] - 1
    S = psi.shape[0]
    h = TWO_PI / D
    r2 = np.empty(D + 1)
    dr2 = np.empty(D + 1)
    r3 = np.empty(D + 1)
    dr3 = np.empty(D + 1)
    f_sun = np.empty(D + 1)
    f_pl = np.empty(D + 1)
    sun = np.empty(D + 1)
    planet = np.empty(D + 1)
    slopes = np.empty(D + 1)
    slopes_b = np.empty(D + 1)
    work_b = np.empty(S)
    at = np.empty(S, dtype=np.int64)
    goal = np.empty(S)
    turn_of = np.empty(S)
    g = np.empty((16, S))
    cos_b = np.empty(S)
    sin_b = np.empty(S)
    span = TWO_PI - theta1
    for p in range(lo, hi):
        _along(x2, R2[p], S2[p], N2, c2[p], h, D, r2, dr2)
        _along(x3, R3[p], S3[p], N3, c3[p], h, D, r3, dr3)
        a1 = _closing_centre_distance(r2, D, turn1) if solve1 else a1_in[p]
        a2 = _closing_centre_distance(r3, D, TWO_PI) if solve2 else a2_in[p]
        a1_out[p], a2_out[p] = a1, a2
        for j in range(D + 1):
            f_sun[j] = r2[j] / (a1 - r2[j])
            f_pl[j] = r3[j] / (a2 - r3[j])
        _running_integrals(f_sun, f_pl, D, h, cp, piv, slopes, slopes_b, sun, planet)
        closure[p, 0] = abs(sun[D] + theta1 - TWO_PI)
        closure[p, 1] = abs(planet[D] - TWO_PI)
        scale = span / sun[D] if rescale else 1.0
        k = 0
        turns = 0
        base = 0.0
        ca = carrier0[p]
        # the merge walk: each sample's interval of the rolling integral and its turns
        for i in range(S):
            tg = target[i] - base
            # an unclosed pair (not rescaled): gear 2 turns on past its turn, the rolling
            # integrals continue periodically
            while not rescale and tg > sun[D] and sun[D] > 0:
                base += sun[D]
                tg -= sun[D]
                turns += 1
                k = 0
            while k < D and sun[k + 1] * scale <= tg:
                k += 1
            kk = k if k < D else D - 1
            at[i] = kk
            goal[i] = tg
            turn_of[i] = turns
            # the interval's ends gathered into rows (the next loop reads them in order)
            g[0, i], g[1, i] = sun[kk] * scale, sun[kk + 1] * scale
            g[2, i], g[3, i] = f_sun[kk] * scale, f_sun[kk + 1] * scale
            g[4, i], g[5, i], g[6, i], g[7, i] = planet[kk], planet[kk + 1], f_pl[kk], f_pl[kk + 1]
            g[8, i], g[9, i], g[10, i], g[11, i] = r2[kk], r2[kk + 1], dr2[kk], dr2[kk + 1]
            g[12, i], g[13, i], g[14, i], g[15, i] = r3[kk], r3[kk + 1], dr3[kk], dr3[kk + 1]
        # then per sample without branches: Newton on the interval's cubic and the
        # Hermite values at the root
        pD, arm_shift = planet[D], arm0[p] - ca
        for i in range(S):
            tg = goal[i]
            y0, y1, d0, d1 = g[0, i], g[1, i], g[2, i], g[3, i]
            s = (tg - y0) / max(y1 - y0, 1e-300)
            for _ in range(2):  # Newton on the cubic (from the chord's guess, two steps)
                val = _hermite(y0, y1, d0, d1, h, s) - tg
                ds = val / _hermite_slope(y0, y1, d0, d1, h, s)
                s = min(max(s - ds, 0.0), 1.0)
            gear2[p, i] = turn_of[i] * TWO_PI + at[i] * h + s * h
            rel = turn_of[i] * pD + _hermite(g[4, i], g[5, i], g[6, i], g[7, i], h, s)
            r2s = _hermite(g[8, i], g[9, i], g[10, i], g[11, i], h, s)
            r3s = _hermite(g[12, i], g[13, i], g[14, i], g[15, i], h, s)
            ratio[p, i] = 0.0 if in_dwell[i] else (a1 - r2s) / r2s * r3s / (a2 - r3s)
            arm[p, i] = (ca - psi[i]) + rel + arm_shift
        cc0, sc0 = np.cos(ca), np.sin(ca)
        if has_play:
            for i in range(S):
                ip = i + 1 if i + 1 < S else 0
                slope = ratio[p, ip] - ratio[p, i - 1]
                sg = 1.0 if slope > 0 else (-1.0 if slope < 0 else 0.0)
                work_b[i] = arm[p, i] - 0.5 * play[p] * sg
            for i in range(S):
                arm[p, i] = work_b[i]
        sincos_rows(arm[p], cos_b, sin_b, S)
        l1, l2 = L1[p], L2[p]
        for i in range(S):
            # cos, sin of the carrier direction carrier0 - psi by the difference formulae
            cc = cc0 * cos_psi[i] + sc0 * sin_psi[i]
            sc = sc0 * cos_psi[i] - cc0 * sin_psi[i]
            cb, sb = cos_b[i], sin_b[i]
            turn = ratio[p, i] - 1.0
            tip[p, i, 0] = l1 * cc + l2 * cb
            tip[p, i, 1] = l1 * sc + l2 * sb
            rate[p, i, 0] = l1 * sc - l2 * turn * sb
            rate[p, i, 1] = -l1 * cc + l2 * turn * cb



@njit(cache=True, error_model="numpy", inline="always")
def _nan_min(m, v):
    """min that keeps a NaN once seen (numpy's ``min``)."""
    return v if (v < m or v != v) and m == m else m


@njit(cache=True, error_model="numpy", inline="always")
def _nan_max(m, v):
    """max that keeps a NaN once seen (numpy's ``max``)."""
    return v if (v > m or v != v) and m == m else m


@njit(cache=True, error_model="numpy")
def _pitch_extremes_rows_span(lo, hi, x, R, Sl, c, a, M, out):
    """Per design p: the shape extremes of gear and mate of one external pair (a gear's
    radii R (P, N) with node slopes Sl at knots x (N + 1), its body angle c (P,) at the
    start, centre distance a (P,), M samples over a turn of the gear, as
    ``manufacturability.shape_pair`` samples them): out (P, 14) = per curve (gear, then
    the mate rho = a - r, phi' = r / (a - r), phi'' = a r' / (a - r)^2) 6 columns: the
    smallest convex radius of curvature, the smallest concave one (magnitude; inf where
    none), the smallest radius, the perimeter (arc speed summed times the step), the
    smallest curvature x radius and the number of concave spans (cyclic; one when all is
    concave); then the largest angle mu = atan(|r'| / r) (rad) between the pitch tangent
    and the normal to the radius vector, and the largest |mu| (NaN kept as numpy's min and
    max keep it).

    Per sample the curvature kappa = num / speed^3 (num = rho^2 phi'^3 + 2 rho'^2 phi' -
    rho rho'' phi' + rho rho' phi'', speed^2 = rho'^2 + (rho phi')^2:
    ``geometry.periodic.polar_curvature_radius``'s terms) is the one division per
    curve: the smallest convex (concave) radius of curvature is 1 / the
    largest (most negative) curvature."""
    P, N = R.shape
    step = TWO_PI / M
    inv_width = np.empty(N)
    for k in range(N):
        inv_width[k] = 1.0 / (x[k + 1] - x[k])
    acc = np.empty(12)
    g = np.empty((6, M))  # per sample: t, 1 / width, y0, y1, d0, d1 of its interval
    q = np.empty((5, M))  # per sample: r, mate curvature, gear curvature, speeds
    qm = np.empty((2, M))  # per sample: mate speed, |r'| / r
    for p in range(lo, hi):
        for col in (0, 6):
            acc[col] = acc[col + 1] = 0.0  # largest convex / concave curvature
            acc[col + 2] = acc[col + 4] = np.inf
            acc[col + 3] = acc[col + 5] = 0.0
        ratio_max = ratio_abs = -np.inf
        prev0 = prev1 = False
        first0 = first1 = False
        every0 = every1 = True
        ap = a[p]
        w0 = (c[p] - x[0]) % TWO_PI
        k = 0
        for j in range(M):  # the march: each sample's interval, gathered into rows
            # the angle wrapped into the turn from x[0] (a knot on a sample takes the span
            # that starts there, where the second derivative of a C1 curve jumps)
            w = w0 + j * step
            if w >= TWO_PI:
                w -= TWO_PI
            u = x[0] + w
            if u < x[k]:
                k = 0
            while k < N - 1 and x[k + 1] <= u:
                k += 1
            hk = x[k + 1] - x[k]
            k1 = k + 1 if k + 1 < N else 0
            g[0, j] = (u - x[k]) * inv_width[k]
            g[1, j] = inv_width[k]
            g[2, j], g[3, j] = R[p, k], R[p, k1]
            g[4, j], g[5, j] = Sl[p, k] * hk, Sl[p, k1] * hk
        for j in range(M):  # the curves' values, no branches (SIMD)
            t, ih, y0, y1, d0, d1 = g[0, j], g[1, j], g[2, j], g[3, j], g[4, j], g[5, j]
            t2 = t * t
            t3 = t2 * t
            dy = y0 - y1
            r = y0 + (2 * t3 - 3 * t2) * dy + (t3 - 2 * t2 + t) * d0 + (t3 - t2) * d1
            r1 = ((6 * t2 - 6 * t) * dy + (3 * t2 - 4 * t + 1) * d0
                  + (3 * t2 - 2 * t) * d1) * ih
            r2 = ((12 * t - 6) * dy + (6 * t - 4) * d0 + (6 * t - 2) * d1) * (ih * ih)
            m = ap - r
            r1r1 = r1 * r1
            # the gear: rho = r, phi = t
            num = r * r + 2 * r1r1 - r * r2
            sp2 = r1r1 + r * r
            sp = np.sqrt(sp2)
            # the mate: rho = m, rho' = -r', rho'' = -r'', phi' = r / m, phi'' = a r' / m^2
            im = 1.0 / m
            dphi = r * im
            ddphi = ap * r1 * im * im
            num_m = m * m * (dphi * dphi * dphi) + 2 * r1r1 * dphi + m * r2 * dphi \
                - m * r1 * ddphi
            sp2m = r1r1 + (m * dphi) * (m * dphi)
            spm = np.sqrt(sp2m)
            q[0, j] = r
            q[1, j] = num_m / (sp2m * spm)
            q[2, j] = num / (sp2 * sp)
            q[3, j] = sp
            qm[0, j] = spm
            qm[1, j] = np.abs(r1) / r
        for j in range(M):  # the extremes and the concave spans
            r = q[0, j]
            kap_g, kap_m = q[2, j], q[1, j]
            for curve in range(2):
                if curve == 0:
                    rho, kappa, speed, col = r, kap_g, q[3, j], 0
                else:
                    rho, kappa, speed, col = ap - r, kap_m, qm[0, j], 6
                if kappa > acc[col]:
                    acc[col] = kappa
                if -kappa > acc[col + 1]:
                    acc[col + 1] = -kappa
                acc[col + 2] = _nan_min(acc[col + 2], rho)
                acc[col + 3] += speed
                acc[col + 4] = _nan_min(acc[col + 4], kappa * rho)
            concave0 = kap_g < 0
            concave1 = kap_m < 0
            if j == 0:
                first0 = concave0
                first1 = concave1
            else:
                if concave0 and not prev0:
                    acc[5] += 1.0
                if concave1 and not prev1:
                    acc[11] += 1.0
            prev0 = concave0
            prev1 = concave1
            every0 = every0 and concave0
            every1 = every1 and concave1
            # atan is monotonic: the largest angle is the angle of the largest |r'| / r
            ratio = qm[1, j]
            ratio_max = _nan_max(ratio_max, ratio)
            ratio_abs = _nan_max(ratio_abs, abs(ratio))
        for col, first, prev, every in ((0, first0, prev0, every0), (6, first1, prev1, every1)):
            if first and not prev:  # a span starting at sample 0 (cyclic)
                acc[col + 5] += 1.0
            if every:
                acc[col + 5] += 1.0
            acc[col + 3] *= step
            acc[col] = np.inf if acc[col] == 0.0 else 1.0 / acc[col]
            acc[col + 1] = np.inf if acc[col + 1] == 0.0 else 1.0 / acc[col + 1]
        for i in range(12):
            out[p, i] = acc[i]
        out[p, 12] = np.arctan(ratio_max)
        out[p, 13] = np.arctan(ratio_abs)


@njit(cache=True, error_model="numpy")
def _locate_rows_span(lo, hi, tip, psi, points, first, count, out, miss):
    """Carrier angles (rad) where each design's tip (P, S, 2) passes closest to each
    section point (K, 2) among its candidate samples: the cyclic run of ``count[p, j]``
    samples from ``first[p, j]``, scanned in ascending sample index; the closest one is
    refined by the parabola through the squared distances at it and its two neighbours
    (vertex offset within +-half a step of psi[1] - psi[0]): out (P, K) rad in [0, 2 pi),
    miss (P, K) the distance at the vertex (mm; the closest sample's when the parabola
    dips below 0). The first smallest sample wins; a NaN distance is taken as numpy's
    argmin takes it (the first NaN); no candidate: sample 0
    (``objectives.seeder_population.locate_sections``)."""
    S = tip.shape[1]
    step = psi[1] - psi[0]
    for p in range(lo, hi):
        for j in range(points.shape[0]):
            px, py = points[j, 0], points[j, 1]
            best = np.inf
            k = 0
            found = False
            f0, n = first[p, j], count[p, j]
            wrap = f0 + n - S  # samples 0 .. wrap - 1 come first (ascending order)
            for r in range(2):
                i0, i1 = (0, wrap) if r == 0 else (f0, min(f0 + n, S))
                for i in range(i0, i1):
                    d2 = (tip[p, i, 0] - px) ** 2 + (tip[p, i, 1] - py) ** 2
                    if d2 != d2:
                        k = i
                        found = True
                        best = d2
                        break
                    if not found or d2 < best:
                        best, k, found = d2, i, True
                if best != best:
                    break
            km, kp = (k - 1) % S, (k + 1) % S
            a = (tip[p, km, 0] - px) ** 2 + (tip[p, km, 1] - py) ** 2
            b = (tip[p, k, 0] - px) ** 2 + (tip[p, k, 1] - py) ** 2
            c = (tip[p, kp, 0] - px) ** 2 + (tip[p, kp, 1] - py) ** 2
            curv = a - 2.0 * b + c
            t = 0.5 * (a - c) / curv if curv > 0 else 0.0
            t = min(max(t, -0.5), 0.5)
            out[p, j] = (psi[k] + t * step) % TWO_PI
            low = b - 0.25 * (a - c) * t
            miss[p, j] = np.sqrt(low if low >= 0 else b)


@njit(cache=True, error_model="numpy", inline="always")
def _interval(psi, where):
    """(k, t): carrier angle ``where`` (rad) lies the fraction t of the way from sample
    psi[k] to the next one (psi ascending in [0, 2 pi), closed at psi[0] + 2 pi; any
    spacing): uniform samples are located by one division, others by bisection."""
    S = psi.shape[0]
    w = where % TWO_PI
    if w < psi[0]:
        w += TWO_PI
    step = psi[1] - psi[0]
    k = int(np.floor((w - psi[0]) / step))
    if k >= S:
        k = S - 1
    # one division locates uniform samples; the check makes any other spacing exact
    if not (psi[k] <= w and (k == S - 1 or w < psi[k + 1])):
        k = np.searchsorted(psi, w, side="right") - 1
    x1 = psi[k + 1] if k < S - 1 else psi[0] + TWO_PI
    return k, (w - psi[k]) / (x1 - psi[k])


@njit(cache=True, error_model="numpy", inline="always")
def _at_row(psi, values, where):
    """values (S,) at carrier angle ``where`` (rad), linear between the samples psi
    (periodic, ``_interval``)."""
    S = values.shape[0]
    k, t = _interval(psi, where)
    return (1.0 - t) * values[k] + t * values[(k + 1) % S]


@njit(cache=True, error_model="numpy", inline="always")
def _speed_at(psi, vx, vy, where, travel):
    """The speed samples |(vx - travel, vy)| (S,) at carrier angle ``where``, linear
    between the samples (periodic), as ``_at_row`` interpolates them."""
    S = vx.shape[0]
    k, t = _interval(psi, where)
    k1 = (k + 1) % S
    return ((1.0 - t) * np.hypot(vx[k] - travel, vy[k])
            + t * np.hypot(vx[k1] - travel, vy[k1]))


@njit(cache=True, error_model="numpy", inline="always")
def _offset(psi_i, start0):
    """(psi_i - start0) mod 2 pi for psi_i and start0 in [0, 2 pi): one subtraction and,
    behind the start, one turn added."""
    d = psi_i - start0
    return d + TWO_PI if d < 0 else d


# the section table's columns: 5 per attitude section (SECTION_STATS) for the sections
# ab, bc, cd, de, ea (ATTITUDE_SECTIONS), then the speeds (SPEED_COLUMNS)
ATTITUDE_SECTIONS = ((0, 1), (1, 2), (2, 3), (3, 4), (4, 0))
SECTION_STATS = ("start", "end", "min", "max", "swing")
SPEED_COLUMNS = ("vx_e", "vy_e", "travel", "peak_static_de", "least_static_ef",
                 "least_dynamic_ef", "peak_dynamic_de", "peak_static", "least_static")
SECTION_COLUMNS = 5 * len(ATTITUDE_SECTIONS) + len(SPEED_COLUMNS)


@njit(cache=True, error_model="numpy")
def _section_table_rows_span(lo, hi, psi, angle, angle_scale, rate, rate_scale, sec, travel,
                             given, full, out):
    """The section table of every design: the attitude rel = (angle - angle[:, 0]) *
    angle_scale (deg) of angles (P, S) and the tip velocity rate * rate_scale (m/s) of
    rates (P, S, 2) at the carrier angles psi (S,) rad (ascending in [0, 2 pi), any
    spacing), sections a..f at ``sec`` (P, 6) rad, the travel speed (P,) m/s when
    ``given`` (else the horizontal tip speed at e, Eq. 18). out (P, SECTION_COLUMNS): per
    attitude section (ab, bc, cd, de, ea) its start, end, min, max and swing (the value
    farthest from the start, minus the start: signed); then vx and vy at e, the travel
    speed, the seeding section's peak static speed (de), the return section's least static
    and least dynamic (Eq. 17) speed (ef), the peak dynamic speed over de and the peak and
    least static speed over the cycle. Section ends are interpolated and included (after
    the samples, start then end); NaN is kept as numpy's max and min keep it. A sample
    psi[i] is in the section [start, start + span] when (psi[i] - start) mod 2 pi <= span
    (``_offset``). ``full`` False: only what the section-4.1 objectives read, faster (the
    optimizer's path): sections ab and de with their swings as |swing| (branch-free), the
    speeds over de and ef; every other column NaN."""
    P, S = angle.shape
    rel = np.empty(S)
    vx = np.empty(S)
    vy = np.empty(S)
    static = np.empty(S)
    for p in range(lo, hi):
        for i in range(S):
            rel[i] = (angle[p, i] - angle[p, 0]) * angle_scale
            vx[i] = rate[p, i, 0] * rate_scale
            vy[i] = rate[p, i, 1] * rate_scale
        for i in range(S):
            static[i] = np.sqrt(vx[i] * vx[i] + vy[i] * vy[i])
        for q in range(5):  # attitude per section
            c = 5 * q
            if not full and q != 0 and q != 3:
                for k in range(5):
                    out[p, c + k] = np.nan
                continue
            s0, s1 = ATTITUDE_SECTIONS[q]
            start, end = sec[p, s0], sec[p, s1]
            ref = _at_row(psi, rel, start)
            fin = _at_row(psi, rel, end)
            span = (end - start) % TWO_PI
            start0 = start % TWO_PI
            if not full:  # |swing| only: the largest |rel - ref| (branch-free, SIMD)
                dev = -np.inf
                for i in range(S):
                    d = abs(rel[i] - ref) if _offset(psi[i], start0) <= span else 0.0
                    dev = _nan_max(dev, d)
                out[p, c], out[p, c + 1], out[p, c + 2], out[p, c + 3] = ref, fin, np.nan, np.nan
                out[p, c + 4] = _nan_max(dev, abs(fin - ref))
                continue
            low, high = ref, ref
            dev, swing = 0.0, 0.0  # the start itself: no change
            nan = ref != ref
            for i in range(S):
                if _offset(psi[i], start0) <= span:
                    v = rel[i]
                    low = _nan_min(low, v)
                    high = _nan_max(high, v)
                    d = abs(v - ref)
                    if d > dev:
                        dev, swing = d, v - ref
                    elif d != d:
                        nan = True
            low, high = _nan_min(low, fin), _nan_max(high, fin)
            d = abs(fin - ref)
            if d > dev:
                dev, swing = d, fin - ref
            elif d != d:
                nan = True
            out[p, c], out[p, c + 1], out[p, c + 2], out[p, c + 3] = ref, fin, low, high
            out[p, c + 4] = np.nan if nan else swing
        d_, e, f = sec[p, 3], sec[p, 4], sec[p, 5]
        vx_e = _at_row(psi, vx, e)
        tr = travel[p] if given else vx_e
        c = 25
        out[p, c], out[p, c + 1], out[p, c + 2] = vx_e, _at_row(psi, vy, e), tr
        span_de = (e - d_) % TWO_PI
        span_ef = (f - e) % TWO_PI
        d0 = d_ % TWO_PI
        e0 = e % TWO_PI
        peak = -np.inf
        low_s = np.inf
        low_d = np.inf
        for i in range(S):
            if _offset(psi[i], d0) <= span_de:
                peak = _nan_max(peak, static[i])
            if _offset(psi[i], e0) <= span_ef:
                low_s = _nan_min(low_s, static[i])
                wx = vx[i] - tr
                low_d = _nan_min(low_d, np.sqrt(wx * wx + vy[i] * vy[i]))
        # the section ends: the speed samples interpolated
        for w in (d_, e):
            peak = _nan_max(peak, _speed_at(psi, vx, vy, w, 0.0))
        for w in (e, f):
            low_s = _nan_min(low_s, _speed_at(psi, vx, vy, w, 0.0))
            low_d = _nan_min(low_d, _speed_at(psi, vx, vy, w, tr))
        peak_d, top, bottom = np.nan, np.nan, np.nan
        if full:
            peak_d, top, bottom = -np.inf, -np.inf, np.inf
            for i in range(S):
                top = _nan_max(top, static[i])
                bottom = _nan_min(bottom, static[i])
                if _offset(psi[i], d0) <= span_de:
                    wx = vx[i] - tr
                    peak_d = _nan_max(peak_d, np.sqrt(wx * wx + vy[i] * vy[i]))
            for w in (d_, e):
                peak_d = _nan_max(peak_d, _speed_at(psi, vx, vy, w, tr))
        out[p, c + 3], out[p, c + 4], out[p, c + 5] = peak, low_s, low_d
        out[p, c + 6], out[p, c + 7], out[p, c + 8] = peak_d, top, bottom


@njit(cache=True, error_model="numpy", parallel=True)
def _simulate_rows_threads(chunks, x2, R2, S2, x3, R3, S3, c2, c3, a1_in, a2_in, solve1,
                           solve2, turn1, D, psi, cos_psi, sin_psi, target, in_dwell, theta1,
                           L1, L2, carrier0, arm0, play, has_play, rescale, cp, piv, tip, arm,
                           ratio, rate, gear2, closure, a1_out, a2_out):
    """``_simulate_rows_span`` over all P designs in ``chunks`` contiguous spans of designs, run
    on numba's threads (``prange``); one chunk: one thread."""
    P = R2.shape[0]
    for ch in prange(chunks):
        _simulate_rows_span(ch * P // chunks, (ch + 1) * P // chunks, x2, R2, S2, x3, R3, S3, c2,
            c3, a1_in, a2_in, solve1, solve2, turn1, D, psi, cos_psi, sin_psi, target,
            in_dwell, theta1, L1, L2, carrier0, arm0, play, has_play, rescale, cp, piv,
            tip, arm, ratio, rate, gear2, closure, a1_out, a2_out)


@njit(cache=True, error_model="numpy", parallel=True)
def _pitch_extremes_rows_threads(chunks, x, R, Sl, c, a, M, out):
    """``_pitch_extremes_rows_span`` over all P designs in ``chunks`` contiguous spans of designs,
    run on numba's threads (``prange``); one chunk: one thread."""
    P = R.shape[0]
    for ch in prange(chunks):
        _pitch_extremes_rows_span(ch * P // chunks, (ch + 1) * P // chunks, x, R, Sl, c, a, M, out)


@njit(cache=True, error_model="numpy", parallel=True)
def _locate_rows_threads(chunks, tip, psi, points, first, count, out, miss):
    """``_locate_rows_span`` over all P designs in ``chunks`` contiguous spans of designs, run on
    numba's threads (``prange``); one chunk: one thread."""
    P = tip.shape[0]
    for ch in prange(chunks):
        _locate_rows_span(ch * P // chunks, (ch + 1) * P // chunks, tip, psi, points, first,
                          count, out, miss)


@njit(cache=True, error_model="numpy", parallel=True)
def _section_table_rows_threads(chunks, psi, angle, angle_scale, rate, rate_scale, sec,
                                travel, given, full, out):
    """``_section_table_rows_span`` over all P designs in ``chunks`` contiguous spans of
    designs, run on numba's threads (``prange``); one chunk: one thread."""
    P = angle.shape[0]
    for ch in prange(chunks):
        _section_table_rows_span(ch * P // chunks, (ch + 1) * P // chunks, psi, angle,
            angle_scale, rate, rate_scale, sec, travel, given, full, out)


def _run(span, threaded, P, args):
    """``span(0, P, *args)``, or ``threaded(chunks, *args)`` when ``chunks_for(P)`` splits
    the designs (a one-span call stays out of numba's thread pool)."""
    chunks = chunks_for(P)
    if chunks == 1:
        span(0, P, *args)
    else:
        threaded(chunks, *args)


def simulate_rows(*args):
    """``_simulate_rows_span`` over every design (R2.shape[0] of them): on one thread, or
    on ``kernel_threads()`` threads in spans (``_simulate_rows_threads``)."""
    _run(_simulate_rows_span, _simulate_rows_threads, args[1].shape[0], args)


def pitch_extremes_rows(*args):
    """``_pitch_extremes_rows_span`` over every design (R.shape[0] of them): on one thread, or
    on ``kernel_threads()`` threads in spans (``_pitch_extremes_rows_threads``)."""
    _run(_pitch_extremes_rows_span, _pitch_extremes_rows_threads, args[1].shape[0], args)


def locate_rows(*args):
    """``_locate_rows_span`` over every design (tip.shape[0] of them): on one thread, or
    on ``kernel_threads()`` threads in spans (``_locate_rows_threads``)."""
    _run(_locate_rows_span, _locate_rows_threads, args[0].shape[0], args)


def section_table_rows(*args):
    """``_section_table_rows_span`` over every design (angle.shape[0] of them): on one
    thread, or on ``kernel_threads()`` threads in spans (``_section_table_rows_threads``)."""
    _run(_section_table_rows_span, _section_table_rows_threads, args[1].shape[0], args)
