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

from dataclasses import dataclass

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


# --- shaper (pinion-shaped cutter) ---------------------------------------------------------
#
# The shaper's pitch circle (radius r_c = m z_c / 2) rolls without slip on the gear's pitch
# curve, so the instant centre of the relative motion is the contact P(s) and the envelope
# condition n . v_rel = 0 (seed 001, Eq. 11-18) says: the normal of the cutter's profile at
# the contact passes through P. In the cutter's own frame P runs round the pitch circle at
# a uniform rate (rolling without slip), at angle -/+ sigma / r_c (external / internal) when
# the cutter has rolled sigma (mm of arc) past the centre of the space it cuts. So for each
# point u of the cutter's profile (position x_c(u), outward normal n_c(u)) the motion
# parameters where it touches are where its normal line meets the pitch circle: closed form,
# two roots (lambda^2 + 2 lambda x.n + |x|^2 - r_c^2 = 0), the same for every gear. The
# envelope points are those profile points carried to the gear frame by the motion at their
# roots. Corners of the profile (the tip corners) are points whose normal sweeps the angle
# between the normals of the two pieces they join: their roots trace the fillet trochoids.

SHAPER_FLANK_POINTS = 60  # samples of each involute flank (roll angle)
SHAPER_CORNER_POINTS = 24  # normal directions swept at each tip corner
SHAPER_TIP_POINTS = 16  # samples of the tip arc
SHAPER_RADIAL_POINTS = 12  # samples of the radial flank below the base circle
SHAPER_CLASSIFY_STEPS = 1600  # cutter positions per window to classify arrangement faces
SHAPER_CHORD_TOL = 1e-3  # mm: the envelope's chords stay this close to the curve
SHAPER_REFINE_ROUNDS = 12  # halvings of the chain's parameter steps at most


class ShaperEnvelopeUnfit(Exception):
    """The envelope cannot stand for the shaper's cut here (the message says why): the gear
    is cut by simulation instead."""


@dataclass
class ShaperTooth:
    """One tooth of the shaper cutter in its own frame: centre at the origin, tooth centred
    on the +x axis. Module m (mm), ``zc`` teeth, pressure angle ``alpha`` (rad), tip radius
    ``ra`` = r_c + h_f m (the gear's dedendum: it cuts the gear's root), root radius ``rf``
    = r_c - (h_a + 0.05) m, tooth thickness ``thickness`` on the pitch circle (mm) =
    pi m / 2 + backlash / 2 (the gear's teeth thinner by half the backlash). The tip
    corners are sharp, as the simulated cutter's (teeth.involute_tooth)."""

    module: float
    zc: int
    alpha: float
    ra: float
    rf: float
    thickness: float

    @property
    def rc(self) -> float:
        return self.module * self.zc / 2

    @property
    def rb(self) -> float:
        return self.rc * np.cos(self.alpha)

    @property
    def half_pitch(self) -> float:
        return np.pi / self.zc

    def psi(self, r):
        """Half tooth angle (rad) of the involute flank at radius r (mm)."""
        a_r = np.arccos(np.clip(self.rb / np.asarray(r, float), -1.0, 1.0))
        return self.thickness / (2 * self.rc) + _inv(self.alpha) - _inv(a_r)

    def check(self) -> None:
        r0 = max(self.rb, self.rf)
        if self.psi(self.ra) <= 0:
            raise ShaperEnvelopeUnfit("the cutter's teeth are pointed (no tip land)")
        if self.psi(r0) >= self.half_pitch:
            raise ShaperEnvelopeUnfit("the cutter's teeth fill their pitch at the root")

    def pieces(self) -> int:
        """Number of pieces of the convex chain (``profile``)."""
        return 7 if self.rf < self.rb else 5

    def profile_parameters(self) -> np.ndarray:
        """A uniform start of the chain parameter (per piece: radial flank, involute,
        corner, tip, corner, involute, radial flank samples), [0, pieces]."""
        per = np.array([SHAPER_RADIAL_POINTS, SHAPER_FLANK_POINTS, SHAPER_CORNER_POINTS,
                        SHAPER_TIP_POINTS, SHAPER_CORNER_POINTS, SHAPER_FLANK_POINTS,
                        SHAPER_RADIAL_POINTS])
        if self.pieces() == 5:
            per = per[1:6]
        return np.concatenate([k + np.linspace(0.0, 1.0, c, endpoint=False)
                               for k, c in enumerate(per)] + [[float(len(per))]])

    def profile(self, u):
        """The tooth's convex chain at chain parameters ``u`` (U,) in [0, pieces]: piece
        by piece from the right root (the radial flank below the base circle, if any) up
        the right involute (by roll angle), round the right tip corner (its normal turning
        from the flank's to the radial direction), over the tip arc, round the left corner
        and down the left flank (the right half mirrored in the x axis). Returns points
        (U, 2) and outward unit normals (U, 2), mm, cutter frame (right flank at negative
        angles)."""
        n_p = self.pieces()
        u = np.asarray(u, float)
        piece = np.clip(np.floor(u).astype(int), 0, n_p - 1)
        t = u - piece
        if n_p == 5:  # no radial flank: pieces are involute, corner, tip, corner, involute
            piece = piece + 1
        left = piece >= 4
        piece_r = np.where(left, 6 - piece, piece)  # the right piece a left one mirrors
        t_r = np.where(left, 1.0 - t, t)
        rb, ra = self.rb, self.ra
        r0 = max(rb, self.rf)
        psi_b = self.thickness / (2 * self.rc) + _inv(self.alpha)  # involute start angle
        psi_a = float(self.psi(ra))
        tau0, tau_a = np.sqrt(max((r0 / rb) ** 2 - 1, 0.0)), np.sqrt((ra / rb) ** 2 - 1)
        x = np.zeros((len(u), 2))
        nrm = np.zeros((len(u), 2))
        # radial flank at angle -psi_b from the root to the base circle
        k = piece_r == 0
        r = self.rf + t_r[k] * (rb - self.rf)
        x[k] = np.c_[r * np.cos(-psi_b), r * np.sin(-psi_b)]
        nrm[k] = [np.sin(-psi_b), -np.cos(-psi_b)]
        # right involute: polar angle -psi_b + tau - atan(tau)
        k = piece_r == 1
        tau = tau0 + t_r[k] * (tau_a - tau0)
        g = -psi_b + tau
        x[k] = rb * np.c_[np.cos(g) + tau * np.sin(g), np.sin(g) - tau * np.cos(g)]
        nrm[k] = np.c_[np.sin(g), -np.cos(g)]
        # right tip corner: its normal turns from the flank's to the radial direction
        k = piece_r == 2
        ga = -psi_b + tau_a
        n0 = np.arctan2(-np.cos(ga), np.sin(ga))
        turn = n0 + t_r[k] * (-psi_a - n0)
        x[k] = [ra * np.cos(-psi_a), ra * np.sin(-psi_a)]
        nrm[k] = np.c_[np.cos(turn), np.sin(turn)]
        k = piece_r == 3
        ph = -psi_a + t_r[k] * 2 * psi_a
        x[k] = ra * np.c_[np.cos(ph), np.sin(ph)]
        nrm[k] = np.c_[np.cos(ph), np.sin(ph)]
        x[left] *= [1.0, -1.0]
        nrm[left] *= [1.0, -1.0]
        return x, nrm

    def outline(self, flank_points: int = 80) -> np.ndarray:
        """The whole tooth as a closed polygon (N, 2), mm, cutter frame: from the right
        root corner (r_f at minus half a pitch) along the root, up the right flank, over the
        tip, down the left flank to the left root corner (the chord between the two root
        corners closes it, inside the cutter's body)."""
        rb, ra, rf, hp = self.rb, self.ra, self.rf, self.half_pitch
        r0 = max(rb, rf)
        r = np.linspace(r0, ra, flank_points)
        psi = self.psi(r)
        right = np.c_[r * np.cos(-psi), r * np.sin(-psi)]
        root = np.linspace(-hp, -psi[0], 8)
        pts = [np.c_[rf * np.cos(root), rf * np.sin(root)], right]
        tip = np.linspace(-psi[-1], psi[-1], 12)[1:-1]
        pts.append(np.c_[ra * np.cos(tip), ra * np.sin(tip)])
        half = np.vstack(pts)
        return np.vstack([half, half[::-1] * [1.0, -1.0]])


def _inv(a):
    return np.tan(a) - a


def shaper_contact_roots(tooth: ShaperTooth, internal: bool, u=None):
    """Motion parameters where each profile point of ``tooth`` touches the gear (the
    envelope condition): sigma (U, 2) mm of arc rolled past the centre of the space the
    tooth cuts, both roots of each point's normal line on the cutter's pitch circle (NaN
    where the line misses the circle: no contact), with the profile points and normals
    (U, 2) of ``ShaperTooth.profile`` at chain parameters ``u``."""
    x, n = tooth.profile(u)
    rc = tooth.rc
    xn = np.einsum("ij,ij->i", x, n)
    disc = xn**2 - np.einsum("ij,ij->i", x, x) + rc**2
    with np.errstate(invalid="ignore"):
        root = np.sqrt(disc)
    lam = np.c_[-xn - root, -xn + root]  # (U, 2)
    p = x[:, None, :] + lam[..., None] * n[:, None, :]  # contact P in the cutter frame
    phi = np.arctan2(p[..., 1], p[..., 0])
    sigma = (rc * phi) if internal else (-rc * phi)
    return sigma, x, n


def shaper_poses(pitch, tooth: ShaperTooth, centres, sigma, internal: bool):
    """Pose of the cutter tooth that cuts the space centred at arc ``centres`` (K,) (mm)
    when it has rolled ``sigma`` (..., broadcast with (K, 1)) past it: (centre (..., 2),
    angle (...) rad of the tooth's axis) in the gear frame. The cutter's centre sits r_c
    beyond the contact along the normal (outside an external gear, inside an internal
    one), its tooth turned by face + / - sigma / r_c (face: the direction from the cutter's
    centre to the contact; rolling without slip, as teeth.cut_gear's simulated cutter)."""
    c = np.asarray(centres, float)[:, None]
    s = np.broadcast_to(c + sigma, np.broadcast_shapes(c.shape, np.shape(sigma)))
    p, _, n = pitch.at(s.ravel())
    sign = -1.0 if internal else 1.0
    centre = p + sign * tooth.rc * n
    face = np.arctan2(-sign * n[:, 1], -sign * n[:, 0])
    ang = face + sign * (s.ravel() - np.broadcast_to(c, s.shape).ravel()) / tooth.rc
    return centre.reshape(s.shape + (2,)), ang.reshape(s.shape)


def _place(xy_c, centre, ang):
    """Cutter-frame points (..., 2) placed by poses (centre (..., 2), angle (...))."""
    ca, sa = np.cos(ang), np.sin(ang)
    x, y = xy_c[..., 0], xy_c[..., 1]
    return np.stack([centre[..., 0] + ca * x - sa * y, centre[..., 1] + sa * x + ca * y], -1)


def shaper_window(tooth: ShaperTooth, addendum: float, internal: bool) -> float:
    """Half-width W (mm of arc rolled) of the motion over which a cutter tooth can reach
    the blank (a straight pitch line's: the tip circle below the addendum line, widened
    by half for curvature and for the tooth's half thickness); the cut is checked: the
    tooth at +-W must be clear of the blank."""
    rc, m = tooth.rc, tooth.module
    c = np.clip((rc - addendum * m) / tooth.ra, -1.0, 1.0)
    return float(rc * (1.5 * np.arccos(c) + tooth.half_pitch) + m)


def shaper_space_polygons(pitch, spec, centres, blank, internal: bool = False):
    """The tooth spaces a shaper (``spec``: module, pressure angle, addendum, dedendum,
    backlash, ``cutter_teeth``) cuts into ``blank`` (shapely polygon, mm) along ``pitch``
    (teeth.PitchPolyline), one per space centre of ``centres`` (K,) (mm of arc, may run
    past the perimeter), each the region the tooth that cuts it sweeps over its window.

    The region's boundary inside the blank lies on the envelope (both roots of every
    profile point, ``shaper_contact_roots``) or on the tooth at the window's ends; so the
    envelope curves, the two end teeth and the blank's edge are overlaid (noded and
    polygonized) and each face of that arrangement is kept when it lies in the blank and a
    point inside it is covered by the tooth at some position of the window (checked at
    ``SHAPER_CLASSIFY_STEPS`` positions, in the cutter's frame). Undercut (the flank
    envelope turning back) and pointed teeth (neighbouring spaces meeting) come out of the
    overlay and the union; no per-position Boolean.

    Returns the spaces (shapely array (K,)). Raises ShaperEnvelopeUnfit when the cutter's
    tooth at either end of a window still touches the blank (the window does not hold
    the whole cut) or a face cannot be classified."""
    import shapely

    m = spec.module
    tooth = ShaperTooth(m, int(spec.cutter_teeth), spec.alpha,
                        m * spec.cutter_teeth / 2 + spec.dedendum * m,
                        m * spec.cutter_teeth / 2 - (spec.addendum + 0.05) * m,
                        np.pi * m / 2 + spec.backlash_mm / 2)
    tooth.check()
    c = np.asarray(centres, float)
    K = len(c)
    W = shaper_window(tooth, spec.addendum, internal)
    outline = tooth.outline()
    # the tooth at the window's ends must be clear of the blank (the window widened while
    # it is not, up to half a turn of the cutter: inside a ring the teeth stay near the
    # blank longer)
    shapely.prepare(blank)
    while True:
        cen, ang = shaper_poses(pitch, tooth, c, np.array([-W, W]), internal)
        ends = _place(outline[None, None], cen[:, :, None], ang[:, :, None])  # (K, 2, N, 2)
        end_polys = shapely.polygons(ends.reshape(2 * K, -1, 2))
        touch = shapely.intersects(blank, end_polys).reshape(K, 2)
        if not touch.any() or 1.25 * W > np.pi * tooth.rc:
            break
        W *= 1.25
    if touch.any():
        k = int(np.argwhere(touch)[0][0])
        raise ShaperEnvelopeUnfit(f"the cutter tooth cutting the space at arc {c[k]:.2f} mm "
                                  f"still touches the blank {W:.2f} mm of rolling away")
    # envelope points of both root branches in each space, the chain's parameter refined
    # until every chord is within SHAPER_CHORD_TOL of the curve (over all spaces)
    u = tooth.profile_parameters()
    pts, ok = _envelope_points(pitch, tooth, c, u, W, internal)
    for _ in range(SHAPER_REFINE_ROUNDS):
        um = 0.5 * (u[1:] + u[:-1])
        pm, okm = _envelope_points(pitch, tooth, c, um, W, internal)
        a, b = pts[:, :, :-1], pts[:, :, 1:]
        ab = b - a
        ln = np.hypot(ab[..., 0], ab[..., 1])
        aq = pm - a
        dev = np.abs(ab[..., 0] * aq[..., 1] - ab[..., 1] * aq[..., 0]) / np.maximum(ln, 1e-12)
        dev = np.where(ln > 1e-12, dev, np.hypot(aq[..., 0], aq[..., 1]))
        valid = ok[:, :-1] & ok[:, 1:] & okm  # (2, U-1)
        bad = ((dev.max(axis=1) > SHAPER_CHORD_TOL) | (ln.max(axis=1) > 0.05 * m)) & valid
        need = bad.any(axis=0)
        if not need.any():
            break
        u = np.r_[u, um[need]]
        order = np.argsort(u, kind="stable")
        u = u[order]
        pts = np.concatenate([pts, pm[:, :, need]], axis=2)[:, :, order]
        ok = np.concatenate([ok, okm[:, need]], axis=1)[:, order]
    lines = []
    for b in range(2):
        for i0, i1 in _runs(ok[b]):
            if i1 - i0 >= 2:
                lines.append(pts[b, :, i0:i1])
    # per space: the envelope branches, the two end teeth and the blank's edge near it
    edge = shapely.boundary(blank)
    spaces = np.empty(K, dtype=object)
    faces_all, owner = [], []
    for k in range(K):
        geoms = [shapely.linestrings(seg[k]) for seg in lines]
        geoms += [shapely.LinearRing(ends[k, 0]), shapely.LinearRing(ends[k, 1])]
        box = shapely.envelope(shapely.multipoints(np.vstack([seg[k] for seg in lines]
                                                              + [ends[k, 0], ends[k, 1]])))
        near = shapely.intersection(edge, shapely.buffer(box, m))
        geoms.append(near)
        noded = shapely.union_all(np.array(geoms, dtype=object))
        faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(noded)))
        faces = faces[shapely.area(faces) > 1e-10]
        faces_all.append(faces)
        owner.append(np.full(len(faces), k))
    faces = np.concatenate(faces_all)
    owner = np.concatenate(owner)
    rep = shapely.get_coordinates(shapely.point_on_surface(faces))
    inside = shapely.contains_xy(blank, rep[:, 0], rep[:, 1])
    covered = np.zeros(len(faces), bool)
    sel = np.flatnonzero(inside)
    if len(sel):
        covered[sel] = _covered(pitch, tooth, c[owner[sel]], rep[sel], W, outline, internal)
    keep = inside & covered
    for k in range(K):
        mine = faces[(owner == k) & keep]
        spaces[k] = shapely.union_all(mine) if len(mine) else shapely.Polygon()
    return spaces


def _envelope_points(pitch, tooth, centres, u, W, internal):
    """Envelope points (2, K, U, 2), mm, gear frame, of the chain parameters ``u`` (U,)
    in each space (``centres`` (K,)), both roots; and whether each root lies in the
    window (a little beyond +-W, so the branches cross the end teeth) (2, U)."""
    sigma, x, _ = shaper_contact_roots(tooth, internal, u)
    ok = (np.isfinite(sigma) & (np.abs(sigma) <= 1.02 * W)).T  # (2, U)
    cen, ang = shaper_poses(pitch, tooth, centres, np.where(ok, sigma.T, 0.0)
                            .reshape(1, -1), internal)
    K = len(centres)
    pts = _place(np.tile(x, (2, 1))[None], cen, ang)  # (K, 2U, 2)
    return pts.reshape(K, 2, len(u), 2).transpose(1, 0, 2, 3), ok


def _runs(mask):
    """(start, stop) of the runs of True in the 1-D ``mask``."""
    e = np.diff(np.r_[0, mask.astype(int), 0])
    return list(zip(np.flatnonzero(e == 1), np.flatnonzero(e == -1), strict=True))


def _covered(pitch, tooth, centres, q, W, outline, internal):
    """Whether each point ``q`` (F, 2) (gear frame, mm) lies in the tooth that cuts the
    space at arc ``centres`` (F,) at some position of its window (+-W mm rolled): each
    point carried into the cutter's frame at ``SHAPER_CLASSIFY_STEPS`` positions and
    tested against the tooth's outline; a point found in none is tested again at 64
    positions around the one where it came nearest (not missed between two positions)."""
    import shapely

    poly = shapely.Polygon(outline)
    shapely.prepare(poly)
    grid = np.linspace(-W, W, SHAPER_CLASSIFY_STEPS)
    xc, yc = _in_cutter_frame(pitch, tooth, centres, q, grid[None, :], internal)
    hit = shapely.contains_xy(poly, xc.ravel(), yc.ravel()).reshape(xc.shape).any(axis=1)
    miss = np.flatnonzero(~hit)
    if len(miss):
        dist = shapely.distance(shapely.points(xc[miss].ravel(), yc[miss].ravel()),
                                poly).reshape(len(miss), -1)
        best = grid[np.argmin(dist, axis=1)]
        fine = best[:, None] + np.linspace(-1.0, 1.0, 64)[None, :] * (grid[1] - grid[0])
        xf, yf = _in_cutter_frame(pitch, tooth, centres[miss], q[miss], fine, internal)
        hit[miss] = shapely.contains_xy(poly, xf.ravel(), yf.ravel()).reshape(
            xf.shape).any(axis=1)
    return hit


def _in_cutter_frame(pitch, tooth, centres, q, sig, internal):
    """Points ``q`` (F, 2) (gear frame, mm) in the frame of the tooth cutting the space at
    arc ``centres`` (F,) at roll positions ``sig`` (F or 1, S): (x (F, S), y (F, S))."""
    cen, ang = shaper_poses(pitch, tooth, centres, sig, internal)
    d = q[:, None, :] - cen
    ca, sa = np.cos(ang), np.sin(ang)
    return ca * d[..., 0] + sa * d[..., 1], -sa * d[..., 0] + ca * d[..., 1]
