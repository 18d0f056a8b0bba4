"""Kernel (numba) of the mates' envelope (``envelope.mate_envelope_lines``): every root of
the meshing equation g(s) = n x (P(s) - x) = 0 (seed 001, Eq. 11-18: the normal of A's
outline at x passes through the pitch point P(s), at arc s of A's pitch curve, mm) for many
outline points at once, bracketed by sign changes on a grid of arc and refined by regula
falsi, in one pass per point without the (points x window) temporaries of the NumPy form.
Imported lazily: numba stays out of the CLI's start-up; its compilation is cached on disk
(``cache=True``). Lengths mm, arcs mm along A's pitch polyline.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def _mod(a, b):
    """np.mod(a, b) for b > 0 (fmod, then + b where negative)."""
    r = np.fmod(a, b)
    if r < 0.0:
        r += b
    return r


@njit(cache=True, error_model="numpy")
def _point_at(xy, seg, ln, cum, s):
    """The point of the closed polyline ``xy`` (N, 2) at arc ``s`` (mm), as
    ``teeth.PitchPolyline.at`` places it (segments ``seg``, lengths ``ln``, cumulative
    arc ``cum`` (N + 1,))."""
    n = ln.shape[0]
    s = _mod(s, cum[n])
    k = np.searchsorted(cum, s, side="right") - 1
    if k < 0:
        k = 0
    elif k > n - 1:
        k = n - 1
    f = (s - cum[k]) / ln[k]
    return xy[k, 0] + f * seg[k, 0], xy[k, 1] + f * seg[k, 1]


@njit(cache=True, error_model="numpy")
def _g_grid(x0, x1, n0, n1, Pg, i0, G, Ns, out):
    """g at the 2 G + 1 grid samples about grid index ``i0`` (a zero counted positive, as
    the bracketing treats it)."""
    for j in range(2 * G + 1):
        k = (i0 - G + j) % Ns
        g = n0 * (Pg[k, 1] - x1) - n1 * (Pg[k, 0] - x0)
        out[j] = 1e-300 if g == 0.0 else g


@njit(cache=True, error_model="numpy")
def mate_roots(x, n, i0, Pg, G, h, xy, refine):
    """Every root of g(s) = n x (P(s) - x) within ``G`` grid steps ``h`` (mm of arc) of
    each point: x, n (U, 2) A's outline points and outward normals, i0 (U,) the grid
    index nearest each point's own arc, Pg (Ns, 2) the pitch points at arcs k h, xy (N, 2)
    A's pitch polyline (the regula falsi's evaluations), ``refine`` regula falsi steps.
    Returns (point index (R,), root arc s (R,), mm), each point's roots in increasing
    arc."""
    U = x.shape[0]
    Ns = Pg.shape[0]
    N = xy.shape[0]
    seg = np.empty((N, 2))
    ln = np.empty(N)
    cum = np.empty(N + 1)
    cum[0] = 0.0
    for k in range(N):
        k1 = (k + 1) % N
        seg[k, 0] = xy[k1, 0] - xy[k, 0]
        seg[k, 1] = xy[k1, 1] - xy[k, 1]
        ln[k] = math.hypot(seg[k, 0], seg[k, 1])
        cum[k + 1] = cum[k] + ln[k]
    g = np.empty(2 * G + 1)
    count = np.zeros(U, np.int64)
    for u in range(U):
        _g_grid(x[u, 0], x[u, 1], n[u, 0], n[u, 1], Pg, i0[u], G, Ns, g)
        c = 0
        for j in range(2 * G):
            if (g[j] < 0.0) != (g[j + 1] < 0.0):
                c += 1
        count[u] = c
    R = int(count.sum())
    ui = np.empty(R, np.int64)
    sr = np.empty(R)
    r = 0
    for u in range(U):
        if count[u] == 0:
            continue
        x0, x1, n0, n1 = x[u, 0], x[u, 1], n[u, 0], n[u, 1]
        _g_grid(x0, x1, n0, n1, Pg, i0[u], G, Ns, g)
        for j in range(2 * G):
            if (g[j] < 0.0) == (g[j + 1] < 0.0):
                continue
            s_lo = (i0[u] + j - G) * h
            s_hi = s_lo + h
            g_lo, g_hi = g[j], g[j + 1]
            for _ in range(refine):
                s_m = s_lo - g_lo * (s_hi - s_lo) / (g_hi - g_lo)
                px, py = _point_at(xy, seg, ln, cum, s_m)
                g_m = n0 * (py - x1) - n1 * (px - x0)
                if (g_m < 0.0) == (g_lo < 0.0):
                    s_lo, g_lo = s_m, g_m
                else:
                    s_hi, g_hi = s_m, g_m
            ui[r] = u
            sr[r] = s_lo - g_lo * (s_hi - s_lo) / (g_hi - g_lo)
            r += 1
    return ui, sr


@njit(cache=True, error_model="numpy")
def _arc_gap(a, b, P):
    """|a - b| along a closed curve of perimeter ``P`` (mm)."""
    d = _mod(a - b + 0.5 * P, P) - 0.5 * P
    return -d if d < 0.0 else d


@njit(cache=True, error_model="numpy")
def _nearest(x, s_r, start, n, P):
    """(arc gap (mm), index k) of the nearest of the roots s_r[start:start + n] to arc
    ``x`` along a closed curve of perimeter ``P`` (the first of equals; (inf, -1) if n is
    0)."""
    best, bk = np.inf, -1
    for k in range(n):
        d = _arc_gap(x, s_r[start + k], P)
        if d < best:
            best, bk = d, k
    return best, bk


@njit(cache=True, error_model="numpy")
def mate_links(first, count, nxt, same, s_r, P, reach):
    """The links of ``envelope.mate_envelope_lines`` for one round: roots grouped by
    outline entry (entry u's roots are ``first[u]`` .. ``first[u] + count[u] - 1``, in
    increasing arc ``s_r``, mm); ``nxt`` (U,) the next entry along the outline, ``same``
    (U,) whether u links to it. Each root of u to the nearest root (in arc) of nxt[u] and
    back, when nearer than ``reach`` (mm); where the counts of u and nxt[u] differ (two
    roots merging at a tangency), consecutive roots of each of the two entries. Each link
    once. Returns (pairs (M, 2) of root indices, whether entry u's roots jumped by a count
    change (U,) bool)."""
    U = first.shape[0]
    Rm = 1
    for u in range(U):
        if count[u] > Rm:
            Rm = count[u]
    within = np.zeros(U, np.bool_)
    change = np.zeros(U, np.bool_)
    for u in range(U):
        if same[u] and count[u] != count[nxt[u]]:
            change[u] = True
            within[u] = True
            within[nxt[u]] = True
    # at most two links per root of u (forward and back) plus the within-entry links
    cap = 2 * int(count.sum()) + 1
    out = np.empty((cap, 2), np.int64)
    fwd = np.empty(Rm, np.int64)
    m = 0
    for u in range(U):
        if not same[u]:
            continue
        v = nxt[u]
        na, nb = count[u], count[v]
        if na == 0 or nb == 0:
            continue
        fa, fb = first[u], first[v]
        for i in range(na):
            best, bj = _nearest(s_r[fa + i], s_r, fb, nb, P)
            fwd[i] = bj if best < reach else -1
            if fwd[i] >= 0:
                out[m, 0], out[m, 1] = fa + i, fb + bj
                m += 1
        for j in range(nb):
            best, bi = _nearest(s_r[fb + j], s_r, fa, na, P)
            if best < reach and fwd[bi] != j:
                out[m, 0], out[m, 1] = fa + bi, fb + j
                m += 1
    pairs = np.empty((m + int(count.sum()), 2), np.int64)
    pairs[:m] = out[:m]
    for u in range(U):
        if within[u]:
            for i in range(count[u] - 1):
                pairs[m, 0], pairs[m, 1] = first[u] + i, first[u] + i + 1
                m += 1
    return pairs[:m], change


@njit(cache=True)
def link_chains(pairs, count):
    """The links ``pairs`` (M, 2) between ``count`` points joined into chains: walks from
    every point that is not an interior point of a curve (its degree is not 2), then round
    the closed loops left. Returns (point indices along the chains (K,), the chain of each
    (K,)), every link used once."""
    M = pairs.shape[0]
    deg = np.zeros(count, np.int64)
    for k in range(M):
        deg[pairs[k, 0]] += 1
        deg[pairs[k, 1]] += 1
    start = np.zeros(count + 1, np.int64)
    for i in range(count):
        start[i + 1] = start[i] + deg[i]
    fill = start[:-1].copy()
    adj = np.empty(2 * M, np.int64)  # (neighbour point, link) as link index
    for k in range(M):
        a, b = pairs[k, 0], pairs[k, 1]
        adj[fill[a]] = k
        fill[a] += 1
        adj[fill[b]] = k
        fill[b] += 1
    used = np.zeros(M, np.bool_)
    nodes = np.empty(2 * M, np.int64)
    line = np.empty(2 * M, np.int64)
    K = 0
    nl = 0
    for phase in range(2):
        for p0 in range(count):
            if phase == 0 and deg[p0] == 2:
                continue
            for e in range(start[p0], start[p0 + 1]):
                k = adj[e]
                if used[k]:
                    continue
                nodes[K], line[K] = p0, nl
                K += 1
                p = p0
                while True:
                    used[k] = True
                    p = pairs[k, 1] if pairs[k, 0] == p else pairs[k, 0]
                    nodes[K], line[K] = p, nl
                    K += 1
                    if deg[p] != 2:
                        break
                    nk = -1
                    for e2 in range(start[p], start[p + 1]):
                        if not used[adj[e2]]:
                            nk = adj[e2]
                    if nk < 0:
                        break
                    k = nk
                nl += 1
    return nodes[:K], line[:K]
