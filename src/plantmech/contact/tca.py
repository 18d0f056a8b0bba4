"""Unloaded tooth-contact analysis of two gear outlines (closed polygons in mm).

Pose of a gear in a pair's mesh frame: centre c (mm) and rotation q (rad, counter-
clockwise, applied to its body-frame outline). The driver's pose is given at every step;
the driven gear turns about its fixed centre. Its free play at a step is the interval
[lo, hi] of extra rotations (rad, counter-clockwise, about the reference rotation) over
which the two outlines do not overlap; at lo and hi its teeth touch the driver's (one
flank direction each), hi - lo is the angular backlash.

Exact for polygons: a first contact under rotation is always a vertex of one outline
meeting an edge of the other. A vertex at radius rho about the driven centre travels on
the circle of that radius; its crossings with the other outline's edges (a quadratic in
the edge parameter) give the rotation to contact. Both directions (driven vertices on
driver edges, driver vertices on driven edges), vectorised over steps x vertices x
edges, restricted to the K vertices of each gear nearest the mesh zone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.contact.outlines import GearOutline

TWO_PI = 2.0 * np.pi


@dataclass
class FreePlay:
    """Free play of the driven gear over the steps (arrays (T,)): ``lo`` / ``hi`` extra
    rotation (rad, CCW) to contact, NaN where no contact within ``max_turn`` (contact
    lost on that flank); ``reference`` the extra rotation the analysis started from at
    each step (0 unless the reference pose overlapped); ``jammed`` no free rotation at
    all (interference that turning cannot clear); contact points on each flank: driven
    and driver body angles (rad) and tooth numbers; ``double_*`` a second tooth pair
    within ``double_tol`` (rad) of the first on that flank."""

    lo: np.ndarray
    hi: np.ndarray
    reference: np.ndarray
    overlapped: np.ndarray
    jammed: np.ndarray
    lo_driven_angle: np.ndarray
    hi_driven_angle: np.ndarray
    lo_driver_angle: np.ndarray
    hi_driver_angle: np.ndarray
    lo_driven_tooth: np.ndarray
    hi_driven_tooth: np.ndarray
    lo_driver_tooth: np.ndarray
    hi_driver_tooth: np.ndarray
    double_lo: np.ndarray
    double_hi: np.ndarray
    mesh_driven_angle: np.ndarray = None  # driven body angle facing the driver (rad)
    mesh_driven_tooth: np.ndarray = None  # its nearest tooth


def _rot(q):
    c, s = np.cos(q), np.sin(q)
    return c, s


def _to_driven_frame(xy, q_driver, c_driver, q_driven, c_driven):
    """Driver body points xy (T, K, 2) -> driven body frame for poses (T,)."""
    c1, s1 = _rot(q_driver)
    x = c1[:, None] * xy[..., 0] - s1[:, None] * xy[..., 1] + c_driver[0] - c_driven[0]
    y = s1[:, None] * xy[..., 0] + c1[:, None] * xy[..., 1] + c_driver[1] - c_driven[1]
    c2, s2 = _rot(-q_driven)
    return np.stack([c2[:, None] * x - s2[:, None] * y, s2[:, None] * x + c2[:, None] * y],
                    axis=-1)


def _nearest(ring: np.ndarray, point: np.ndarray, k: int, farthest: bool = False):
    """Indices (T, k) of the ring vertices nearest to (farthest from) points (T, 2)."""
    d = (ring[None, :, 0] - point[:, None, 0]) ** 2 + (ring[None, :, 1] - point[:, None, 1]) ** 2
    if farthest:
        d = -d
    k = min(k, ring.shape[0])
    return np.argpartition(d, k - 1, axis=1)[:, :k]


def _crossings(pts, s0, s1, max_turn: float | None = None):
    """Every (step, point, segment) where the circle about the origin through the point
    (t, P, 2) meets the segment s0 -> s1 (t, S, 2), and the rotation (rad, wrapped to
    (-pi, pi]) that brings the point there; with ``max_turn`` (rad) only the rotations
    up to that size (every caller discards the others). Candidates come from a sort of
    the points' radii against each segment's exact distance range (closest point to
    farthest end), so the work grows with the crossings, not with points x segments;
    with ``max_turn`` a candidate whose point lies farther than max_turn in polar angle
    from its segment's sector is dropped before the quadratic is solved (the crossing
    lies in that sector: exact, no crossing within max_turn is lost)."""
    t, npt, _ = pts.shape
    ns = s0.shape[1]
    rho = np.hypot(pts[..., 0], pts[..., 1])
    big = 2.0 * (float(np.max(rho)) + float(np.max(np.abs(s0))) + float(np.max(np.abs(s1)))
                 + 1.0)
    off = np.arange(t)[:, None] * big
    key = (rho + off).ravel()
    order = np.argsort(key, kind="stable")
    skey = key[order]
    d = s1 - s0
    dx, dy = d[..., 0], d[..., 1]
    x0, y0 = s0[..., 0], s0[..., 1]
    dd = dx * dx + dy * dy
    u0 = np.clip(-(x0 * dx + y0 * dy) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    near = np.hypot(x0 + u0 * dx, y0 + u0 * dy)
    far = np.maximum(np.hypot(x0, y0), np.hypot(s1[..., 0], s1[..., 1]))
    lo = np.searchsorted(skey, (near - 1e-12 + off).ravel(), side="left")
    hi = np.searchsorted(skey, (far + 1e-12 + off).ravel(), side="right")
    counts = hi - lo
    total = int(counts.sum())
    seg = np.repeat(np.arange(t * ns), counts)
    start = np.repeat(np.cumsum(counts) - counts, counts)
    flat_p = order[np.repeat(lo, counts) + np.arange(total) - start]
    if max_turn is not None:
        # a crossing lies between its segment's end angles (the polar angle along a
        # segment is monotone): only points within max_turn of that sector can reach it
        a0 = np.arctan2(y0, x0)
        half = 0.5 * (np.mod(np.arctan2(s1[..., 1], s1[..., 0]) - a0 + np.pi, 2 * np.pi)
                      - np.pi)
        mid = (a0 + half).ravel()
        reach = (np.abs(half) + (max_turn + 1e-9)).ravel()
        ang = np.arctan2(pts[..., 1], pts[..., 0]).ravel()
        gap = np.abs(np.mod(ang[flat_p] - mid[seg] + np.pi, 2 * np.pi) - np.pi)
        k = np.flatnonzero(gap <= reach[seg])
        seg, flat_p = seg[k], flat_p[k]
    ax, ay = x0.ravel()[seg], y0.ravel()[seg]
    vx, vy = dx.ravel()[seg], dy.ravel()[seg]
    a = dd.ravel()[seg]
    b = 2.0 * (ax * vx + ay * vy)
    c = ax * ax + ay * ay - rho.ravel()[flat_p] ** 2
    sq = np.sqrt(np.maximum(b * b - 4.0 * a * c, 0.0))
    a2 = np.where(a > 0, 2.0 * a, np.inf)
    pf = pts.reshape(-1, 2)
    out_seg, out_p, out_dq = [], [], []
    for sign in (-1.0, 1.0):
        u = (-b + sign * sq) / a2
        k = np.flatnonzero((u >= -1e-12) & (u <= 1.0 + 1e-12))
        uk = u[k]
        x = ax[k] + uk * vx[k]
        y = ay[k] + uk * vy[k]
        fp = flat_p[k]
        px, py = pf[fp, 0], pf[fp, 1]
        # the rotation from the point to the crossing (both at its radius), (-pi, pi]
        dq = np.arctan2(px * y - py * x, px * x + py * y)
        if max_turn is not None:
            k2 = np.flatnonzero(np.abs(dq) <= max_turn)
            dq, k, fp = dq[k2], k[k2], fp[k2]
        out_dq.append(dq)
        out_seg.append(seg[k])
        out_p.append(fp)
    sg, fp = np.concatenate(out_seg), np.concatenate(out_p)
    return sg // ns, fp % npt, sg % ns, np.concatenate(out_dq)


def _reduce(t, step, dq, tooth, side: int, max_turn: float, tol: float):
    """Per step: the smallest positive (side +1) or largest negative (side -1) rotation,
    the index of its crossing, and whether another driven tooth touches within tol."""
    v = dq * side
    ok = (v >= -1e-12) & (v <= max_turn)
    idx = np.flatnonzero(ok)
    best = np.full(t, np.inf)
    arg = np.full(t, -1)
    if len(idx):
        si, vi = step[idx], v[idx]
        np.minimum.at(best, si, vi)
        # the first crossing (in candidate order) at each step's smallest rotation
        hit = np.flatnonzero(vi == best[si])
        first_steps, first = np.unique(si[hit], return_index=True)
        arg[first_steps] = idx[hit[first]]
    best_tooth = np.where(arg >= 0, tooth[np.maximum(arg, 0)], -1)
    other = np.full(t, np.inf)
    sel = idx[tooth[idx] != best_tooth[step[idx]]]
    np.minimum.at(other, step[sel], v[sel])
    with np.errstate(invalid="ignore"):
        double = np.isfinite(best) & np.isfinite(other) & (other - best <= tol)
    return np.where(np.isfinite(best), side * best, np.nan), arg, double


def free_play(driven: GearOutline, driver: GearOutline, c_driven, c_driver, q_driven,
              q_driver, max_turn: float | None = None, window_pitches: float | None = None,
              double_tol: float = 1e-5, chunk: int = 90) -> FreePlay:
    """Free play of ``driven`` (centre c_driven, reference rotation q_driven (T,)) against
    ``driver`` (c_driver, q_driver (T,)); mm and rad. ``max_turn``: the largest rotation
    searched (default: 0.75 of the driven gear's mean tooth angle). ``window_pitches``:
    the vertices of each gear within that many of its tooth pitches either side of the
    mesh take part (default 2.5; 5 for an internal pair, whose teeth wrap round the
    planet: on the shipped transplanter 2.5 missed contacts, 4 and more gave identical
    results). ``double_tol``: rad."""
    c_n = np.asarray(c_driven, dtype=float)
    c_d = np.asarray(c_driver, dtype=float)
    q_n = np.asarray(q_driven, dtype=float)
    q_d = np.broadcast_to(np.asarray(q_driver, dtype=float), q_n.shape)
    T = len(q_n)
    if max_turn is None:
        max_turn = 0.75 * TWO_PI / max(driven.teeth, 1)
    if window_pitches is None:
        window_pitches = 5.0 if (driver.internal or driven.internal) else 2.5
    kn = int(np.ceil(2 * window_pitches * len(driven.ring) / driven.teeth))
    kd = int(np.ceil(2 * window_pitches * len(driver.ring) / driver.teeth))
    ring_n, ring_d = driven.ring, driver.ring
    nn, nd = len(ring_n), len(ring_d)
    ref = np.zeros(T)
    overlapped = np.zeros(T, dtype=bool)
    jammed = np.zeros(T, dtype=bool)
    poly_n, poly_d = _prepared(driven), _prepared(driver)
    mesh = np.zeros(T)
    res = {key: np.full(T, np.nan) for key in ("lo", "hi", "lon", "hin", "lod", "hid")}
    dbl = {"lo": np.zeros(T, dtype=bool), "hi": np.zeros(T, dtype=bool)}
    for s in range(0, T, chunk):
        sl = slice(s, min(T, s + chunk))
        qd = q_d[sl]
        t = len(qd)
        # centres in each other's body frames (the mesh zone)
        cd_in_n = _to_driven_frame(np.zeros((t, 1, 2)), qd, c_d, q_n[sl], c_n)[:, 0]
        cn_in_d = _to_driven_frame(np.zeros((t, 1, 2)), q_n[sl], c_n, qd, c_d)[:, 0]
        mesh[sl] = np.arctan2(cd_in_n[:, 1], cd_in_n[:, 0]) + (np.pi if driver.internal
                                                               else 0.0)
        # the planet inside a ring: its teeth in mesh face away from the ring's centre
        vn = _nearest(ring_n, cd_in_n, kn, farthest=driver.internal)
        vd = _nearest(ring_d, cn_in_d, kd, farthest=driven.internal)
        pn = ring_n[vn]                      # driven vertices, driven frame
        en1 = ring_n[(vn + 1) % nn]          # driven edges vn -> vn + 1
        # a reference pose where the outlines overlap: start from the nearest free turn
        reach = (driven._reach, driver._reach)
        in_n, in_d = _inside(pn, ring_d[vd], q_n[sl], c_n, qd, c_d, poly_n, poly_d, *reach)
        bad = in_n.any(axis=1) | in_d.any(axis=1)
        overlapped[sl] = bad
        if bad.any():
            rows = np.flatnonzero(bad)
            off, jam = _free_offsets(rows, pn, en1, ring_d, vd, q_n[sl], qd, c_n, c_d,
                                     max_turn, poly_n, poly_d, reach, in_n[rows], in_d[rows])
            ref[s + np.flatnonzero(bad)] = off
            jammed[s + np.flatnonzero(bad)] = jam
        qn = q_n[sl] + ref[sl]
        pd = _to_driven_frame(ring_d[vd], qd, c_d, qn, c_n)
        ed1 = _to_driven_frame(ring_d[(vd + 1) % nd], qd, c_d, qn, c_n)
        # (a) driven vertices onto driver edges: the driven turns by dq
        sa, pa, _, qa = _crossings(pn, pd, ed1, max_turn)
        # (b) driver vertices onto driven edges: the driven turns by -dq
        sb, pb, eb, qb = _crossings(pd, pn, en1, max_turn)
        step = np.r_[sa, sb]
        dq = np.r_[qa, -qb]
        if not len(step):  # no contact within +-max_turn at any step of the chunk: no
            continue       # play is found there (NaN: contact lost; gears of another train)
        kind_a = np.r_[np.ones(len(sa), bool), np.zeros(len(sb), bool)]
        vert = np.r_[pa, pb]
        tooth = np.r_[driven.tooth_of_vertex[vn[sa, pa]], driven.tooth_of_vertex[vn[sb, eb]]]
        for key, side in (("lo", -1), ("hi", 1)):
            val, k, double = _reduce(t, step, dq, tooth, side, max_turn, double_tol)
            res[key][sl] = val + ref[sl]
            dbl[key][sl] = double
            ang_n, ang_d = _contact_angles(k, kind_a, vert, pn, pd, vd, ring_d, val, qd, c_d,
                                           qn, c_n)
            res[key + "n"][sl] = ang_n
            res[key + "d"][sl] = ang_d
    lo, hi = res["lo"], res["hi"]
    lo[jammed] = np.nan
    hi[jammed] = np.nan

    def teeth_of(gear, ang):
        out = np.zeros(T, dtype=int)
        ok = np.isfinite(ang)
        out[ok] = gear.tooth_at(ang[ok])
        return out

    return FreePlay(lo, hi, ref, overlapped, jammed, res["lon"], res["hin"], res["lod"],
                    res["hid"], teeth_of(driven, res["lon"]), teeth_of(driven, res["hin"]),
                    teeth_of(driver, res["lod"]), teeth_of(driver, res["hid"]),
                    dbl["lo"], dbl["hi"], np.mod(mesh, TWO_PI), driven.tooth_at(mesh))


def _contact_angles(k, kind_a, vert, pn, pd, vd, ring_d, val, qd, c_d, qn, c_n):
    """Body angles (rad) of the contact point on the driven and the driver gear."""
    t = len(k)
    ang_n = np.full(t, np.nan)
    ang_d = np.full(t, np.nan)
    rows = np.arange(t)
    ok = np.isfinite(val) & (k >= 0)
    kk = np.maximum(k, 0)
    in_a = ok & kind_a[kk]
    if in_a.any():
        # a driven vertex touches: its own body angle; the driver's point: that vertex
        # with the driven turned by val, in the driver frame
        q = pn[rows[in_a], vert[kk[in_a]]]
        ang_n[in_a] = np.arctan2(q[:, 1], q[:, 0])
        x = _pose_point(q, val[in_a], qn[in_a], c_n, qd[in_a], c_d)
        ang_d[in_a] = np.arctan2(x[:, 1], x[:, 0])
    in_b = ok & ~kind_a[kk]
    if in_b.any():
        # a driver vertex touches: its own body angle; the driven's point: the driver
        # vertex in the driven frame, turned back by val
        j = vd[rows[in_b], vert[kk[in_b]]]
        ang_d[in_b] = np.arctan2(ring_d[j, 1], ring_d[j, 0])
        x = pd[rows[in_b], vert[kk[in_b]]]
        c, s = np.cos(-val[in_b]), np.sin(-val[in_b])
        ang_n[in_b] = np.arctan2(s * x[:, 0] + c * x[:, 1], c * x[:, 0] - s * x[:, 1])
    return np.mod(ang_n, TWO_PI), np.mod(ang_d, TWO_PI)


def _pose_point(q_body_n, extra, qn, c_n, qd, c_d):
    """A driven body point, the driven turned by ``extra`` -> driver body frame."""
    c, s = np.cos(qn + extra), np.sin(qn + extra)
    x = c * q_body_n[:, 0] - s * q_body_n[:, 1] + c_n[0] - c_d[0]
    y = s * q_body_n[:, 0] + c * q_body_n[:, 1] + c_n[1] - c_d[1]
    c2, s2 = np.cos(-qd), np.sin(-qd)
    return np.c_[c2 * x - s2 * y, s2 * x + c2 * y]


def _free_offsets(rows, pn, en1, ring_d, vd, q_n, q_d, c_n, c_d, max_turn, poly_n, poly_d,
                  reach, in_n, in_d):
    """For steps whose reference pose overlaps: the free extra rotation nearest to it
    (rad) and whether there is none (jammed).

    A window vertex's inside/outside status (against the other gear) changes only where
    its circle about the driven centre crosses one of the other gear's edges, so from its
    status at the reference (``in_n`` (R, Kn): driven vertices inside the driver, ``in_d``
    (R, Kd): driver vertices inside the driven gear) the number of vertices inside is known
    between any two consecutive crossing rotations (a parity sweep, vectorised over steps
    and vertices). The candidates are the midpoints between consecutive crossings within
    +-max_turn (no free interval is missed, however narrow); the free one nearest to the
    reference is taken and confirmed by a point-in-polygon test of every window vertex.
    No free midpoint: jammed, once each midpoint has a witness (a vertex the sweep holds
    inside there, found strictly inside by point-in-polygon: the overlap is proven). A
    pick the test does not confirm, or a midpoint without a proven witness (a vertex
    whose status changes on an edge outside the window: an internal gear's teeth wrap
    round the planet beyond it) sends the step to the midpoint search
    (``_free_offsets_search``, which tests the same midpoints nearest first): the
    result is the search's in every case; the sweep saves testing the candidates one by
    one (checked identical on the Table 4 train and the tests' cases)."""
    nd = len(ring_d)
    n = len(rows)
    kn = in_n.shape[1]
    qn, qd = q_n[rows], q_d[rows]
    pd = _to_driven_frame(ring_d[vd[rows]], qd, c_d, qn, c_n)
    ed = _to_driven_frame(ring_d[(vd[rows] + 1) % nd], qd, c_d, qn, c_n)
    sa, pa, _, qa = _crossings(pn[rows], pd, ed, max_turn)
    sb, pb, _, qb = _crossings(pd, pn[rows], en1[rows], max_turn)
    st = np.r_[sa, sb]
    vid = np.r_[pa, kn + pb]  # vertex id within a step: driven 0..kn-1, driver kn..
    dq = np.r_[qa, -qb]
    keep = np.abs(dq) <= max_turn
    st, vid, dq = st[keep], vid[keep], dq[keep]
    status0 = np.c_[in_n, in_d]  # (n, kn + kd) inside at the reference
    # each vertex's status at -max_turn: its reference status flipped once per crossing
    # between -max_turn and 0
    neg = np.zeros(status0.shape, dtype=int)
    np.add.at(neg, (st[dq < 0], vid[dq < 0]), 1)
    low = status0 ^ (neg % 2 == 1)
    # sweep upwards: per vertex, its k-th crossing (k = 0, 1, ..) leaves it inside when
    # low xor (k + 1 odd)
    order = np.lexsort((dq, vid, st))
    st_v, vid_v = st[order], vid[order]
    first = np.r_[True, (st_v[1:] != st_v[:-1]) | (vid_v[1:] != vid_v[:-1])]
    start = np.maximum.accumulate(np.where(first, np.arange(len(order)), 0))
    k = np.arange(len(order)) - start
    after = low[st_v, vid_v] ^ (k % 2 == 0)
    delta = np.empty(len(order), dtype=int)
    delta[order] = np.where(after, 1, -1)
    # all events of a step in rotation order, the sentinels +-max_turn around them
    st_e = np.r_[st, np.arange(n), np.arange(n)]
    dq_e = np.r_[dq, np.full(n, -max_turn), np.full(n, max_turn)]
    de = np.r_[delta, low.sum(axis=1), np.zeros(n, dtype=int)]
    o = np.lexsort((dq_e, st_e))
    st_e, dq_e, de = st_e[o], dq_e[o], de[o]
    # the -max_turn sentinel sorts first in its step and carries the count there
    count = np.cumsum(de)
    step_first = np.r_[True, st_e[1:] != st_e[:-1]]
    base = np.maximum.accumulate(np.where(step_first, np.arange(len(st_e)), 0))
    count = count - np.r_[0, count][base]  # per-step running count (sentinel included)
    same = st_e[1:] == st_e[:-1]
    gap = (dq_e[1:] - dq_e[:-1]) > 1e-12
    free = same & gap & (count[:-1] == 0)
    mid = 0.5 * (dq_e[1:] + dq_e[:-1])[free]
    ms = st_e[1:][free]
    off = np.zeros(n)
    found = np.zeros(n, dtype=bool)
    if len(ms):
        o = np.lexsort((np.abs(mid), ms))
        mid, ms = mid[o], ms[o]
        best = np.r_[True, ms[1:] != ms[:-1]]
        off[ms[best]] = mid[best]
        found[ms[best]] = True
    ok = found.copy()
    if found.any():
        f = np.flatnonzero(found)
        ok[f] = ~_overlap(pn[rows][f], ring_d[vd[rows]][f], qn[f] + off[f], c_n, qd[f], c_d,
                          poly_n, poly_d, *reach)
    # no free midpoint: jammed, once every midpoint's overlap is proven by a witness (a
    # vertex the sweep holds inside, found strictly inside by point-in-polygon)
    jam = ~found
    if jam.any():
        proven = np.zeros(n, dtype=bool)
        proven[jam] = _witnessed(np.flatnonzero(jam), st_e, dq_e, count, st, vid, dq,
                                 order, low, after, max_turn, pn[rows], pd, kn, qn, c_n, qd,
                                 c_d, poly_n, poly_d)
        ok |= jam & proven
        jam &= proven
    redo = np.flatnonzero(~ok)
    if len(redo):
        o2, j2 = _free_offsets_search(rows[redo], pn, en1, ring_d, vd, q_n, q_d, c_n, c_d,
                                      max_turn, poly_n, poly_d, reach)
        off[redo], jam[redo] = o2, j2
    return off, jam


def _witnessed(steps, st_e, dq_e, count, st, vid, dq, order, low, after, max_turn, pn, pd,
               kn, qn, c_n, qd, c_d, poly_n, poly_d) -> np.ndarray:
    """For the sweep's steps ``steps`` that it finds jammed: whether the overlap at every
    candidate midpoint is proven by a witness, a vertex the sweep holds inside there
    that point-in-polygon finds strictly inside the other gear (one test per midpoint).
    A vertex is held inside over intervals of rotation: from -max_turn to its first
    crossing when inside there (``low``), and from each crossing after which it is inside
    (``after``, in ``order``) to its next crossing or +max_turn."""
    import shapely

    n = len(low)
    # inside intervals of every vertex
    st_o, vid_o, dq_o = st[order], vid[order], dq[order]
    m = len(st_o)  # no crossing at all: every array below is empty (np.r_ would add one)
    last = np.r_[(st_o[1:] != st_o[:-1]) | (vid_o[1:] != vid_o[:-1]), True][:m]
    nxt = np.where(last, max_turn, np.r_[dq_o[1:], max_turn][:m])
    first = np.r_[True, last[:-1]][:m]
    s_low, v_low = np.nonzero(low)
    first_dq = np.full(low.shape, max_turn)
    first_dq[st_o[first], vid_o[first]] = dq_o[first]
    iv_s = np.r_[st_o[after], s_low]
    iv_v = np.r_[vid_o[after], v_low]
    iv_0 = np.r_[dq_o[after], np.full(len(s_low), -max_turn)]
    iv_1 = np.r_[nxt[after], first_dq[s_low, v_low]]
    # the midpoints to prove: between consecutive events of a jammed step
    want = np.zeros(n, dtype=bool)
    want[steps] = True
    same = st_e[1:] == st_e[:-1]
    gap = (dq_e[1:] - dq_e[:-1]) > 1e-12
    pick = same & gap & want[st_e[1:]]
    m_s = st_e[1:][pick]
    m_x = 0.5 * (dq_e[1:] + dq_e[:-1])[pick]
    proven = want.copy()
    if len(iv_s) == 0:
        proven[m_s] = False
        return proven[steps]
    # an interval covering each midpoint: sorted by (step, start), the running farthest
    # end (keys offset per step so steps never mix)
    big = 4.0 * max_turn + 1.0
    o = np.lexsort((iv_0, iv_s))
    k0 = iv_0[o] + iv_s[o] * big
    k1 = iv_1[o] + iv_s[o] * big
    run = np.maximum.accumulate(k1)
    arg = np.maximum.accumulate(np.where(k1 >= run, np.arange(len(k1)), 0))
    pos = np.searchsorted(k0, m_x + m_s * big, side="right") - 1
    w = o[arg[np.maximum(pos, 0)]]
    covered = (pos >= 0) & (iv_s[w] == m_s) & (iv_1[w] >= m_x) & (iv_0[w] <= m_x)
    proven[m_s[~covered]] = False
    # test each covered midpoint's witness
    ws, wv, wx = m_s[covered], iv_v[w[covered]], m_x[covered]
    hit = np.zeros(len(ws), dtype=bool)
    a = wv < kn
    if a.any():  # a driven vertex, the driven gear turned by x: in the driver's frame
        p = pn[ws[a], wv[a]][:, None, :]
        x = _to_driven_frame(p, qn[ws[a]] + wx[a], c_n, qd[ws[a]], c_d)[:, 0]
        hit[a] = shapely.contains_xy(poly_d, x[:, 0], x[:, 1])
    b = ~a
    if b.any():  # a driver vertex (driven frame) seen from the driven gear turned by x
        p = pd[ws[b], wv[b] - kn]
        c, sn = np.cos(-wx[b]), np.sin(-wx[b])
        x = np.c_[c * p[:, 0] - sn * p[:, 1], sn * p[:, 0] + c * p[:, 1]]
        hit[b] = shapely.contains_xy(poly_n, x[:, 0], x[:, 1])
    proven[ws[~hit]] = False
    return proven[steps]


def _free_offsets_search(rows, pn, en1, ring_d, vd, q_n, q_d, c_n, c_d, max_turn, poly_n,
                         poly_d, reach, candidates: int = 48):
    """For steps whose reference pose overlaps: the free extra rotation nearest to it
    (rad) and whether there is none (jammed). The overlap status can only change where a
    vertex crosses an edge, so the candidates are the midpoints between consecutive
    crossing rotations (exact: no free interval is missed, however narrow), nearest
    first, tested at once."""
    nd = len(ring_d)
    qn, qd = q_n[rows], q_d[rows]
    pd = _to_driven_frame(ring_d[vd[rows]], qd, c_d, qn, c_n)
    ed = _to_driven_frame(ring_d[(vd[rows] + 1) % nd], qd, c_d, qn, c_n)
    sa, _, _, qa = _crossings(pn[rows], pd, ed, max_turn)
    sb, _, _, qb = _crossings(pd, pn[rows], en1[rows], max_turn)
    n = len(rows)
    st = np.r_[sa, sb, np.arange(n), np.arange(n)]
    dq = np.r_[qa, -qb, np.full(n, -max_turn), np.full(n, max_turn)]
    keep = np.abs(dq) <= max_turn
    st, dq = st[keep], dq[keep]
    order = np.lexsort((dq, st))
    st, dq = st[order], dq[order]
    same = st[1:] == st[:-1]
    mid = 0.5 * (dq[1:] + dq[:-1])[same]
    ms = st[1:][same]
    gap = (dq[1:] - dq[:-1])[same] > 1e-12
    mid, ms = mid[gap], ms[gap]
    # nearest ``candidates`` midpoints of each step
    order = np.lexsort((np.abs(mid), ms))
    mid, ms = mid[order], ms[order]
    first = np.r_[0, np.flatnonzero(np.diff(ms)) + 1]
    rank = np.arange(len(ms)) - np.repeat(first, np.diff(np.r_[first, len(ms)]))
    off = np.zeros(n)
    jam = np.ones(n, dtype=bool)
    # nearest first, in batches of ``candidates`` per step, until every step is resolved
    for r0 in range(0, int(rank.max()) + 1 if len(rank) else 0, candidates):
        pick = (rank >= r0) & (rank < r0 + candidates) & jam[ms]
        if not pick.any():
            break
        m_, s_ = mid[pick], ms[pick]
        free = ~_overlap(pn[rows][s_], ring_d[vd[rows]][s_], qn[s_] + m_, c_n, qd[s_], c_d,
                         poly_n, poly_d, *reach)
        idx = np.flatnonzero(free)
        if len(idx):
            firsts = idx[np.r_[True, s_[idx][1:] != s_[idx][:-1]]]  # nearest free per step
            off[s_[firsts]] = m_[firsts]
            jam[s_[firsts]] = False
    return off, jam


def _prepared(gear: GearOutline):
    import shapely

    if getattr(gear, "_poly", None) is None:
        gear._poly = gear.polygon()
        shapely.prepare(gear._poly)
        gear._reach = float(max(np.hypot(*r.T).max() for r in gear.rings)) + 1e-9
    return gear._poly


def _inside(pn, pd_body, q_n, c_n, q_d, c_d, poly_n, poly_d, reach_n, reach_d):
    """Which window vertices lie strictly inside the other gear: driven vertices pn
    (T, Kn, 2, driven frame) inside the driver, (T, Kn); driver vertices pd_body (T, Kd, 2,
    driver frame) inside the driven gear, (T, Kd); at the poses q_n, q_d (T,)."""
    import shapely

    in_d = _to_driven_frame(pn, q_n, c_n, q_d, c_d)  # driven vertices -> driver frame
    in_n = _to_driven_frame(pd_body, q_d, c_d, q_n, c_n)
    out = []
    for pts, poly, reach in ((in_d, poly_d, reach_d), (in_n, poly_n, reach_n)):
        hit = np.zeros(pts.shape[:2], dtype=bool)
        # only points within the other gear's reach can lie inside it
        near = np.einsum("tkc,tkc->tk", pts, pts) < reach * reach
        if near.any():
            hit[near] = shapely.contains_xy(poly, pts[near][:, 0], pts[near][:, 1])
        out.append(hit)
    return out[0], out[1]


def _overlap(pn, pd_body, q_n, c_n, q_d, c_d, poly_n, poly_d, reach_n, reach_d) -> np.ndarray:
    """Whether a window vertex of either gear lies strictly inside the other gear (T,):
    driven vertices pn (T, K, 2, driven frame), driver vertices pd_body (T, K, 2, driver
    frame) at the poses q_n, q_d (T,)."""
    a, b = _inside(pn, pd_body, q_n, c_n, q_d, c_d, poly_n, poly_d, reach_n, reach_d)
    return a.any(axis=1) | b.any(axis=1)
