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

TWO_PI = 2.0 * np.pi
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
        noded = shapely.union_all(np.array(geoms, dtype=object), grid_size=MATE_NODING_GRID)
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


# --- the mate: a gear generated by its driver's cut teeth ----------------------------------
#
# Gear B of a pair is cut by gear A's teeth (a "generating A": A's cut outline, teeth thicker
# by the backlash and longer by the clearance) rolled through the cycle by the pitch curves'
# law. The instant centre of the relative motion of A and B is the pitch point, the contact
# of the pitch curves on the line of centres (seed 001, Eq. 11-18); in A's frame it runs along
# A's pitch curve, at arc s when A's contact is there. So a point x of A's outline with
# outward normal n touches B when its normal line passes through P(s):
#
#     g(s) = n x (P(s) - x) = 0,
#
# an equation in one unknown per outline point, solved over a window of arc about the point
# (bracketed on a grid, refined by regula falsi: every root, so the multiple roots near
# undercut and the corners are all found). The outline is A's polyline itself: each edge's
# points carry its normal, each vertex the normals between those of the edges it joins
# (a sharp tip corner's sweep traces the trochoid that forms B's fillet and root). The
# roots carried into B's frame by the motion are the envelope; it loops where B is undercut
# or where a corner's trochoid cuts into a flank. Trimming as for the shaper: the curves
# (points of consecutive outline parameters joined), the blank's edge (and on a partial
# gear A's outline at the cycle's two ends) are noded and polygonized, and a face is cut
# away when a point of it lies inside A's outline at some position of the motion.

MATE_GRID_PER_PITCH = 48  # arc samples per pitch bracketing the roots (and classifying)
# the window of arc about each point: the simulated cut's farthest reach (A's pieces of one
# pitch whose middles lie within 3 pitches of the contact), fixed. Not widened to hold the
# whole cut: inside a ring, teeth far from the pitch point foul, and a mate cut over A's
# whole reach would be trimmed there, hiding that interference from the mesh check
# (docs/validation.md, the published transplanter at module 1)
MATE_WINDOW_PITCHES = 3.5
MATE_CORNER_STEP = np.radians(2.0)  # normal directions swept at a vertex, at most this apart
MATE_EDGE_MAX = 0.05  # x module: longer edges of A's outline get points in between
MATE_REFINE = 3  # regula falsi steps per root
MATE_LINK_MAX = 0.05  # x module: longer links in B's frame get outline points in between
MATE_LINK_ROUNDS = 10  # halvings of the outline's steps at most
MATE_REFINE_NEAR = 0.2  # x module: a link is refined when longer, or with an end this near B
MATE_DANGLE_REACH = 1.5  # x module: A's outline this near a dangling root closes it
MATE_DANGLE_DEPTH = 0.01  # x module: a dangling root is joined this far inside A
MATE_CHECK_PER_PITCH = 24  # positions per pitch of the self-check (as the simulated cut)
MATE_NODING_GRID = 1e-5  # mm: the curves are noded snapped to this grid (snap-rounding)
MATE_SIMPLIFY = 2e-4  # mm: the envelope's chains are simplified within this before noding
MATE_SLIVER = 1e-3  # mm: faces narrower than this (2 area / perimeter) are cut unclassified
MATE_CHECK_DEPTH = 0.01  # x module: A may not reach deeper into B's material (mesh limit)


MATE_REACH_PITCHES = 3.0  # the simulated cut's reach: pieces whose middles are this near


@dataclass(frozen=True)
class MateReach:
    """The simulated cut's reach (``teeth._mate_simulated_sweep``) as a window per point of
    A: A's band is cut into ``count`` pieces of ``piece`` mm of arc of its pitch curve
    (``teeth._pieces``: wedges from A's centre, piece k over the polar angles of arcs
    [k piece, (k + 1) piece)), each taken whole while its middle is within ``half`` mm of
    arc of the contact (3 pitches and half a piece: ``teeth._near``). A point of A
    belongs to the piece its polar angle lies in, and touches B only at contact arcs
    within ``half`` of that piece's middle (not of the point itself)."""

    piece: float
    count: int
    half: float
    perimeter: float

    @classmethod
    def of(cls, perimeter: float, pitch: float,
           pitches: float = MATE_REACH_PITCHES) -> MateReach:
        """The reach on A's pitch curve of ``perimeter`` (mm), pieces of about one
        ``pitch`` (mm, pi m), as ``teeth._pieces`` and ``teeth._near`` make it."""
        n = max(8, int(round(perimeter / pitch)))
        piece = perimeter / n
        return cls(piece, n, pitches * pitch + piece / 2, perimeter)

    def middle(self, s):
        """Arc (mm) of the middle of the piece holding arc ``s`` (mm)."""
        k = np.clip(np.floor(np.mod(s, self.perimeter) / self.piece), 0, self.count - 1)
        return (k + 0.5) * self.piece

    def within(self, middle, s):
        """Whether contact arc ``s`` lies within the reach of the piece of ``middle``."""
        P = self.perimeter
        return np.abs(np.mod(np.asarray(s) - middle + P / 2, P) - P / 2) <= self.half


class MateEnvelopeUnfit(Exception):
    """The envelope cannot stand for the mate's simulated cut here (the message says why):
    the mate is cut by simulation instead."""


@dataclass
class MateMotion:
    """The generating motion of a pair in A's frame: A's pitch curve ``pitch_a``
    (teeth.PitchPolyline, mm) and the law of B's contact angle ``phi_b`` (rad) against A's
    contact angle ``theta_a`` (rad, increasing over one turn of A; both over the cycle), the
    centre distance ``a`` (mm), ``internal`` (A is the ring, B inside it). ``periodic``:
    the motion repeats (B closed); else it runs once from theta_a[0] to theta_a[-1]."""

    pitch_a: object
    theta_a: np.ndarray
    phi_b: np.ndarray
    a: float
    internal: bool
    periodic: bool

    def __post_init__(self):
        self.theta_a = np.asarray(self.theta_a, float)
        self.phi_b = np.asarray(self.phi_b, float)
        if np.any(np.diff(self.theta_a) <= 0) or abs(self.theta_a[-1] - self.theta_a[0]
                                                     - TWO_PI) > 1e-6:
            raise MateEnvelopeUnfit("the motion does not run once round A's pitch curve")
        P = self.pitch_a.perimeter
        self.perimeter = P
        xy = self.pitch_a.xy
        cum = np.r_[0.0, np.cumsum(np.hypot(*self.pitch_a.seg.T))]
        ang = np.unwrap(np.r_[np.arctan2(xy[:, 1], xy[:, 0]), np.arctan2(xy[0, 1], xy[0, 0])])
        if abs(abs(ang[-1] - ang[0]) - TWO_PI) > 1e-6 or np.any(np.diff(ang) * np.sign(
                ang[-1] - ang[0]) <= 0):
            raise MateEnvelopeUnfit("A's pitch curve is not star-shaped about its centre")
        self._cum, self._ang = cum, ang

    def theta(self, s):
        """A's contact angle (rad) when its contact is at arc ``s`` (mm), in the cycle's
        turn [theta_a[0], theta_a[0] + 2 pi)."""
        P = self.perimeter
        ang = np.interp(np.mod(s, P), self._cum, self._ang)
        t0 = self.theta_a[0]
        return t0 + np.mod(ang - t0, TWO_PI)

    def arc(self, theta):
        """Arc (mm) of A's pitch point at polar angle ``theta`` (rad)."""
        a0 = self._ang[0]
        return np.interp(a0 + np.mod(np.asarray(theta, float) - a0, TWO_PI), self._ang,
                         self._cum)

    def to_b(self, x, theta):
        """A-frame points ``x`` (..., 2) carried into B's frame at A's contact angles
        ``theta`` (...): turned by -theta into the mesh frame, shifted by -a, turned by
        phi_B (internal) or phi_B - pi (external, B faces A across the line of centres;
        teeth.placed)."""
        phi = np.interp(theta, self.theta_a, self.phi_b)
        turn = phi if self.internal else phi - np.pi
        c, s_ = np.cos(theta), np.sin(theta)
        mx = c * x[..., 0] + s_ * x[..., 1] - self.a
        my = -s_ * x[..., 0] + c * x[..., 1]
        c, s_ = np.cos(turn), np.sin(turn)
        return np.stack([c * mx - s_ * my, s_ * mx + c * my], -1)

    def to_a(self, q, theta):
        """B-frame points ``q`` (..., 2) carried into A's frame at contact angles ``theta``
        (the inverse of ``to_b``)."""
        phi = np.interp(theta, self.theta_a, self.phi_b)
        turn = phi if self.internal else phi - np.pi
        c, s_ = np.cos(turn), np.sin(turn)
        mx = c * q[..., 0] + s_ * q[..., 1] + self.a
        my = -s_ * q[..., 0] + c * q[..., 1]
        c, s_ = np.cos(theta), np.sin(theta)
        return np.stack([c * mx - s_ * my, s_ * mx + c * my], -1)


def _outline_chains(tool, keep, module: float):
    """Points and outward normals along every ring of ``tool`` (shapely polygon, mm, or an
    array of them: the pieces of a ``MateReach``; the
    material on the left of each ring as oriented), the vertices where ``keep(xy)`` holds:
    each vertex with the normals from its incoming edge's to its outgoing edge's (at most
    ``MATE_CORNER_STEP`` apart), edges longer than ``MATE_EDGE_MAX`` module with points in
    between. Returns (x (U, 2), n (U, 2), chain id (U,), closed: whether each entry links
    to the next in its chain (U,) bool, the index of the polygon in ``tool`` each entry
    lies on (U,))."""
    import shapely

    rings, owners = [], []
    geoms = tool if isinstance(tool, np.ndarray) else [tool]
    for i, g in enumerate(geoms):
        for part in shapely.get_parts(g):
            if part.geom_type != "Polygon":
                continue
            part = shapely.geometry.polygon.orient(part, 1.0)
            rr = [np.asarray(part.exterior.coords)[:-1]] + [np.asarray(r.coords)[:-1]
                                                            for r in part.interiors]
            rings += rr
            owners += [i] * len(rr)
    xs, ns, ids, links, srcs = [], [], [], [], []
    chain = 0
    for V, owner_geom in zip(rings, owners, strict=True):
        if len(V) < 3:
            continue
        e = np.roll(V, -1, axis=0) - V
        ln = np.hypot(*e.T)
        ok = ln > 1e-12
        V, e, ln = V[ok], e[ok], ln[ok]
        n_edge = np.c_[e[:, 1], -e[:, 0]] / ln[:, None]
        n_in = np.roll(n_edge, 1, axis=0)
        turn = np.arctan2(n_in[:, 0] * n_edge[:, 1] - n_in[:, 1] * n_edge[:, 0],
                          np.einsum("ij,ij->i", n_in, n_edge))
        J = np.maximum(1, np.ceil(np.abs(turn) / MATE_CORNER_STEP).astype(int))
        L = np.maximum(0, np.ceil(ln / (MATE_EDGE_MAX * module)).astype(int) - 1)
        per = J + 1 + L  # sweep entries then edge interior entries, per vertex
        owner = np.repeat(np.arange(len(V)), per)
        k = np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per)
        sweep = k <= J[owner]
        ang = np.arctan2(n_in[owner, 1], n_in[owner, 0]) + turn[owner] * np.where(
            sweep, k / J[owner], 1.0)
        f = np.where(sweep, 0.0, (k - J[owner]) / (L[owner] + 1))
        x = V[owner] + f[:, None] * e[owner]
        n = np.c_[np.cos(ang), np.sin(ang)]
        inside = keep(V)
        use = inside[owner] | inside[(owner + 1) % len(V)]
        # runs of used entries: a run wrapping the whole ring stays closed
        link = use & np.roll(use, -1)
        if use.all():
            xs.append(x), ns.append(n), ids.append(np.full(len(x), chain)), links.append(link)
            srcs.append(np.full(len(x), owner_geom))
            chain += 1
            continue
        # cut the ring at an unused entry so every run is contiguous
        start = int(np.flatnonzero(~use)[0])
        order = np.roll(np.arange(len(x)), -start)
        x, n, use, link = x[order], n[order], use[order], link[order]
        run = np.cumsum(np.r_[0, np.diff(use.astype(int)) == 1])
        sel = use
        link = link & sel
        xs.append(x[sel]), ns.append(n[sel]), ids.append(chain + run[sel]),
        links.append(link[sel])
        srcs.append(np.full(int(sel.sum()), owner_geom))
        chain += int(run.max()) + 1
    return (np.concatenate(xs), np.concatenate(ns), np.concatenate(ids),
            np.concatenate(links), np.concatenate(srcs))


def mate_envelope_lines(tool, motion: MateMotion, module: float, depth: float,
                        window: float = MATE_WINDOW_PITCHES, blank=None,
                        reach: MateReach | None = None):
    """The envelope of ``tool`` (A's generating outline, shapely polygon in A's frame, mm)
    in B's frame under ``motion`` (MateMotion): every root of every outline point within
    ``depth`` (mm) of A's pitch curve (radially), within ``window`` pitches of arc of it,
    joined along the outline: each root to the nearest root (in arc) of the next outline
    point and back, and where the count of roots changes, neighbouring roots of one point
    (two roots merging at a tangency). Where a link is longer than ``MATE_LINK_MAX``
    module in B's frame the outline points between are refined (``MATE_LINK_ROUNDS``
    halvings at most); links still longer are branch jumps, dropped.

    ``blank`` (shapely polygon, B's frame, prepared), when given: only the links that can
    reach it are refined. ``reach`` (MateReach), when given, replaces the window: a point's
    roots are those within the reach of its piece's middle (the simulated cut's pieces).

    Returns (segments (M, 2, 2) mm in B's frame, root points (R, 2) in B's frame, their
    contact angles theta (R,), rad, the outline points (U, 2) used, A's frame, the links as
    pairs of root indices (M, 2), each root's outline point and outward normal (R, 2),
    A's frame, and with ``reach`` the paths of sharp corners whose long links were
    dropped (``_corner_paths``, B's frame; else an empty list))."""
    import shapely

    pa = motion.pitch_a
    P = motion.perimeter
    pitch = np.pi * module
    h = pitch / MATE_GRID_PER_PITCH
    Ns = int(np.ceil(P / h))
    h = P / Ns
    Pg = pa.at(np.arange(Ns) * h)[0]

    def keep(xy):
        arc = motion.arc(np.arctan2(xy[:, 1], xy[:, 0]))
        p = pa.at(arc)[0]
        return np.abs(np.hypot(*xy.T) - np.hypot(*p.T)) <= depth

    def roots(x, n, c_x=None):
        """(entry index, arc, theta, B point) of every root of the points x (``c_x``:
        the middles of their pieces, with ``reach``)."""
        from plantmech.gears.envelope_kernels import mate_roots

        if c_x is None:  # the window's centre: the point's own arc
            c_x = motion.arc(np.arctan2(x[:, 1], x[:, 0]))
        i0 = np.round(c_x / h).astype(np.int64)
        ui, s_r = mate_roots(np.ascontiguousarray(x), np.ascontiguousarray(n), i0, Pg, G, h,
                             pa.xy, MATE_REFINE)
        if reach is not None:  # the grid's whole steps reach past the piece's: trimmed
            ok = reach.within(c_x[ui], s_r)
            ui, s_r = ui[ok], s_r[ok]
        th = motion.theta(s_r)
        return ui, s_r, th, motion.to_b(x[ui], th)

    from plantmech.gears.envelope_kernels import mate_links

    if reach is None:
        x, n, chain, link, _ = _outline_chains(tool, keep, module)
        mid = None
    else:  # the simulated cut's pieces, each with its reach: their cut edges bound it too
        from plantmech.gears.teeth import _pieces

        pieces, middles, _ = _pieces(tool, pa, reach.piece)
        x, n, chain, link, src = _outline_chains(pieces, keep, module)
        mid = middles[src]
    key = np.arange(len(x), dtype=float)
    paths = []
    if blank is not None:  # only the links that can reach the blank are refined
        reach_blank = shapely.buffer(blank, MATE_REFINE_NEAR * module, quad_segs=4)
        shapely.prepare(reach_blank)
    G = int(np.ceil(window * pitch / h)) if reach is None else int(np.ceil(reach.half / h)) + 1
    ui, s_r, th, q = roots(x, n, mid)
    tol = MATE_LINK_MAX * module
    for rnd in range(MATE_LINK_ROUNDS + 1):
        U = len(x)
        # roots grouped by entry (each entry's roots come in increasing arc from the kernel)
        order = np.argsort(ui, kind="stable")
        ui, s_r, th, q = ui[order], s_r[order], th[order], q[order]
        nxt = np.r_[np.arange(1, U), 0]
        same = link & (chain[nxt] == chain)
        R = np.bincount(ui, minlength=U)
        first = np.r_[0, np.cumsum(R)[:-1]]
        pair, change = mate_links(first, R, nxt, same, s_r, P, pitch)
        if not motion.periodic:  # no link across the cycle's seam (B jumps there)
            pair = pair[np.abs(th[pair[:, 0]] - th[pair[:, 1]]) < np.pi]
        ln = np.hypot(*(q[pair[:, 1]] - q[pair[:, 0]]).T)
        # refine between the outline entries of the long links (and where roots appear
        # or vanish, to close the tangency's gap)
        long_ = ln > tol
        e0, e1 = ui[pair[long_, 0]], ui[pair[long_, 1]]
        lo = np.where(e1 == nxt[e0], e0, np.where(e0 == nxt[e1], e1, -1))
        if blank is not None:  # only where the curve can reach B's blank
            ends = pair[long_]
            near_ = (ln[long_] > MATE_REFINE_NEAR * module) | shapely.contains_xy(
                reach_blank, q[ends[:, 0], 0], q[ends[:, 0], 1]) | shapely.contains_xy(
                reach_blank, q[ends[:, 1], 0], q[ends[:, 1], 1])
            lo = np.where(near_, lo, -1)
            # a tangency between entries u and nxt[u]: refined when a root of either is
            # near the blank
            cand = np.flatnonzero((change | np.roll(change, 1))[ui])
            rel = np.zeros(U, bool)
            rel[ui[cand[shapely.contains_xy(reach_blank, q[cand, 0], q[cand, 1])]]] = True
            change = change & (rel | rel[nxt])
        need = np.zeros(U, bool)
        need[lo[lo >= 0]] = True
        # a long link between two roots of one entry (a tangency's chord): refine between
        # that entry and the neighbour whose count differs
        e = e0[e0 == e1]
        need[e[change[e]]] = True
        e = np.mod(e - 1, U)
        need[e[change[e]]] = True
        need &= same
        if rnd == MATE_LINK_ROUNDS or not need.any():
            if reach is not None:
                paths = _corner_paths(pair[long_], ui, s_r, x, mid, motion, reach, module,
                                      reach_blank if blank is not None else None, q,
                                      blank)
            pair = pair[~long_]
            break
        k = np.flatnonzero(need)
        k1 = nxt[k]
        xm = 0.5 * (x[k] + x[k1])
        nm = n[k] + n[k1]
        nm /= np.hypot(*nm.T)[:, None]
        km = np.where(k1 > k, 0.5 * (key[k] + key[k1]), key[k] + 0.5)
        new_ui, new_s, new_th, new_q = roots(xm, nm, None if mid is None else mid[k])
        ui = np.r_[ui, new_ui + U]
        s_r, th, q = np.r_[s_r, new_s], np.r_[th, new_th], np.r_[q, new_q]
        x, n, key = np.r_[x, xm], np.r_[n, nm], np.r_[key, km]
        if mid is not None:
            mid = np.r_[mid, mid[k]]
        chain, link = np.r_[chain, chain[k]], np.r_[link, np.ones(len(k), bool)]
        # entries in outline order again (within each chain, by key)
        o = np.lexsort((key, chain))
        inv_o = np.empty_like(o)
        inv_o[o] = np.arange(len(o))
        x, n, key, chain, link = x[o], n[o], key[o], chain[o], link[o]
        if mid is not None:
            mid = mid[o]
        ui = inv_o[ui]
    segs = np.stack([q[pair[:, 0]], q[pair[:, 1]]], axis=1)
    return segs, q, th, x, pair, x[ui], n[ui], paths


def _corner_paths(jumps, ui, s_r, x, mid, motion: MateMotion, reach: MateReach,
                  module: float, near=None, q_r=None, ends_in=None):
    """The long links left (``jumps``, pairs of root indices) that join two roots of one
    point of A (a sharp corner, its normals swept: ``_outline_chains``) stand for that
    point's path between the two contact arcs (every normal between touches in between):
    where the link is a chord across a fast turn of the motion its path is the cut's
    boundary, and dropping it left a face open (the K-H-V planet). One path per point,
    over the hull of its links' arcs (the point lies on A's outline at every contact
    within its piece's reach, so its path lies in the swept region: more of it only
    subdivides faces), kept where it comes within ``near`` (prepared shapely geometry,
    B's frame) when given, and only for links with an end (``q_r``, the roots in B's
    frame) in ``ends_in`` when given. Returns the paths in B's frame, a list of (N, 2)
    arrays (mm), sampled so that a step stays under ``MATE_LINK_MAX`` module where the motion is
    smooth (at most 400 samples each)."""
    import shapely

    if not len(jumps):
        return []
    a, b = jumps[:, 0], jumps[:, 1]
    same = np.all(x[ui[a]] == x[ui[b]], axis=1)
    if ends_in is not None:  # (a chord with both ends outside the blank: not needed here)
        same &= shapely.contains_xy(ends_in, q_r[a, 0], q_r[a, 1]) | shapely.contains_xy(
            ends_in, q_r[b, 0], q_r[b, 1])
    a, b = a[same], b[same]
    if not len(a):
        return []
    P = motion.perimeter
    # both contacts relative to the piece's middle, inside its reach (an interval)
    m0 = mid[ui[a]]
    s1 = m0 + np.mod(s_r[a] - m0 + P / 2, P) - P / 2
    s2 = m0 + np.mod(s_r[b] - m0 + P / 2, P) - P / 2
    # one path per point: the hull of its links' arcs
    pts, inv = np.unique(x[ui[a]], axis=0, return_inverse=True)
    inv = inv.ravel()
    lo = np.full(len(pts), np.inf)
    hi = np.full(len(pts), -np.inf)
    np.minimum.at(lo, inv, np.minimum(s1, s2))
    np.maximum.at(hi, inv, np.maximum(s1, s2))
    f = np.linspace(0.0, 1.0, 9)
    s = lo[:, None] + f[None, :] * (hi - lo)[:, None]
    q = motion.to_b(np.broadcast_to(pts[:, None, :], s.shape + (2,)), motion.theta(s))
    if near is not None:
        keep = shapely.contains_xy(near, q[..., 0], q[..., 1]).any(axis=1)
        pts, lo, hi, q = pts[keep], lo[keep], hi[keep], q[keep]
    length = np.hypot(*np.diff(q, axis=1).transpose(2, 0, 1)).sum(axis=1)
    count = np.clip(np.ceil(length / (MATE_LINK_MAX * module)) + 1, 9, 400).astype(int)
    out = []
    for k in range(len(pts)):
        sk = np.linspace(lo[k], hi[k], count[k])
        out.append(motion.to_b(np.broadcast_to(pts[k], (count[k], 2)), motion.theta(sk)))
    return out


def mate_space_polygons(tool, motion: MateMotion, blank, module: float, depth: float,
                        reach: MateReach | None = None):
    """The material the generating A (``tool``: its outline in its own frame, mm) removes
    from B's ``blank`` (shapely polygon, B's frame) over ``motion``, by the envelope
    (module notes above): the envelope curves, the blank's edge and, when the motion does
    not repeat, A's outline at the cycle's ends are noded and polygonized; a face inside
    the blank is removed when a point of it lies inside A at some position within the
    window of the envelope point nearest it (``MATE_GRID_PER_PITCH`` positions per pitch,
    then 64 about the nearest approach). The generating body is A's band within ``depth``
    (mm) of its pitch curve, as in the simulated cut. Where a linked curve ends inside the
    blank, A's outline at that root's position closes it (``_dangle_closures``).
    ``reach`` (MateReach), when given, stands for the fixed window: the simulated cut's
    pieces of A, each over the contact arcs within its reach (the envelope's roots, the
    faces' classification and the self-check), and each piece's outline at the two ends
    of its reach bounds the cut too (where it enters and leaves, its wedge's cut edges
    included).
    Returns the material left (shapely geometry, the faces inside the blank not removed).
    Raises MateEnvelopeUnfit when the self-check finds A's outline, at a position
    of the motion (``MATE_CHECK_PER_PITCH`` per pitch), deeper than ``MATE_CHECK_DEPTH``
    module inside the material left (a space the arrangement failed to close)."""
    import shapely

    pitch = np.pi * module
    shapely.prepare(blank)
    # the generating body is A's band within ``depth`` of its pitch curve, as in the
    # simulated cut (teeth._mate_simulated_sweep): its inner edge and the corners where
    # A's outline leaves the band cut B too where a gouged tooth of A runs deeper
    tool_band = shapely.intersection(tool, shapely.buffer(shapely.boundary(
        shapely.Polygon(motion.pitch_a.xy)), depth))
    # the window of arc about each point: the simulated cut's reach (MATE_WINDOW_PITCHES);
    # where an envelope curve ends at it inside the blank, A's outline at that position
    # closes it (_dangle_closures), as the simulated cut's last piece does
    window = MATE_WINDOW_PITCHES
    segs, q, th, x, pair, xr, nr, paths = mate_envelope_lines(
        tool_band, motion, module, np.inf, window, blank=blank, reach=reach)
    # only the links that can reach the blank matter (the rest lie in the swept region
    # outside it)
    reach_len = float(np.hypot(*(segs[:, 1] - segs[:, 0]).T).max()) if len(segs) else 0.0
    grown = shapely.buffer(blank, reach_len + 1e-6)
    shapely.prepare(grown)
    near = (shapely.contains_xy(grown, segs[:, 0, 0], segs[:, 0, 1])
            | shapely.contains_xy(grown, segs[:, 1, 0], segs[:, 1, 1]))
    geoms = [_curves(q, pair[near])]
    geoms.append(shapely.boundary(blank))
    if paths:  # sharp corners' paths across fast turns (inside a ring, _corner_paths)
        lines = shapely.linestrings(np.concatenate(paths), indices=np.repeat(
            np.arange(len(paths)), [len(p) for p in paths]))
        lines = lines[shapely.intersects(lines, grown)]
        if len(lines):
            geoms.append(shapely.intersection(shapely.multilinestrings(lines), grown))
    if not motion.periodic:  # A's outline at the motion's two ends bounds the cut too
        for t_end in (motion.theta_a[0], motion.theta_a[-1]):
            b = shapely.boundary(tool_band)
            geoms.append(shapely.transform(b, lambda xy, t=t_end: motion.to_b(
                xy, np.full(len(xy), t))))
    geoms += _dangle_closures(tool_band, motion, q, th, pair, xr, nr, grown, module)
    if reach is not None:
        geoms += _reach_ends(tool_band, motion, reach, grown)
    noded = shapely.union_all(np.array(geoms, dtype=object), grid_size=MATE_NODING_GRID)
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(noded)))
    faces = faces[shapely.area(faces) > 1e-10]
    rep = shapely.get_coordinates(shapely.point_on_surface(faces))
    inside = shapely.contains_xy(blank, rep[:, 0], rep[:, 1])
    # most faces are slivers between curves within a micrometre of each other (the
    # envelopes of neighbouring outline points, the closures along them): narrower than
    # MATE_SLIVER they are cut away unclassified (a slit that narrow is closed again by
    # the outline cleaning, outline.clean_outline, which fills gaps under 4 um)
    wide = 2.0 * shapely.area(faces) > MATE_SLIVER * shapely.length(faces)
    sel = np.flatnonzero(inside & wide)
    covered = ~wide
    if len(sel):
        covered[sel] = _covered_by_mate(tool_band, motion, rep[sel], q, th, x, pitch,
                                        window, reach)
    # every curve lies in the swept region (points of A's outline, or links between
    # nearby ones), so B's material is one face or a few: united, they are the gear
    material = shapely.union_all(faces[inside & ~covered])
    # self-check: A's outline at the stations of the motion must stay out of B's material
    # (a face the arrangement failed to close would have been kept as material whole)
    deep = _mate_overlap(tool_band, motion, material, module, window, reach=reach)
    if deep is not None:
        raise MateEnvelopeUnfit(
            f"self-check: the generating gear's outline reaches {MATE_CHECK_DEPTH:g} module "
            f"into the envelope's material at ({deep[0]:.2f}, {deep[1]:.2f}) mm (B's frame): "
            f"a tooth space the arrangement did not close")
    return material


def _curves(q, pair):
    """The links ``pair`` (M, 2) between the points ``q`` (mm) as one multilinestring of
    chains (each run of links through points of degree two one linestring), simplified
    within ``MATE_SIMPLIFY`` mm: noding a few thousand chains is several times faster than
    noding each link on its own."""
    import shapely

    from plantmech.gears.envelope_kernels import link_chains

    if not len(pair):
        return shapely.MultiLineString()
    nodes, line = link_chains(np.ascontiguousarray(pair, dtype=np.int64), len(q))
    lines = shapely.linestrings(q[nodes], indices=line)
    return shapely.simplify(shapely.multilinestrings(lines), MATE_SIMPLIFY,
                            preserve_topology=False)


def _mate_overlap(tool_band, motion: MateMotion, material, module: float, window: float,
                  per_pitch: int = MATE_CHECK_PER_PITCH, reach: MateReach | None = None):
    """Where A's outline (``tool_band``'s vertices, edges split to 0.05 module) at the
    motion's positions (``per_pitch`` per pitch of arc on A, and as many per pitch of B's
    turn relative to A at three modules from its centre) lies deeper than
    ``MATE_CHECK_DEPTH`` module inside B's ``material``, within ``window`` pitches of arc
    of the contact (with ``reach``: the vertices of the pieces within it): the first such
    point (B's frame, mm), or None."""
    import shapely

    pitch = np.pi * module
    inner = shapely.buffer(material, -MATE_CHECK_DEPTH * module, quad_segs=4)
    if inner.is_empty:
        return None
    shapely.prepare(inner)
    if reach is None:
        v = shapely.get_coordinates(shapely.segmentize(shapely.boundary(tool_band),
                                                       MATE_EDGE_MAX * module))
        sv = motion.arc(np.arctan2(v[:, 1], v[:, 0]))
    else:  # the pieces' outlines (their cut edges too), each vertex with its piece's middle
        from plantmech.gears.teeth import _pieces

        pieces, middles, _ = _pieces(tool_band, motion.pitch_a, reach.piece)
        v, k = shapely.get_coordinates(shapely.segmentize(shapely.boundary(pieces),
                                                          MATE_EDGE_MAX * module),
                                       return_index=True)
        sv = middles[k]
    order = np.argsort(sv, kind="stable")
    v, sv = v[order], sv[order]
    P = motion.perimeter
    # stations: uniform in arc on A and in B's turn relative to A (fast spans get more)
    th, ph = motion.theta_a, motion.phi_b
    s_at = motion.arc(th)
    s_at = s_at[0] + np.r_[0.0, np.cumsum(np.mod(np.diff(s_at) + P / 2, P) - P / 2)]
    u = np.r_[0.0, np.cumsum(np.maximum(np.abs(np.diff(s_at)),
                                        3 * module * np.abs(np.diff(ph) - np.diff(th))))]
    count = int(np.ceil(u[-1] / pitch * per_pitch)) + 1
    t = np.interp(np.linspace(0.0, u[-1], count), u, th)
    s_t = np.interp(t, th, s_at)
    W = window * pitch if reach is None else reach.half
    lo = np.searchsorted(sv, np.mod(s_t - W, P))
    hi = np.searchsorted(sv, np.mod(s_t + W, P))
    n = np.mod(hi - lo, len(v))
    n = np.where(2 * W >= P, len(v), n)
    owner = np.repeat(np.arange(count), n)
    idx = np.mod(np.repeat(lo, n) + np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n),
                 len(v))
    for chunk in np.array_split(np.arange(len(idx)), max(1, len(idx) // 500_000)):
        q = motion.to_b(v[idx[chunk]], t[owner[chunk]])
        hit = shapely.contains_xy(inner, q[:, 0], q[:, 1])
        if hit.any():
            return q[np.argmax(hit)]
    return None


def _dangle_closures(tool_band, motion: MateMotion, q, th, pair, xr, nr, grown,
                     module: float):
    """Curves that close the envelope where its linked curves end inside B's blank (a
    root with one link: a branch jump dropped, a root pair merging at a tangency, or the
    seam of a motion that does not repeat). Without them polygonize drops the dangling
    curve and the tooth space it bounds merges with B's material face. At each dangling
    root q (contact angle theta, A's outline point x, outward normal n): A's outline at
    that position near x (within ``MATE_DANGLE_REACH`` module; it passes through q and
    lies in the swept region, so it only subdivides faces) and a segment from q to the
    point ``MATE_DANGLE_DEPTH`` module inside A there (it crosses that outline, however
    tangent the envelope is to it). Neighbouring dangling ends' outlines cross each other,
    closing the gap between them to within a scallop of the motion's step. Returns a list
    of shapely geometries in B's frame."""
    import shapely

    deg = np.bincount(pair.ravel(), minlength=len(q)) if len(pair) else np.zeros(len(q), int)
    d = np.flatnonzero((deg == 1) & shapely.contains_xy(grown, q[:, 0], q[:, 1]))
    if not len(d):
        return []
    inner = motion.to_b(xr[d] - MATE_DANGLE_DEPTH * module * nr[d], th[d])
    out = [shapely.multilinestrings(shapely.linestrings(np.stack([q[d], inner], axis=1)))]
    discs = shapely.buffer(shapely.points(xr[d]), MATE_DANGLE_REACH * module, quad_segs=16)
    local = shapely.intersection(shapely.boundary(tool_band), discs)
    xy, idx = shapely.get_coordinates(local, return_index=True)
    if len(xy):
        local = shapely.set_coordinates(local.copy(), motion.to_b(xy, th[d][idx]))
        out.append(shapely.union_all(local))
    return out


def _covered_by_mate(tool, motion: MateMotion, reps, q, th, x, pitch, window,
                     reach: MateReach | None = None):
    """Whether each B-frame point of ``reps`` (F, 2) lies inside ``tool`` (A's frame) at
    some position of the motion within the window about the contact angle of the
    envelope point of ``q``/``th`` nearest it (``window`` pitches of arc each way; with
    ``reach``: inside a piece of A at a position within that piece's reach, positions
    searched within the reach and a piece of the nearest point's):
    ``MATE_GRID_PER_PITCH`` positions per
    pitch of arc; a point found in none is tried again at 64 positions about the one where
    it came nearest A's outline points ``x`` (not missed between two positions)."""
    import shapely
    from scipy.spatial import cKDTree

    shapely.prepare(tool)
    _, j = cKDTree(q).query(reps)
    s0 = motion.arc(th[j])
    span = window if reach is None else (reach.half + reach.piece) / pitch  # pitches
    W = span * pitch
    steps = int(2 * span * MATE_GRID_PER_PITCH) + 1
    off = np.linspace(-W, W, steps)

    def inside(rows, s):
        """Whether the points ``rows`` lie in A at contact arcs ``s`` (rows, k): (rows, k)
        bool, and their A-frame points."""
        t = _theta_in_cycle(motion, s)
        xa = motion.to_a(np.broadcast_to(reps[rows, None, :], t.shape + (2,)), t)
        hit = shapely.contains_xy(tool, xa[..., 0].ravel(), xa[..., 1].ravel()
                                  ).reshape(t.shape)
        if reach is not None:  # only the pieces within their reach cut
            mid = reach.middle(motion.arc(np.arctan2(xa[..., 1], xa[..., 0])))
            hit &= reach.within(mid, s)
        return hit, xa

    # first the positions within half a pitch of the nearest envelope point's (where a
    # face of a space is mostly covered), then the whole window for the rest
    hit = np.zeros(len(reps), bool)
    near = np.abs(off) <= 0.5 * pitch
    for cols, rows in ((off[near], np.arange(len(reps))), (off[~near], None)):
        rows = np.flatnonzero(~hit) if rows is None else rows
        if not len(rows):
            break
        hit[rows] = inside(rows, s0[rows, None] + cols[None, :])[0].any(axis=1)
    miss = np.flatnonzero(~hit)
    if len(miss):
        _, xa = inside(miss, s0[miss, None] + off[None, :])
        # (positions farther than a pitch from every outline point need no exact distance)
        dist, near_x = cKDTree(x).query(xa.reshape(-1, 2), distance_upper_bound=pitch)
        if reach is not None:  # the nearest approach of a piece within its reach
            s_pos = np.broadcast_to(s0[miss, None] + off[None, :], xa.shape[:-1]).ravel()
            found = near_x < len(x)
            mid_x = reach.middle(motion.arc(np.arctan2(x[near_x[found], 1],
                                                       x[near_x[found], 0])))
            dist[np.flatnonzero(found)[~reach.within(mid_x, s_pos[found])]] = np.inf
        best = off[np.argmin(dist.reshape(len(miss), -1), axis=1)]
        fine = best[:, None] + np.linspace(-1.0, 1.0, 64)[None, :] * (off[1] - off[0])
        hit[miss] = inside(miss, s0[miss, None] + fine)[0].any(axis=1)
    miss = np.flatnonzero(~hit)
    if len(miss) and reach is not None:
        # a face bounded by a piece's outline where it enters or leaves the cut may be
        # inside it only over a short span there: the pieces' reach ends (just inside)
        mids = (np.arange(reach.count) + 0.5) * reach.piece
        eps = 1e-6 * reach.piece
        ends = np.r_[mids - reach.half + eps, mids + reach.half - eps]
        for chunk in np.array_split(miss, max(1, len(miss) // 64)):
            s_end = np.broadcast_to(ends, (len(chunk), len(ends)))
            hit[chunk] = inside(chunk, s_end)[0].any(axis=1)
    return hit


def _reach_ends(tool_band, motion: MateMotion, reach: MateReach, grown):
    """Each piece of A's band (``reach``: the simulated cut's pieces) at the two ends of
    its reach, where it enters and leaves the cut: its outline, the wedge's cut edges
    included, in B's frame (the parts within ``grown``, B's blank grown by the longest
    link). Returns a list of shapely geometries."""
    import shapely

    from plantmech.gears.teeth import _pieces

    pieces, middles, plen = _pieces(tool_band, motion.pitch_a, reach.piece)
    if len(pieces) != reach.count or abs(plen - reach.piece) > 1e-9 * reach.piece:
        raise MateEnvelopeUnfit("the simulated cut's pieces differ from the reach's")
    lines = shapely.boundary(pieces)
    xy, idx = shapely.get_coordinates(lines, return_index=True)
    out = []
    for sign in (-1.0, 1.0):
        t = motion.theta(middles + sign * reach.half)
        placed = shapely.set_coordinates(lines.copy(), motion.to_b(xy, t[idx]))
        out += [g for g in shapely.intersection(placed, grown) if not g.is_empty]
    return out


def _theta_in_cycle(motion: MateMotion, s):
    """Contact angles of arcs ``s`` (mm); on a motion that does not repeat, positions
    beyond its ends are held at them (the cut starts and ends there)."""
    return motion.theta(s)
