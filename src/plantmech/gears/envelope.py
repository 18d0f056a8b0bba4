"""Teeth of non-circular gears by the envelope condition of the meshing equation (seed 001,
Eq. 11-18): the tool's flank in every generating position touches the gear's flank where
the flank's normal passes through the instant centre of the relative motion, the pitch
point P (the contact of the rolling pitch curves). For a rack (straight flanks at the
pressure angle alpha) this is closed form, so each tooth space of the gear is a handful of
curves evaluated at once over the space's generating positions:

- flanks: the foot of the perpendicular from P(s) onto the rack's flank line, for every
  rack position s (mm of arc) where that foot lies on the rack's straight flank
  (v = -w sin(alpha) cos(alpha), w the flank's offset along the pitch line);
- fillets: the trochoids the rack's two tip corners trace in the gear's frame;
- root: the envelope of the rack's tip line, the pitch curve offset by the dedendum h_f m.

Where the pitch curve is too sharply curved for the rack, the flank envelope has a cusp (its
regression point) and the tip corner's trochoid cuts into the flank above it: the flank is
undercut. Each space is therefore the union of two simple polygons, one bounded by the two
flank envelopes up to their cusps, one by the two fillet trochoids and the root; the gear
is the blank (the pitch curve grown by the addendum) less the Z spaces, a few dozen
polygons instead of the thousands of rack positions of a simulated cut (``teeth.cut_gear``
with ``method="simulated"``, kept as the reference).

Conventions as in teeth.py: a pitch curve is a counter-clockwise closed polyline (mm) about
its gear's centre; s is arc length (mm); n(s) the outward normal; the rack's coordinate
sigma (mm) along its pitch line sits at sigma - s from P(s) (rolling without slip); a rack
tooth (thickness on the pitch line pi m / 2 + backlash / 2) is centred at every space
centre c_k of the gear.
"""

from __future__ import annotations

import numpy as np

FLANK_POINTS = 40  # samples per flank (the involute-like flank is smooth: 40 keep it < 1 um)
FILLET_POINTS = 16  # samples per fillet trochoid
ROOT_POINTS = 6  # samples of the root between the fillets
TOP_MARGIN = 0.3  # flanks run this far (x module) beyond the addendum, out of the blank


def rack_space_polygons(pitch, spec, centres: np.ndarray):
    """The tooth spaces a rack (``spec``: module m, pressure angle alpha, addendum h_a,
    dedendum h_f, backlash) generates on ``pitch`` (teeth.PitchPolyline, convex: on a
    concave span the rack's other teeth would cut too, which this does not model), one per space
    centre of ``centres`` (K,) (mm of arc, the rack coordinate of the rack tooth that cuts
    it; may run past the perimeter: arcs are taken modulo it).

    Returns (flank_polygons (K,), fillet_polygons (K,)) as shapely arrays, each space the
    union of its two (module docstring), and ``cusped`` (K, 2) bool: the left / right flank
    envelope of the space has a cusp inside the blank (the rack undercuts it there)."""
    import shapely

    m, alpha = spec.module, spec.alpha
    half = (spec.pitch / 2 + spec.backlash_mm / 2) / 2  # rack tooth half thickness, pitch line
    hf, ha = spec.dedendum * m, (spec.addendum + TOP_MARGIN) * m
    sa, ca, ta = np.sin(alpha), np.cos(alpha), np.tan(alpha)
    sc = sa * ca
    c = np.asarray(centres, float)[:, None]  # (K, 1)
    K = len(c)
    # flanks, bottom (contact at the rack's tip corner, v = -h_f) to top (v = h_a + margin):
    # w = offset of the flank's pitch point from P along the tangent, v_Q = -/+ w sin cos
    f = np.linspace(0.0, 1.0, FLANK_POINTS)[None, :]
    w_right = hf / sc + f * (-ha / sc - hf / sc)  # v_Q = -w sc from -h_f to h_a
    s_right = c + half - w_right
    w_left = -hf / sc + f * (ha / sc + hf / sc)  # v_Q = +w sc
    s_left = c - half - w_left
    right = _foot(pitch, s_right, w_right * ca * ca, -w_right * sc)
    left = _foot(pitch, s_left, w_left * ca * ca, w_left * sc)
    # fillets: the tip corners (u = w -/+ h_f tan alpha, v = -h_f) from the flank's foot
    # (contact at the corner) to the root (corner on P's normal)
    g = np.linspace(0.0, 1.0, FILLET_POINTS)[None, :]
    wr = hf / sc + g * (hf * ta - hf / sc)
    fil_right = _foot(pitch, c + half - wr, wr - hf * ta, np.full_like(wr, -hf))
    wl = -hf / sc + g * (-hf * ta + hf / sc)
    fil_left = _foot(pitch, c - half - wl, wl + hf * ta, np.full_like(wl, -hf))
    h = np.linspace(0.0, 1.0, ROOT_POINTS)[None, :]
    s_root = c - half + hf * ta + h * (2 * half - 2 * hf * ta)
    root = _foot(pitch, s_root, np.zeros_like(s_root), np.full_like(s_root, -hf))
    # the flanks up to their cusps (where the envelope turns back: undercut)
    left_cut, cusp_l = _to_cusp(left[:, ::-1])  # top -> bottom
    right_cut, cusp_r = _to_cusp(right[:, ::-1])  # top -> bottom
    # each flank's top pushed out along the outward normal there, out of the blank
    _, _, n_l = pitch.at(s_left[:, -1])
    _, _, n_r = pitch.at(s_right[:, -1])
    out_l = left[:, -1] + 2 * m * n_l
    out_r = right[:, -1] + 2 * m * n_r
    flank_polys, fillet_polys = [], []
    for k in range(K):
        ring = np.vstack([out_l[k], left_cut[k], right_cut[k][::-1], out_r[k]])
        flank_polys.append(ring)
        fillet_polys.append(np.vstack([fil_left[k], root[k], fil_right[k][::-1]]))
    # (the flank rings differ in length where cusps cut them)
    flank = shapely.make_valid(np.array([shapely.Polygon(r) for r in flank_polys]))
    fillet = shapely.make_valid(np.array([shapely.Polygon(r) for r in fillet_polys]))
    # a cusp counts where it lies inside the blank (below the addendum curve)
    cusped = np.c_[cusp_l, cusp_r]
    return flank, fillet, cusped


def _foot(pitch, s, u, v):
    """Points (..., 2) at rack coordinates (u along the tangent, v along the outward
    normal, mm) about the pitch points P(s) (arrays of one shape)."""
    shape = np.shape(s)
    p, t, n = pitch.at(np.ravel(s))
    u = np.broadcast_to(u, shape).reshape(-1, 1)
    v = np.broadcast_to(v, shape).reshape(-1, 1)
    return (p + u * t + v * n).reshape(shape + (2,))


def _to_cusp(curves: np.ndarray):
    """Each curve of ``curves`` (K, N, 2) up to its first cusp: the first point after which
    the curve turns back (consecutive steps more than 90 deg apart). Returns a list of
    (N_k, 2) arrays and whether each had a cusp."""
    d = np.diff(curves, axis=1)
    back = np.einsum("kij,kij->ki", d[:, 1:], d[:, :-1]) < 0.0  # (K, N-2)
    has = back.any(axis=1)
    first = np.where(has, np.argmax(back, axis=1) + 2, curves.shape[1])
    return [curves[k, : first[k]] for k in range(len(curves))], has
