"""Clearance between rigidly moving polygons, vectorised over designs and samples (numpy).

Polygons are complex vertex arrays (..., K): x + i y in mm, closed implicitly (the last
vertex joins the first), simple (no edge crosses another), either orientation. The
clearance of two closed polygons (boundary and inside) is the smallest distance between
them, and -1 where they overlap or touch (the convention of the transplanter's
interference objectives (i), (ii) of seed 001).

``smallest_clearance`` is the population kernel: the smallest clearance over every
sample of every design, exact, with a cheap lower bound (the distance between the two
polygons' bounding capsules) that leaves the exact polygon distance to the few samples
that can still be the smallest.
"""

from __future__ import annotations

import numba
import numpy as np


def bounding_capsule(z):
    """The capsule (segment c0-c1 and radius r, mm) along the principal axis of the
    vertices z (..., K) that holds the polygon: (c0, c1, r) of shapes (...)."""
    m = z.mean(axis=-1, keepdims=True)
    w = z - m
    s = (w * w).sum(axis=-1, keepdims=True)  # its half angle: the principal direction
    d = np.where(np.abs(s) > 0, np.sqrt(s / np.where(np.abs(s) > 0, np.abs(s), 1.0)), 1.0)
    loc = w * np.conj(d)
    c0 = (m + d * loc.real.min(axis=-1, keepdims=True))[..., 0]
    c1 = (m + d * loc.real.max(axis=-1, keepdims=True))[..., 0]
    return c0, c1, np.abs(loc.imag).max(axis=-1)


def smallest_clearance(pairs, pose_a, pose_b):
    """Smallest clearance (mm, (P,)) over M poses and over polygon pairs (a, b), every a
    carried by pose_a and every b by pose_b: world = rot * z + shift.

    pairs: [(a, b), ...], a (P or 1, Ka), b (P or 1, Kb): vertices in their own frames
    (complex); pose_a, pose_b: (rot, shift), complex arrays broadcasting to (P, M)
    (|rot| = 1; a fixed polygon has rot 1, shift 0). -1 for a design where a pair
    overlaps or touches at some pose; NaN where a pose is not finite.

    Each polygon lies in a bounding capsule, and each capsule in a circle. The exact
    clearance is computed first at the pose where the circles' centres are nearest; the
    capsule bound (distance between the capsules) then at every pose whose circle bound
    is below it, the exact clearance at the pose of the smallest capsule bound, and at
    every pose whose capsule bound is below the smallest clearance so far. A pose skipped
    cannot be smaller, so the result equals the exact clearance at every pose, minimised.
    The loop over designs and poses is compiled (numba, cached): a polygon pair per pose
    is too small for numpy."""
    rot_a, shift_a = (np.asarray(v, complex) for v in pose_a)
    rot_b, shift_b = (np.asarray(v, complex) for v in pose_b)
    shape = np.broadcast_shapes(rot_a.shape, shift_a.shape, rot_b.shape, shift_b.shape)
    polys = [(np.atleast_2d(np.asarray(a, complex)), np.atleast_2d(np.asarray(b, complex)))
             for a, b in pairs]
    P = max([shape[0] if len(shape) == 2 else 1]
            + [max(a.shape[0], b.shape[0]) for a, b in polys])
    M = shape[-1] if shape else 1
    # b in the frame of a: z -> rel_rot z + rel_shift (once for every pair)
    back = np.conj(rot_a)
    rel_rot = np.ascontiguousarray(np.broadcast_to(rot_b * back, (P, M)))
    rel_shift = np.ascontiguousarray(np.broadcast_to((shift_b - shift_a) * back, (P, M)))
    best = np.full(P, np.inf)
    for a, b in polys:
        a0, a1, ra = bounding_capsule(a)
        b0, b1, rb = bounding_capsule(b)
        caps = np.ascontiguousarray(np.broadcast_to(
            np.stack(np.broadcast_arrays(a0, a1, b0, b1, ra + rb + 0j), axis=-1), (P, 5)))
        out = np.empty(P)
        _smallest_clearance(np.ascontiguousarray(np.broadcast_to(a, (P, a.shape[-1]))),
                            np.ascontiguousarray(np.broadcast_to(b, (P, b.shape[-1]))),
                            rel_rot, rel_shift, caps, out)
        best = np.minimum(best, out)
    return best


@numba.njit(cache=True)
def _clearance_one(ax, ay, bx, by):
    """polygon_clearance of one pair of polygons (vertex coordinate arrays)."""
    ka, kb = ax.shape[0], bx.shape[0]
    d2 = np.inf
    for i in range(ka):
        x0, y0 = ax[i], ay[i]
        x1, y1 = ax[(i + 1) % ka], ay[(i + 1) % ka]
        ex, ey = x1 - x0, y1 - y0
        ee = ex * ex + ey * ey
        for k in range(kb):
            u0, v0 = bx[k], by[k]
            u1, v1 = bx[(k + 1) % kb], by[(k + 1) % kb]
            # edges crossing
            c0 = (u1 - u0) * (y0 - v0) - (v1 - v0) * (x0 - u0)
            c1 = (u1 - u0) * (y1 - v0) - (v1 - v0) * (x1 - u0)
            c2 = ex * (v0 - y0) - ey * (u0 - x0)
            c3 = ex * (v1 - y0) - ey * (u1 - x0)
            if c0 * c1 < 0 and c2 * c3 < 0:
                return -1.0
            # vertex k of b to edge i of a
            wx, wy = u0 - x0, v0 - y0
            t = (wx * ex + wy * ey) / ee if ee > 0 else 0.0
            t = min(max(t, 0.0), 1.0)
            dx, dy = wx - t * ex, wy - t * ey
            d2 = min(d2, dx * dx + dy * dy)
            # vertex i of a to edge k of b
            fx, fy = u1 - u0, v1 - v0
            ff = fx * fx + fy * fy
            wx, wy = x0 - u0, y0 - v0
            t = (wx * fx + wy * fy) / ff if ff > 0 else 0.0
            t = min(max(t, 0.0), 1.0)
            dx, dy = wx - t * fx, wy - t * fy
            d2 = min(d2, dx * dx + dy * dy)
    if d2 == 0.0 or _inside_one(ax[0], ay[0], bx, by) or _inside_one(bx[0], by[0], ax, ay):
        return -1.0
    return np.sqrt(d2)


@numba.njit(cache=True)
def _inside_one(px, py, x, y):
    """Even-odd point-in-polygon test."""
    k = x.shape[0]
    inside = False
    for i in range(k):
        x0, y0, x1, y1 = x[i], y[i], x[(i + 1) % k], y[(i + 1) % k]
        if (y0 > py) != (y1 > py) and px < x0 + (py - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


@numba.njit(cache=True)
def _seg_seg(p0x, p0y, p1x, p1y, q0x, q0y, q1x, q1y):
    """Distance between two segments (0 where they cross)."""
    c0 = (q1x - q0x) * (p0y - q0y) - (q1y - q0y) * (p0x - q0x)
    c1 = (q1x - q0x) * (p1y - q0y) - (q1y - q0y) * (p1x - q0x)
    c2 = (p1x - p0x) * (q0y - p0y) - (p1y - p0y) * (q0x - p0x)
    c3 = (p1x - p0x) * (q1y - p0y) - (p1y - p0y) * (q1x - p0x)
    if c0 * c1 < 0 and c2 * c3 < 0:
        return 0.0
    d2 = min(min(_pt_seg2(p0x, p0y, q0x, q0y, q1x, q1y), _pt_seg2(p1x, p1y, q0x, q0y, q1x, q1y)),
             min(_pt_seg2(q0x, q0y, p0x, p0y, p1x, p1y), _pt_seg2(q1x, q1y, p0x, p0y, p1x, p1y)))
    return np.sqrt(d2)


@numba.njit(cache=True)
def _pt_seg2(px, py, ax, ay, bx, by):
    ex, ey = bx - ax, by - ay
    wx, wy = px - ax, py - ay
    ee = ex * ex + ey * ey
    t = (wx * ex + wy * ey) / ee if ee > 0 else 0.0
    t = min(max(t, 0.0), 1.0)
    dx, dy = wx - t * ex, wy - t * ey
    return dx * dx + dy * dy


@numba.njit(cache=True)
def _exact_at(ax, ay, b, bx, by, rr, sh):
    """Clearance of polygon (ax, ay) and polygon b placed at rr b + sh."""
    for k in range(b.shape[0]):
        z = rr * b[k] + sh
        bx[k], by[k] = z.real, z.imag
    return _clearance_one(ax, ay, bx, by)


@numba.njit(cache=True, nogil=True)
def _smallest_clearance(a, b, rel_rot, rel_shift, caps, out):
    P, M = rel_rot.shape
    ka, kb = a.shape[1], b.shape[1]
    ax, ay = np.empty(ka), np.empty(ka)
    bx, by = np.empty(kb), np.empty(kb)
    capsule = np.empty(M)
    for p in range(P):
        for i in range(ka):
            ax[i], ay[i] = a[p, i].real, a[p, i].imag
        bp = b[p]
        a0, a1, b0, b1, r = caps[p, 0], caps[p, 1], caps[p, 2], caps[p, 3], caps[p, 4].real
        # each capsule inside a circle: a bound cheaper still
        ca, cb = 0.5 * (a0 + a1), 0.5 * (b0 + b1)
        reach = 0.5 * (abs(a1 - a0) + abs(b1 - b0)) + r
        finite = True
        first, near = 0, np.inf
        for m in range(M):  # the pose where the circles are nearest
            g = rel_rot[p, m] * cb + rel_shift[p, m] - ca
            gap2 = g.real * g.real + g.imag * g.imag
            if not (np.isfinite(gap2) and np.isfinite(rel_rot[p, m])):
                finite = False
                break
            if gap2 < near:
                first, near = m, gap2
        if not finite:
            out[p] = np.nan
            continue
        best = _exact_at(ax, ay, bp, bx, by, rel_rot[p, first], rel_shift[p, first])
        # capsule bounds where the circles are nearer than that; the smallest one next
        second = first
        for m in range(M):
            capsule[m] = np.inf
            if m == first or best <= -1.0:
                continue
            rr, sh = rel_rot[p, m], rel_shift[p, m]
            g = rr * cb + sh - ca
            lim = best + reach  # circles apart by at least best: no smaller here
            if lim <= 0.0 or g.real * g.real + g.imag * g.imag >= lim * lim:
                continue
            q0, q1 = rr * b0 + sh, rr * b1 + sh
            capsule[m] = _seg_seg(a0.real, a0.imag, a1.real, a1.imag,
                                  q0.real, q0.imag, q1.real, q1.imag) - r
            if capsule[m] < capsule[second] or second == first:
                second = m
        if second != first and capsule[second] < best:
            best = min(best, _exact_at(ax, ay, bp, bx, by, rel_rot[p, second],
                                       rel_shift[p, second]))
            capsule[second] = np.inf
        # every other pose whose capsule bound is below the smallest so far
        for m in range(M):
            if best <= -1.0:
                break
            if capsule[m] < best:
                best = min(best, _exact_at(ax, ay, bp, bx, by, rel_rot[p, m], rel_shift[p, m]))
        out[p] = best
