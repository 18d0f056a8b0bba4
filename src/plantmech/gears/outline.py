"""Cut gear outlines as a workshop sees them: cleaning of Boolean debris (zero-width spikes
and slits), an independent spike detector, and the teeth found on a cut outline (where each
tooth is, its number and its tip land).

A simulated cut (teeth.py) subtracts thousands of cutter positions from a blank; where two
positions leave the blank's edge between them to within round-off, the difference carries
zero-width "spikes" (the outline runs out 0.001-0.19 mm and back to the same point) and
slits. They have no area, but an extruded solid falls apart on them (the seeder optimum's
sun was 27 STL bodies). ``clean_outline`` removes every feature narrower than 2 x
``CLEAN_WIDTH_MM`` by a morphological opening and closing (buffer -e/+e and +e/-e, mitred
so sharp corners stay sharp), which moves the rest of the outline by less than 1 um.

Conventions as in teeth.py: mm, the gear's rotation centre at the origin, body angles in
deg measured counter-clockwise from the body's +x axis.
"""

from __future__ import annotations

import numpy as np

CLEAN_WIDTH_MM = 2e-3  # e: features narrower than 2 e (mm) are debris, not material
FOLD_BACK_DEG = 170.0  # a vertex whose outline turns by more than this folds back (a spike)


def clean_outline(geom, width: float = CLEAN_WIDTH_MM):
    """``geom`` (shapely (multi)polygon, mm) without zero-width spikes, slits and crumbs:
    opening (buffer -e then +e: removes material narrower than 2 e) and closing (+e then
    -e: fills gaps narrower than 2 e), mitred joins so corners are kept; e = ``width``
    (mm). Returns the largest polygon (holes below 0.01 mm^2 dropped)."""
    import shapely

    g = shapely.make_valid(geom)
    kw = {"join_style": "mitre", "mitre_limit": 10.0}
    g = g.buffer(-width, **kw).buffer(width, **kw)
    g = g.buffer(width, **kw).buffer(-width, **kw)
    g = shapely.make_valid(g)
    if g.geom_type == "GeometryCollection":
        g = shapely.union_all([p for p in g.geoms if p.geom_type in ("Polygon",
                                                                       "MultiPolygon")])
    if g.geom_type == "MultiPolygon":
        g = max(g.geoms, key=lambda p: p.area)
    if g.is_empty:
        return g
    holes = [h for h in g.interiors if shapely.Polygon(h).area > 1e-2]
    g = shapely.Polygon(g.exterior, holes).simplify(2e-4)
    return g if g.geom_type == "Polygon" else clean_outline(g, width)


def rings_of(poly) -> list[np.ndarray]:
    """Every boundary ring of a polygon as an (N, 2) array without the closing point."""
    return [np.asarray(r.coords)[:-1, :2] for r in (poly.exterior, *poly.interiors)]


def fold_backs(poly, limit_deg: float = FOLD_BACK_DEG) -> np.ndarray:
    """Vertices (K, 2) of ``poly`` where the outline turns by more than ``limit_deg``: the
    two edges at the vertex fold back onto each other (the tip of a zero-width spike or
    slit). A clean gear outline turns by at most ~110 deg at a corner (a tooth flank
    meeting its root)."""
    out = []
    for xy in rings_of(poly):
        d = np.roll(xy, -1, axis=0) - xy
        keep = np.hypot(*d.T) > 1e-9
        xy = xy[keep]
        d = np.roll(xy, -1, axis=0) - xy
        h = np.arctan2(d[:, 1], d[:, 0])
        turn = np.abs(np.angle(np.exp(1j * (h - np.roll(h, 1)))))
        out.append(xy[turn > np.radians(limit_deg)])
    return np.vstack(out) if out else np.zeros((0, 2))


def teeth_on_outline(poly, pitch_xy: np.ndarray, module: float, addendum: float,
                     internal: bool = False, tip_tolerance: float | None = None) -> dict:
    """The teeth of a cut gear found on its outline: a tooth is a run of the outline beyond
    the pitch curve (outward for an external gear, inward for an internal one); its tip
    land is the length of the run within ``tip_tolerance`` (mm; default 0.01 m, at least
    1 um) of the addendum curve (pitch curve offset by h_a m, where the blank was left
    uncut). Teeth are numbered 1, 2, ... counter-clockwise from the first whose centre
    lies at body angle >= 0.

    Returns {"angle_deg": (Z,) body angle of each tooth's centre, "tip_land_mm": (Z,),
    "height_mm": (Z,) largest height above the pitch curve}."""
    import shapely
    from scipy.spatial import cKDTree

    tol = max(1e-3, 0.01 * module) if tip_tolerance is None else tip_tolerance
    base = shapely.Polygon(pitch_xy)
    rings = rings_of(poly)
    if internal:  # the toothed ring of an internal gear is the hole around the centre
        ring = min(rings[1:] or rings, key=lambda r: np.hypot(*r.T).mean())
    else:
        ring = rings[0]
    # densify to <= 0.02 m per segment so lands are measured to that resolution
    seg = np.roll(ring, -1, axis=0) - ring
    n = np.maximum(1, np.ceil(np.hypot(*seg.T) / (0.02 * module)).astype(int))
    f = np.concatenate([np.arange(k) / k for k in n])
    pts = np.repeat(ring, n, axis=0) + np.repeat(seg, n, axis=0) * f[:, None]
    # distance to the pitch curve: nearest point of a dense copy of it
    pseg = np.roll(pitch_xy, -1, axis=0) - pitch_xy
    pn = np.maximum(1, np.ceil(np.hypot(*pseg.T) / (0.01 * module)).astype(int))
    pf = np.concatenate([np.arange(k) / k for k in pn])
    dense = np.repeat(pitch_xy, pn, axis=0) + np.repeat(pseg, pn, axis=0) * pf[:, None]
    dist, _ = cKDTree(dense).query(pts)
    inside = shapely.contains_xy(base, pts[:, 0], pts[:, 1])
    height = np.where(inside == internal, dist, -dist)  # toward the tooth tips
    step = np.hypot(*(np.roll(pts, -1, axis=0) - pts).T)
    above = height > 0.0
    empty = {"angle_deg": np.zeros(0), "tip_land_mm": np.zeros(0), "height_mm": np.zeros(0)}
    if above.all() or not above.any():
        return empty
    # runs of ``above`` on the closed ring, started after a point below the pitch curve
    start = int(np.flatnonzero(~above)[0])
    order = np.roll(np.arange(len(pts)), -start)
    a = above[order]
    edges = np.diff(np.r_[0, a.astype(int), 0])
    begins, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    tip = height[order] >= addendum * module - tol
    ang, land, top = [], [], []
    for b, e in zip(begins, ends, strict=True):
        idx = order[b:e]
        if height[idx].max() < 0.25 * module:  # a ripple on the pitch curve, not a tooth
            continue
        # the tooth's centre: halfway (in body angle) between its two pitch crossings,
        # each interpolated between the last point below and the first above
        cross = []
        for i0, i1 in ((order[b - 1], order[b]), (order[e % len(order)], order[e - 1])):
            f = height[i0] / (height[i0] - height[i1])
            q = pts[i0] + f * (pts[i1] - pts[i0])
            cross.append(np.exp(1j * np.arctan2(q[1], q[0])))
        ang.append(np.degrees(np.mod(np.angle(cross[0] + cross[1]), 2 * np.pi)))
        land.append(float(step[order[b:e - 1]][tip[b:e - 1] & tip[b + 1:e]].sum()))
        top.append(float(height[idx].max()))
    ang, land, top = np.array(ang), np.array(land), np.array(top)
    k = np.argsort(ang, kind="stable")
    return {"angle_deg": ang[k], "tip_land_mm": land[k], "height_mm": top[k]}


def tooth_number(tooth_angles_deg: np.ndarray, angle_deg: float) -> int | None:
    """Number (1-based, as in ``teeth_on_outline``) of the tooth whose centre is nearest
    to body angle ``angle_deg``; None without teeth."""
    if len(tooth_angles_deg) == 0:
        return None
    d = np.abs(np.angle(np.exp(1j * np.radians(np.asarray(tooth_angles_deg) - angle_deg))))
    return int(np.argmin(d)) + 1
