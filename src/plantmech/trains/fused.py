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
- ``pair_laws``: a pair's closed law (closure solve, ratio, the spline's running
  integral); ``mate_tables``: the follower's pitch curve rolled from it (an idler's, the
  next pair's driver); ``chain_tips``: the tip motion walked once per design, arm and
  sample along the chain of pairs (``trains.model.simulate_tips``).
- ``crossings``: the proper self-crossings of closed polylines
  (``objectives.planetary.self_crossings``): per design its segments sorted by their
  smallest x and swept (a crossing pair overlaps in x), then the exact orientation test
  of the NumPy version: the same counts.

Imported lazily, for populations of at least ``curves.KERNEL_POINTS`` grid points only:
numba stays out of the CLI's start-up and of single designs; compilation cached on disk.
Radii mm, angles rad.

A population's tables are a few MB each (``objectives.planetary.CHUNK_POINTS``), made and
freed per sub-population. glibc's allocator maps blocks that large afresh and hands the
freed heap top back to the system, so every sub-population page-faulted its tables in
again (Table 4 at grid 16384: ~270 faults per design, 40 % of its CPU time). Importing
this module therefore asks glibc (``_keep_heap``; elsewhere nothing) to serve blocks up to
32 MB from the heap and keep up to 128 MB of freed heap: measured on Table 4 x 720
samples, every objective, 1,300 -> 820 us of CPU per design at grid 16384 and 270 -> 180
at grid 2048, no fault left.
"""

from __future__ import annotations

import numpy as np
from numba import njit


def _keep_heap(mmap_threshold: int = 32 << 20, trim_threshold: int = 128 << 20) -> bool:
    """glibc's ``mallopt``: blocks below ``mmap_threshold`` bytes from the heap, freed heap
    kept up to ``trim_threshold`` bytes (module docstring). Whether it was set (False off
    glibc: nothing done)."""
    import ctypes
    import sys

    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None)
        mallopt = libc.mallopt
    except (OSError, AttributeError):  # not glibc
        return False
    M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
    return bool(mallopt(M_MMAP_THRESHOLD, mmap_threshold)) and bool(
        mallopt(M_TRIM_THRESHOLD, trim_threshold))


HEAP_KEPT = _keep_heap()

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


@njit(cache=True, error_model="numpy", inline="always")
def _extreme_points(r, r1, p, i0, i1, N, kappa, ca, sd, sf, h, cdv, cfv, rhov, fv, pdv, pfv):
    """``pair_extremes``' per-point values at grid points i0 <= i < i1 of row p (its
    arithmetic, term by term; r'' from the slopes' centred differences, wrapping round at
    the ends): both gears' signed radii of curvature, the follower's radius and body-angle
    rate, both perimeter terms."""
    for i in range(i0, i1):
        rr, d = r[p, i], r1[p, i]
        dd = ((r1[p, i + 1] if i + 1 < N else r1[p, 0])
              - (r1[p, i - 1] if i > 0 else r1[p, N - 1])) / (2 * h)
        rho = kappa * rr + ca
        f = rr / rho
        ff = ca * d / (rho * rho)
        kd, kdd = kappa * d, kappa * dd
        cdv[i] = sd * _curvature(rr, d, dd, 1.0, 0.0, True)
        cfv[i] = sf * _curvature(rho, kd, kdd, f, ff, False)
        rhov[i] = rho
        fv[i] = f
        pdv[i] = np.sqrt(d * d + rr * rr)
        rf = rho * f
        pfv[i] = np.sqrt(kd * kd + rf * rf)


@njit(cache=True, error_model="numpy", nogil=True)
def pair_extremes(r, r1, a, kappa, c, ring_d, ring_f, t0, h):
    """(values (P, 13), indices (P, 8)) of P pairs from the driver's tables r, r' (P, N)
    (r'' from the slopes' centred differences, ``curves.second_derivative``'s) on the grid
    t_i = i h and the centre distances ``a`` (P,): the driver's and
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
    sd = -1.0 if ring_d else 1.0
    sf = -1.0 if ring_f else 1.0
    cdv = np.empty(N)  # per point, the branch-free pass's values (SIMD)
    cfv = np.empty(N)
    rhov = np.empty(N)
    fv = np.empty(N)
    pdv = np.empty(N)
    pfv = np.empty(N)
    for p in range(P):
        ca = c * a[p]
        # the arithmetic, branch-free (SIMD): the ends' r'' wrap round (below)
        _extreme_points(r, r1, p, 1, N - 1, N, kappa, ca, sd, sf, h, cdv, cfv, rhov, fv, pdv,
                        pfv)
        _extreme_points(r, r1, p, 0, 1, N, kappa, ca, sd, sf, h, cdv, cfv, rhov, fv, pdv,
                        pfv)
        _extreme_points(r, r1, p, N - 1, N, N, kappa, ca, sd, sf, h, cdv, cfv, rhov, fv,
                        pdv, pfv)
        cvx_d = ccv_d = rad_d = cvx_f = ccv_f = rad_f = diff = inf
        i_cvx_d = i_ccv_d = i_rad_d = i_cvx_f = i_ccv_f = i_rad_f = i_mu = i_diff = 0
        per_d = per_f = 0.0
        mu = -inf
        cum = 0.0
        phi_cvx = phi_ccv = phi_rad = 0.0
        for i in range(N):  # the reductions, in the grid's order
            rr, d = r[p, i], r1[p, i]
            cd, cf, rho, f = cdv[i], cfv[i], rhov[i], fv[i]
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
            per_d += pdv[i]
            per_f += pfv[i]
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


@njit(cache=True, error_model="numpy", nogil=True)
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


@njit(cache=True, error_model="numpy", fastmath={"reassoc", "nsz"})
def _ratio_sums(r, p, kappa, c, a, stride):
    """(mean of g = r / (kappa r + c a), mean of g / (kappa r + c a)) over the strided row
    p of r (its sums reassociated: SIMD; 1e-16 relative from the sequential sums)."""
    N = r.shape[1]
    s1 = 0.0
    s2 = 0.0
    n = 0
    for i in range(0, N, stride):
        x = r[p, i]
        inv = 1.0 / (kappa * x + c * a)
        gi = x * inv
        s1 += gi
        s2 += gi * inv
        n += 1
    return s1 / n, s2 / n


@njit(cache=True, error_model="numpy", fastmath={"reassoc", "nsz", "nnan", "ninf"})
def _row_range(r, p):
    """(smallest, largest) of row p of r."""
    lo = r[p, 0]
    hi = r[p, 0]
    for i in range(r.shape[1]):
        x = r[p, i]
        lo = min(lo, x)
        hi = max(hi, x)
    return lo, hi


@njit(cache=True, error_model="numpy")
def _closing_distance(r, p, kappa, c, q, lo, hi, coarse, step_tol):
    """a with mean(r / (kappa r + c a)) = q over row p of r (``solve_centre_distance``'s
    root, to its relative step ``step_tol``): the mean is monotone in a on [lo, hi], so
    Newton on the coarse table (every ``coarse``-th radius), kept inside a bracket it
    shrinks (a step leaving it bisects), then Newton on the full table until the relative
    step is below ``step_tol``; the full table's 64 bisections if 12 steps do not settle
    it. Returns (a, settled by Newton)."""
    rising = c < 0  # an internal pair: the mean ratio rises with a
    a0, a1 = lo, hi
    a = 0.5 * (a0 + a1)
    if coarse > 1:
        for _ in range(4):  # a quarter of the bracket first: Newton's basin
            m, _ = _ratio_sums(r, p, kappa, c, a, coarse)
            if (m < q) == rising:
                a0 = a
            else:
                a1 = a
            a = 0.5 * (a0 + a1)
        for _ in range(40):
            m, d = _ratio_sums(r, p, kappa, c, a, coarse)
            if (m < q) == rising:
                a0 = a
            else:
                a1 = a
            new = a - (m - q) / (-c * d)
            if not (new > a0 and new < a1):
                new = 0.5 * (a0 + a1)
            done = abs(new - a) <= 1e-12 * abs(a)
            a = new
            if done or a1 - a0 <= 1e-13 * abs(a):
                break
    settled = False
    for _ in range(12):
        m, d = _ratio_sums(r, p, kappa, c, a, 1)
        new = min(max(a - (m - q) / (-c * d), lo), hi)
        settled = abs(new - a) <= step_tol * abs(a)
        a = new
        if settled:
            break
    if not settled:
        a0, a1 = lo, hi
        for _ in range(64):
            mid = 0.5 * (a0 + a1)
            m, _ = _ratio_sums(r, p, kappa, c, mid, 1)
            if (m < q) == rising:
                a0 = mid
            else:
                a1 = mid
        a = 0.5 * (a0 + a1)
    return a, settled


#: cells a sweep's chain is started before its segment: the (1, 4, 1) system's Thomas
#: factors are 2 - sqrt(3) = 0.268 within a few cells, so a state guessed 0 there is off
#: by 0.268^40 = 1e-23 of the state's size at the segment
_WARM = 40


@njit(cache=True, error_model="numpy")
def _thomas(rhs, cp, w, m, N):
    """m = T^-1 rhs for the tridiagonal (1, d_i, 1) system with Thomas factors cp = 1 /
    den: w_i = (rhs_i - w_i-1) cp_i, m_i = w_i - cp_i m_i+1. Each sweep runs as four
    chains over quarters of the row at once (independent: the processor overlaps their
    latency), each quarter's chain started ``_WARM`` cells early from 0: the same values
    as one chain to rounding (the discarded state is damped by cp^40)."""
    L = N // 4
    if L <= 2 * _WARM:
        for i in range(N):
            w[i] = (rhs[i] - (w[i - 1] if i > 0 else 0.0)) * cp[i]
        m[N - 1] = w[N - 1]
        for i in range(N - 2, -1, -1):
            m[i] = w[i] - cp[i] * m[i + 1]
        return
    wa = 0.0
    wb = 0.0
    wc = 0.0
    wd = 0.0
    for i in range(L - _WARM, L):
        wb = (rhs[i] - wb) * cp[i]
    for i in range(2 * L - _WARM, 2 * L):
        wc = (rhs[i] - wc) * cp[i]
    for i in range(3 * L - _WARM, 3 * L):
        wd = (rhs[i] - wd) * cp[i]
    for t in range(L):
        wa = (rhs[t] - wa) * cp[t]
        w[t] = wa
        wb = (rhs[L + t] - wb) * cp[L + t]
        w[L + t] = wb
        wc = (rhs[2 * L + t] - wc) * cp[2 * L + t]
        w[2 * L + t] = wc
        wd = (rhs[3 * L + t] - wd) * cp[3 * L + t]
        w[3 * L + t] = wd
    for i in range(4 * L, N):
        wd = (rhs[i] - wd) * cp[i]
        w[i] = wd
    # backwards: m_N-1 = w_N-1; chains down from L - 1, 2L - 1, 3L - 1 (started _WARM
    # cells above) and N - 2 (from m_N-1), over [0, L), [L, 2L), [2L, 3L), [3L, N - 1)
    m[N - 1] = w[N - 1]
    ma = 0.0
    mb = 0.0
    mc = 0.0
    md = m[N - 1]
    for i in range(L + _WARM - 1, L - 1, -1):
        ma = w[i] - cp[i] * ma
    for i in range(2 * L + _WARM - 1, 2 * L - 1, -1):
        mb = w[i] - cp[i] * mb
    for i in range(3 * L + _WARM - 1, 3 * L - 1, -1):
        mc = w[i] - cp[i] * mc
    for t in range(L - 1):
        ma = w[L - 1 - t] - cp[L - 1 - t] * ma
        m[L - 1 - t] = ma
        mb = w[2 * L - 1 - t] - cp[2 * L - 1 - t] * mb
        m[2 * L - 1 - t] = mb
        mc = w[3 * L - 1 - t] - cp[3 * L - 1 - t] * mc
        m[3 * L - 1 - t] = mc
        md = w[N - 2 - t] - cp[N - 2 - t] * md
        m[N - 2 - t] = md
    m[0] = w[0] - cp[0] * ma
    m[L] = w[L] - cp[L] * mb
    m[2 * L] = w[2 * L] - cp[2 * L] * mc
    for i in range(N - 2 - (L - 1), 3 * L - 1, -1):
        md = w[i] - cp[i] * md
        m[i] = md


@njit(cache=True, error_model="numpy")
def _running_sum(step, out, p, N):
    """out[p, i] = step_0 + ... + step_i-1 (out[p, 0] = 0) and the whole sum: four chains
    over quarters of the row, then each quarter's offset added (the same sums to
    rounding)."""
    L = N // 4
    if L < 2:
        total = 0.0
        for i in range(N):
            out[p, i] = total
            total += step[i]
        return total
    sa = 0.0
    sb = 0.0
    sc = 0.0
    sd = 0.0
    for t in range(L):
        out[p, t] = sa
        sa += step[t]
        out[p, L + t] = sb
        sb += step[L + t]
        out[p, 2 * L + t] = sc
        sc += step[2 * L + t]
        out[p, 3 * L + t] = sd
        sd += step[3 * L + t]
    for i in range(4 * L, N):
        out[p, i] = sd
        sd += step[i]
    ob = sa
    oc = ob + sb
    od = oc + sc
    for t in range(L):
        out[p, L + t] += ob
        out[p, 2 * L + t] += oc
    for i in range(3 * L, N):
        out[p, i] += od
    return od + sd


@njit(cache=True, error_model="numpy", nogil=True)
def pair_laws(r, dr, kappa, c, q, lo, hi, given, solve, coarse, coarse_steps, step_tol):
    """The closed laws of P pairs of one kind (``trains.pairs.pair_law``'s tables) in one
    pass per design: the centre distance a (given, or solved as
    ``solve_centre_distance`` solves it, by ``_closing_distance``: Newton on every
    ``coarse``-th radius inside a shrinking bracket, then on the full table until the
    relative step is below ``step_tol``; the same root to 1e-14 relative; ``coarse_steps``
    is not used: kept for the callers), the ratio g = r / (kappa r + c a) and its slope,
    the periodic cubic spline's running integral F of g (its moments by the cyclic
    (1, 4, 1) system, Sherman-Morrison on a Thomas sweep, where the NumPy path uses an FFT:
    the same spline, 1e-16 apart), q_e = F(2 pi) / 2 pi and the periodic part
    Fp = F - q_e theta. Returns (a (P,), g, dg, Fp (P, N), q_e (P,), smallest follower
    radius (P,)). ``kappa``, ``c``: the kind's r_f = kappa r_d + c a."""
    P, N = r.shape
    h = 2.0 * np.pi / N
    a_out = np.empty(P)
    g = np.empty((P, N))
    dg = np.empty((P, N))
    Fp = np.empty((P, N))
    q_e = np.empty(P)
    rf_min = np.empty(P)
    # the Thomas factors of the cyclic (1, 4, 1) system's tridiagonal part (corners
    # moved to the Sherman-Morrison vector u = (gamma, 0, ..., 0, 1), gamma = -4)
    gamma = -4.0
    diag = np.full(N, 4.0)
    diag[0] = 4.0 - gamma
    diag[N - 1] = 4.0 - 1.0 / gamma
    cp = np.empty(N)
    den = np.empty(N)
    den[0] = diag[0]
    cp[0] = 1.0 / den[0]
    for i in range(1, N):
        den[i] = diag[i] - cp[i - 1]
        cp[i] = 1.0 / den[i]
    z = np.empty(N)
    w = np.empty(N)
    m = np.empty(N)
    rhs = np.empty(N)
    step = np.empty(N)
    u0 = gamma
    # z = T^-1 u
    w[0] = u0 / den[0]
    for i in range(1, N):
        ui = 1.0 if i == N - 1 else 0.0
        w[i] = (ui - w[i - 1]) / den[i]
    z[N - 1] = w[N - 1]
    for i in range(N - 2, -1, -1):
        z[i] = w[i] - cp[i] * z[i + 1]
    zfact = 1.0 + z[0] + z[N - 1] / gamma
    scale = 6.0 / (h * h)
    for p in range(P):
        if solve:
            a, _ = _closing_distance(r, p, kappa, c, q[p], lo[p], hi[p], coarse, step_tol)
        else:
            a = given[p]
        a_out[p] = a
        ca = c * a
        for i in range(N):
            inv = 1.0 / (kappa * r[p, i] + ca)
            g[p, i] = r[p, i] * inv
            dg[p, i] = dr[p, i] * ca * (inv * inv)
        rmin, rmax = _row_range(r, p)  # r_f = kappa r + c a: smallest at an end of r's range
        rf_min[p] = min(kappa * rmin + ca, kappa * rmax + ca)
        # moments: T x = rhs (Thomas), then the Sherman-Morrison correction
        for i in range(N):
            prev = g[p, i - 1] if i > 0 else g[p, N - 1]
            nxt = g[p, i + 1] if i + 1 < N else g[p, 0]
            rhs[i] = scale * (prev - 2.0 * g[p, i] + nxt)
        _thomas(rhs, cp, w, m, N)
        fact = (m[0] + m[N - 1] / gamma) / zfact
        h3 = h * h * h / 24.0
        for i in range(N):
            m[i] -= fact * z[i]
        for i in range(N):
            j = i + 1 if i + 1 < N else 0
            step[i] = 0.5 * h * (g[p, i] + g[p, j]) - h3 * (m[i] + m[j])
        total = _running_sum(step, Fp, p, N)
        qe = total / (2.0 * np.pi)
        q_e[p] = qe
        for i in range(N):
            Fp[p, i] -= qe * (h * i)
    return a_out, g, dg, Fp, q_e, rf_min


@njit(cache=True, error_model="numpy", inline="always")
def _cell(x, N, inv):
    """(interval k, fraction s in [0, 1)) of angle x (rad) on the uniform periodic grid of
    N points, spacing 1 / ``inv`` (``kernels.hermite_rows``' interval rule)."""
    u = x * inv
    kf = np.floor(u)
    return int(kf) % N, u - kf


@njit(cache=True, error_model="numpy", inline="always")
def _cubic(y, dy, p, k, N, h, s, sub):
    """Value at fraction s of interval k of row p's periodic Hermite table through values
    ``y`` and slopes ``dy`` - ``sub`` (``kernels.hermite_rows``' value, its interval
    already found)."""
    k1 = 0 if k == N - 1 else k + 1
    s2 = s * s
    s3 = s2 * s
    y0 = y[p, k]
    return (y0 + (2 * s3 - 3 * s2) * (y0 - y[p, k1]) + (s3 - 2 * s2 + s) * ((dy[p, k] - sub) * h)
            + (s3 - s2) * ((dy[p, k1] - sub) * h))


@njit(cache=True, error_model="numpy", inline="always")
def _cubic_slope(y, dy, p, k, N, h, s):
    """(value, slope) at fraction s of interval k of row p's periodic Hermite table
    through values ``y`` and slopes ``dy`` (``kernels.hermite_rows``, its interval already
    found)."""
    k1 = 0 if k == N - 1 else k + 1
    s2 = s * s
    s3 = s2 * s
    y0 = y[p, k]
    dyy = y0 - y[p, k1]
    d0 = dy[p, k] * h
    d1 = dy[p, k1] * h
    value = y0 + (2 * s3 - 3 * s2) * dyy + (s3 - 2 * s2 + s) * d0 + (s3 - s2) * d1
    slope = ((6 * s2 - 6 * s) * dyy + (3 * s2 - 4 * s + 1) * d0 + (3 * s2 - 2 * s) * d1) / h
    return value, slope


@njit(cache=True, error_model="numpy", inline="always")
def _invert_cell(Fp, g, p, qp, F, N, h, k_last, last, walk):
    """(k, s, whole turns w, remainder) with Fp(theta) + q theta = F at theta = (k + s) h +
    2 pi w: the interval of the table Fp + q theta_k (the last k with table[k] <=
    remainder, the k of ``kernels.invert_rows``: galloped from the previous target's, 1,
    2, 4 ... cells, then bisected; bisected when not ``walk``), its linear inverse, then
    Newton on that interval's cubic in s (no interval search per step; up to 4 steps,
    stopped after a step below 1e-8: Newton's error is then below (h g' / 2 g) 1e-16,
    i.e. s to the last bit; 2 steps on the bundled grids)."""
    period = 2.0 * np.pi * qp
    w = np.floor(F / period)
    yv = F - w * period
    lo, hi = 0, N
    if walk and yv >= last:  # table[k_last] <= yv: gallop up (1, 2, 4 ... cells)
        lo = k_last
        step = 1
        while lo + step < N and Fp[p, lo + step] + qp * ((lo + step) * h) <= yv:
            lo += step
            step *= 2
        hi = min(lo + step, N)
    elif walk:  # table[k_last + 1] > yv: gallop down
        hi = k_last + 1
        step = 1
        while hi - step > 0 and Fp[p, hi - step] + qp * ((hi - step) * h) > yv:
            hi -= step
            step *= 2
        lo = max(hi - step, 0)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if Fp[p, mid] + qp * (mid * h) <= yv:
            lo = mid
        else:
            hi = mid
    k = lo
    k1 = 0 if k == N - 1 else k + 1
    y0 = Fp[p, k]
    dyy = y0 - Fp[p, k1]
    d0 = (g[p, k] - qp) * h
    d1 = (g[p, k1] - qp) * h
    base = qp * (k * h)
    qh = qp * h
    f0 = y0 + base
    f1 = Fp[p, k1] + qp * ((k + 1) * h)
    s = (yv - f0) / (f1 - f0 if f1 > f0 else 1.0)
    for _ in range(4):
        s2 = s * s
        s3 = s2 * s
        val = (y0 + (2 * s3 - 3 * s2) * dyy + (s3 - 2 * s2 + s) * d0 + (s3 - s2) * d1
               + base + qh * s)
        der = (6 * s2 - 6 * s) * dyy + (3 * s2 - 4 * s + 1) * d0 + (3 * s2 - 2 * s) * d1 + qh
        step = (val - yv) / der
        s -= step
        if abs(step) <= 1e-8:  # quadratic: the next step would be below 1e-16
            break
    return k, s, w, yv


@njit(cache=True, error_model="numpy", nogil=True)
def chain_tips(Fp, g, dg, q_e, delta, given, eps_d, eps_f, sense, shift, derived,
               lock, width, tsense, dwell, sun0, sun_rate, carrier0, cs, arms, samples,
               shaft, arm_length, arm_angle, same_arms):
    """The tip motion of P trains from their K pairs' laws (tuples of K (P, N) tables
    ``Fp``, ``g``, ``dg``; ``q_e``, ``delta`` (K, P)): per design, arm and carrier
    sample the chain of ``trains.model.simulate`` (its module docstring) walked once, pair
    by pair: the sun's body angle sun0 + sun_rate psi - cs 2 pi j / J (rate ``sun_rate``),
    a compound driver turned by ``shift`` (K, P), a derived one (``derived`` (K,) True)
    phased so it starts at ``shift`` at arm 0's first sample; pair 0's toothless dwell
    (``dwell``: lock, width (P,), ``tsense``) squeezes its toothless arcs out; a pair whose
    follower is ``given`` inverts its law (``_invert_cell``: the interval walked from the
    previous sample's, Newton on its cubic), else reads it forward (one interval lookup for
    F and g). ``same_arms`` (a fixed sun, samples a multiple of the arms): arm j at psi is
    arm 1 at psi + 2 pi j / J, so arm 1 is walked (one sample more: its arm angle a turn
    on) and the others copied, the arm angle a turn on past 2 pi. The carrier's direction
    exp(i cs (psi + 2 pi j / J)) is tabulated once for every design (turned by each
    design's start), the arm's exp(i beta) that times exp(i (planet body angle + arm
    offset)): one sin/cos pair per sample. Returns (tip, tip rate d tip / d psi (complex
    (P, J, S)), arm angle beta, its rate (P, J, S), the planet's centre (complex
    (P, J, S)))."""
    K = len(Fp)
    P, N = Fp[0].shape
    h = 2.0 * np.pi / N
    inv = 1.0 / h
    two_pi = 2.0 * np.pi
    tip = np.empty((P, arms, samples), dtype=np.complex128)
    tip_rate = np.empty((P, arms, samples), dtype=np.complex128)
    centre_out = np.empty((P, arms, samples), dtype=np.complex128)
    beta_out = np.empty((P, arms, samples))
    rate_out = np.empty((P, arms, samples))
    start = np.empty(K)
    k_last = np.zeros(K, dtype=np.int64)
    y_last = np.zeros(K)
    walked = 1 if same_arms else arms
    S1 = samples + (1 if same_arms else 0)
    turn = np.empty((walked, S1), dtype=np.complex128)  # exp(i cs (psi + off_j))
    for j in range(walked):
        for si in range(S1):
            x = cs * (two_pi * si / samples + two_pi * j / arms)
            turn[j, si] = complex(np.cos(x), np.sin(x))
    for p in range(P):
        planet0 = 0.0
        beta_end = 0.0
        c0 = carrier0[p]
        start_dir = complex(np.cos(c0), np.sin(c0))
        for j in range(walked):
            off = two_pi * j / arms
            for si in range(S1):
                psi = two_pi * si / samples
                alpha = sun0[p] + sun_rate * psi - cs * off
                rate = sun_rate
                for k in range(K):
                    if k > 0 and derived[k]:
                        if j == 0 and si == 0:
                            start[k] = alpha
                        alpha = alpha + (shift[k, p] - start[k])
                    elif k > 0:
                        alpha = alpha + shift[k, p]
                    am = alpha
                    if k == 0 and dwell:
                        t = tsense * (alpha - lock[p])
                        turns = np.floor(t / two_pi)
                        v = t - two_pi * turns
                        meshes = v >= width[p]
                        rolled = turns * (two_pi - width[p]) + (v - width[p] if meshes else 0.0)
                        am = lock[p] + tsense * rolled
                        if not meshes:
                            rate = 0.0
                    theta_d = delta[k, p] + eps_d[k] - am
                    qk = q_e[k, p]
                    if given[k]:
                        c, s, w, y_last[k] = _invert_cell(
                            Fp[k], g[k], p, qk, sense[k] * theta_d, N, h, k_last[k],
                            y_last[k], si > 0)
                        k_last[k] = c
                        theta_f = (c * h + h * s) + two_pi * w
                        if s < 0.0 or s >= 1.0:  # Newton stepped off its interval
                            c, s = _cell(theta_f, N, inv)
                        gv = _cubic(g[k], dg[k], p, c, N, h, s, 0.0)
                        rate = sense[k] * rate / gv
                    else:
                        c, s = _cell(theta_d, N, inv)
                        fp = _cubic(Fp[k], g[k], p, c, N, h, s, qk)
                        gv = _cubic(g[k], dg[k], p, c, N, h, s, 0.0)
                        theta_f = sense[k] * (fp + qk * theta_d)
                        rate = sense[k] * gv * rate
                    alpha = delta[k, p] + eps_f[k] - theta_f
                carrier = c0 + cs * (psi + off)
                cdir = start_dir * turn[j, si]
                centre = shaft[p] * cdir
                planet = carrier + alpha
                if j == 0 and si == 0:
                    planet0 = planet
                beta = planet + (arm_angle[p] - planet0)
                if si == samples:  # one turn on: the arm's whole turns per carrier turn
                    beta_end = beta
                    break
                body = alpha + (arm_angle[p] - planet0)
                e = cdir * complex(np.cos(body), np.sin(body))
                tip[p, j, si] = centre + arm_length[p] * e
                centre_out[p, j, si] = centre
                br = cs + rate
                tip_rate[p, j, si] = 1j * cs * centre + 1j * arm_length[p] * br * e
                beta_out[p, j, si] = beta
                rate_out[p, j, si] = br
        if same_arms:  # arm j at psi is arm 1 at psi + 2 pi j / J, a turn later past 2 pi
            turn_b = beta_end - beta_out[p, 0, 0]
            for j in range(1, arms):
                lag = samples * j // arms
                for si in range(samples):
                    src = si + lag
                    extra = 0.0
                    if src >= samples:
                        src -= samples
                        extra = turn_b
                    tip[p, j, si] = tip[p, 0, src]
                    tip_rate[p, j, si] = tip_rate[p, 0, src]
                    centre_out[p, j, si] = centre_out[p, 0, src]
                    beta_out[p, j, si] = beta_out[p, 0, src] + extra
                    rate_out[p, j, si] = rate_out[p, 0, src]
    return tip, tip_rate, beta_out, rate_out, centre_out


@njit(cache=True, error_model="numpy", nogil=True)
def mate_tables(Fp, g, q_e, r, dr, a, kappa, c, sense):
    """The follower's pitch curve (r_f, dr_f / dphi) (P, N) on its own uniform grid phi_i
    = 2 pi i / N of P closed laws (``pairs.PairLaw.mate``) in one pass per design: the
    contact's driver angle theta = F^-1(sense phi) (``_invert_cell``, walked along the
    grid), the driver's radius and slope there (its Hermite table ``r``, ``dr``, read in
    the interval the inverse found), r_f = kappa r +
    c a and its slope kappa r' / (sense g), g = r / r_f: PairLaw.mate's numbers."""
    P, N = Fp.shape
    h = 2.0 * np.pi / N
    inv = 1.0 / h
    rf_out = np.empty((P, N))
    slope_out = np.empty((P, N))
    for p in range(P):
        k_last, last = 0, 0.0
        qp = q_e[p]
        ca = c * a[p]
        for i in range(N):
            target = sense * (2.0 * np.pi * i / N)
            k_last, s, w, last = _invert_cell(Fp, g, p, qp, target, N, h, k_last, last,
                                              i > 0)
            k, u = k_last, s
            if u < 0.0 or u >= 1.0:  # Newton stepped off its interval
                k, u = _cell((k_last * h + h * s) + 2.0 * np.pi * w, N, inv)
            rd, drd = _cubic_slope(r, dr, p, k, N, h, u)
            rf = kappa * rd + ca
            gg = rd / rf
            rf_out[p, i] = rf
            slope_out[p, i] = kappa * drd / (sense * gg)
    return rf_out, slope_out
