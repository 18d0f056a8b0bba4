"""Stages and the twelve objectives (i)-(xii) of seed 001 for transplanting mechanisms,
computed from a ``TransplanterMotion`` (arrays over designs x arms x samples).

Every definition the paper leaves open is written down in docs/conventions.md
("Seed 001 objectives") with its default; the numbers here follow it:

- seedling box frame: origin at the door point (Yx, Yy), u along the box floor
  (direction Ya, up the slope), v normal to it on the mat side; the mat lies in
  0 <= v <= thickness.
- ground: ``planting_depth`` above the lowest tip point of arm 0.
- stages per arm: picking = tip inside the mat layer near the door; planting = from
  entering the ground to the lowest point; conveying in between; return the rest.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from plantmech.design import TransplanterLimitsSpec as TransplanterLimits  # noqa: F401
from plantmech.geometry.refine import cyclic_extreme
from plantmech.mechanisms.transplanter import TransplanterMotion
from plantmech.objectives import Check, limit_text, relative_violation

TWO_PI = 2.0 * np.pi


@dataclass
class FieldSetup:
    """Everything around the mechanism (mm, deg)."""

    box_x: float = 165.0
    box_y: float = 70.0
    box_inclination_deg: float = 52.0
    mat_thickness: float = 20.0
    sample: float = 8.0
    box_length: float = 300.0
    door_length: float = 15.0  # slotted floor at the door: the needle may pass
    floor_thickness: float = 5.0
    planting_depth: float = 25.0
    spacing_nominal: float | np.ndarray = 120.0  # mm, or (P,): per design (travel speed)
    spacing_range: tuple = (60.0, 180.0)
    carrier_speed_deg_s: float = 360.0
    check_height: float = 100.0  # height above ground for the forward inclination
    gearbox_radius: float | None = None
    needle_length: float = 40.0  # last part of A->B allowed through the seedling door
    outline: dict | None = None  # {layer: polygon (K, 2)} in the arm frame (mm)


def default_outline(arm, needle_cut: float = 0.0) -> dict[str, np.ndarray]:
    """Arm outline (mm) in the arm frame: origin at the planet axis, x along the arm line
    towards the tip B = (S, 0), break point A at H1 e^{i acos(H1/S)}. Two layers, as on
    rotary planting arms where the fork is mounted outside the housing: ``housing``, a
    20 mm wide band from 15 mm behind the planet axis to A, and ``fork``, an 8 mm wide
    band from A to the tip, shortened by ``needle_cut`` mm (documented default; any
    polygons can be given). Arrays (K, 2), or (P, K, 2) for a population of arms."""
    S = np.asarray(arm.S, float)
    a = np.asarray(arm.H1, float) * np.exp(1j * arm.break_angle)
    b = S + 0j

    def band(p, q, half, back=0.0, cut=0.0):
        d = (q - p) / np.abs(q - p)
        p = p - back * d
        q = q - cut * d
        nrm = 1j * d
        pts = np.stack([p + half * nrm, q + half * nrm, q - half * nrm, p - half * nrm], -1)
        return np.stack([pts.real, pts.imag], -1)

    return {"housing": band(0j * a, a, 10.0, back=15.0), "fork": band(a, b, 4.0, cut=needle_cut)}


def _circular_mean_deg(values, mask):
    z = np.where(mask, np.exp(1j * np.radians(values)), 0.0)
    s = z.sum(axis=-1)
    out = np.mod(np.degrees(np.angle(s)), 360.0)
    return np.where(mask.any(axis=-1), out, np.nan)


def _run_around(mask, centre):
    """Start and end indices (cyclic) of the True run of ``mask`` (..., S) that contains
    index ``centre`` (...,)."""
    S = mask.shape[-1]
    k = np.arange(S)
    c = centre[..., None]
    back = np.where(~mask, np.mod(c - k, S), S)
    back = np.where(back == 0, S, back).min(axis=-1)
    fwd = np.where(~mask, np.mod(k - c, S), S)
    fwd = np.where(fwd == 0, S, fwd).min(axis=-1)
    return np.mod(centre - back + 1, S), np.mod(centre + fwd - 1, S)


def _span_mask(S, start, end):
    k = np.arange(S)
    return np.mod(k - start[..., None], S) <= np.mod(end - start, S)[..., None]


def _take(a, idx):
    return np.take_along_axis(a, np.mod(idx, a.shape[-1])[..., None], axis=-1)[..., 0]


@dataclass
class TransplanterEvaluation:
    names: list[str]
    units: list[str]
    limits: list[str]
    values: np.ndarray  # (P, K)
    ok: np.ndarray
    violation: np.ndarray
    metrics: dict = field(default_factory=dict)

    @property
    def feasible(self):
        return self.ok.all(axis=1)

    def checks(self, p: int = 0) -> list[Check]:
        notes = self.metrics.get("notes", {})
        out = []
        for n, u, lim, v, o in zip(self.names, self.units, self.limits, self.values[p],
                                   self.ok[p], strict=True):
            note = notes.get(n, "")
            if not np.isfinite(v):
                note = (f"not computed: {PICK_MISSING}" if n in PICK_DEPENDENT
                        else "not computed") + (f". {note}" if note else "")
            out.append(Check(n, None if not np.isfinite(v) else round(float(v), 6), lim,
                             bool(o), u, note))
        return out


PICK_DEPENDENT = {"picking_angle", "angle_difference", "seedling_block_skew",
                  "needle_seedling_angle"}
PICK_MISSING = "the tip never passes through the seedling mat (check the box position)"


def stages(motion: TransplanterMotion, setup: FieldSetup) -> dict:
    """Stage boundaries (sample indices, (P, J)) and the box/ground geometry."""
    B = motion.B
    S = B.shape[-1]
    col = lambda v: np.asarray(v, float).reshape(-1, 1, 1)  # noqa: E731
    u_dir = np.exp(1j * np.radians(col(setup.box_inclination_deg)))
    box = (B - (col(setup.box_x) + 1j * col(setup.box_y))) / u_dir
    u, v = box.real, box.imag
    in_mat = ((v >= 0) & (v <= setup.mat_thickness) & (u >= -setup.sample - 10.0)
              & (u <= setup.box_length))
    has_pick = in_mat.any(axis=-1)
    deepest = np.argmin(np.where(in_mat, v, np.inf), axis=-1)
    p0, p1 = _run_around(in_mat, deepest)
    # the lowest point of arm 0's path, between the samples (geometry.refine)
    lowest = cyclic_extreme(B[:, 0].imag, motion.tip_rate[:, 0].imag, TWO_PI / S,
                            largest=False)
    ground = lowest + setup.planting_depth  # (P,)
    below = B.imag < ground[:, None, None]
    kmin = np.argmin(B.imag, axis=-1)
    g_start, g_end = _run_around(below, kmin)
    return {"u": u, "v": v, "in_mat": in_mat, "has_pick": has_pick, "pick": (p0, p1),
            "plant": (g_start, kmin), "below": (g_start, g_end), "ground_y": ground, "S": S}


def evaluate(motion: TransplanterMotion, setup: FieldSetup, limits: TransplanterLimits,
             perimeter=None, teeth: int | None = None, gearbox_radius=None,
             interference: bool = True, gear_fit: dict | None = None
             ) -> TransplanterEvaluation:
    """The twelve objectives for all designs (values (P, K)), and, given ``gear_fit``
    (``gears.internal.tooth_fit``), two manufacturability objectives beyond the paper:
    (xiii) smallest equivalent tooth count, (xiv) working pressure angle."""
    st = stages(motion, setup)
    P, J, S = motion.B.shape
    psi_deg = np.degrees(motion.carrier_angle)
    # the needle direction of arm 0 (the objectives' arm), deg: A -> B, as needle_angle
    needle = np.mod(np.degrees(np.angle(motion.B[:, 0] - motion.A[:, 0])), 360.0)  # (P, S)
    names, units, lims, vals, viol, notes = [], [], [], [], [], {}

    def add(name, value, lo, hi, unit, note=""):
        value = np.asarray(value, dtype=float)
        names.append(name)
        units.append(unit)
        lims.append(limit_text(lo, hi, unit))
        vals.append(value)
        # anything not finite counts as not computed
        viol.append(relative_violation(np.where(np.isfinite(value), value, np.nan), lo, hi))
        if note:
            notes[name] = note

    # --- (i), (ii) interference (outline polygons) -------------------------------
    if interference:
        clear_arms, clear_box = _interference(motion, setup)
    else:
        clear_arms = clear_box = np.full(P, np.nan)
    add("arms_clearance", clear_arms, 0.0, None, "mm",
        "(i) smallest distance between any two arm outlines over the cycle")
    add("arm_box_clearance", clear_box, 0.0, None, "mm",
        "(ii) smallest distance between an arm (without its needle) and the seedling mat "
        "or the box floor")
    # --- (iii)-(v) angles over the stages of arm 0 ---------------------------------
    p0, p1 = st["pick"]
    g0, g1 = st["plant"]
    pick_mask = _span_mask(S, p0[:, 0], p1[:, 0]) & st["has_pick"][:, :1]
    plant_mask = _span_mask(S, g0[:, 0], g1[:, 0])
    pick_ang = _circular_mean_deg(needle, pick_mask)
    push_ang = _circular_mean_deg(needle, plant_mask)
    add("picking_angle", pick_ang, *limits.picking_angle_deg, "deg",
        "(iii) mean needle angle (A -> B, CCW from +x) while the tip is in the seedling mat")
    add("pushing_angle", push_ang, *limits.pushing_angle_deg, "deg",
        "(iv) mean needle angle from entering the ground to the lowest point")
    diff = np.mod(pick_ang - push_ang + 180.0, 360.0) - 180.0
    add("angle_difference", diff, *limits.angle_difference_deg, "deg",
        "(v) picking angle - pushing angle")
    # --- (vi) rectangular seedling block ------------------------------------------
    u, v = st["u"][:, 0], st["v"][:, 0]
    a0, a1 = p0[:, 0], p1[:, 0]
    rows = np.arange(P)
    th = setup.mat_thickness

    def cross(i0, i1, level):
        ua, ub = u[rows, np.mod(i0, S)], u[rows, np.mod(i1, S)]
        va, vb = v[rows, np.mod(i0, S)], v[rows, np.mod(i1, S)]
        t = (level - va) / np.where(vb == va, np.nan, vb - va)
        ok = (t >= -1e-9) & (t <= 1 + 1e-9)
        return np.where(ok, ua + t * (ub - ua), np.nan)

    u_top = cross(a0 - 1, a0, th)
    u_bot = cross(a1, a1 + 1, 0.0)
    add("seedling_block_skew", np.abs(u_top - u_bot), None, limits.rectangularity_mm, "mm",
        "(vi) |upper - lower surface length| of the picked block: where the needle's pass "
        "crosses the mat's top and bottom surfaces, along the box floor")
    # --- (vii) trajectory height above ground ---------------------------------------
    S = motion.B.shape[-1]
    height = cyclic_extreme(motion.B[:, 0].imag, motion.tip_rate[:, 0].imag, TWO_PI / S,
                            largest=True) - st["ground_y"]  # between the samples
    add("trajectory_height", height, limits.min_trajectory_height_mm, None, "mm",
        "(vii) highest tip point above the ground (against bridging)")
    # --- (viii), (ix) absolute trajectory -------------------------------------------
    w = np.radians(setup.carrier_speed_deg_s)
    vel = motion.tip_rate[:, 0] * w  # mm/s (P, S)
    kmin = g1[:, 0]
    fwd_sign = -np.sign(_take(vel.real, kmin))  # machine moves against the tip at the bottom
    fwd_sign = np.where(fwd_sign == 0, 1.0, fwd_sign)
    per_turn = J  # one plant per arm per carrier turn
    spacing = np.asarray(setup.spacing_nominal, dtype=float)
    incl = _forward_inclination(motion.B[:, 0], kmin, st["ground_y"], fwd_sign,
                                spacing * per_turn, setup.check_height,
                                motion.tip_rate[:, 0])
    spacing_text = (f"{float(spacing):g} mm" if spacing.ndim == 0 else
                    f"{spacing.min():g}-{spacing.max():g} mm over the designs")
    add("forward_inclination", incl, limits.min_forward_inclination_deg, None, "deg",
        "(viii) angle to the forward ground of the absolute path from leaving the ground to "
        f"{setup.check_height:g} mm above it (nominal spacing {spacing_text})")
    spacings = np.arange(setup.spacing_range[0], setup.spacing_range[1] + 1e-9, 10.0)
    widths = _hole_width(motion.B[:, 0], st["below"][0][:, 0], st["below"][1][:, 0], fwd_sign,
                         spacings * per_turn, motion.tip_rate[:, 0], st["ground_y"])
    add("hole_width", widths.max(axis=1), None, limits.max_hole_width_mm, "mm",
        f"(ix) widest hole over plant spacings {spacings[0]:g}-{spacings[-1]:g} mm")
    # --- (x) gearbox clearance -------------------------------------------------------
    if gearbox_radius is None:
        gearbox_radius = np.full(P, np.nan)
    clearance = -np.asarray(gearbox_radius) - st["ground_y"]
    add("gearbox_clearance", clearance, limits.min_gearbox_clearance_mm, None, "mm",
        "(x) ground below the gearbox's lowest point")
    # --- (xi) module ---------------------------------------------------------------------
    module = (np.asarray(perimeter) / (np.pi * teeth) if perimeter is not None and teeth
              else np.full(P, np.nan))
    add("module", module, limits.min_module_mm, None, "mm",
        f"(xi) pitch-curve perimeter / (pi z), z = {teeth}")
    # --- (xii) needle vs seedlings at picking ------------------------------------------
    nd = np.radians(_take(needle, a0))
    into_mat = np.radians(np.asarray(setup.box_inclination_deg, float)) - np.pi / 2  # -v
    ang = np.degrees(np.arccos(np.abs(np.cos(nd - into_mat))))
    ang = np.where(st["has_pick"][:, 0], ang, np.nan)
    add("needle_seedling_angle", ang, limits.min_needle_angle_deg, None, "deg",
        "(xii) angle between the needle and the seedlings' growth direction (normal to the "
        "box floor) where the needle enters the mat")
    # --- beyond the paper: can the pitch curves carry teeth of this module? ---------------
    if gear_fit is not None:
        add("equivalent_teeth", gear_fit["min_equivalent_teeth"], limits.min_equivalent_teeth,
            None, "", "(xiii) smallest 2|rho|/m over the internal and planet pitch curves "
            "(rho: radius of curvature; below 8 no shaper fits a concave span, convex spans "
            "are cut to pointed teeth)")
        add("internal_teeth_difference", gear_fit["min_internal_teeth_difference"],
            limits.min_internal_teeth_difference, None, "",
            "(xv) smallest z_int_eq - z_planet_eq where the ring curves around the planet "
            "(circular internal pairs at 20 deg foul below 8, tests/test_teeth.py)")
        add("working_pressure_angle", gear_fit["max_working_pressure_angle_deg"], None,
            limits.max_working_pressure_angle_deg, "deg",
            "(xiv) tool pressure angle + largest atan(|dr/dtheta| / r) of the pair")
        add("cuttable_module_margin", gear_fit["cuttable_module_mm"] - module, 0.0, None, "mm",
            "largest module the pitch curves can be cut with (no undercut or pointed tooth, "
            "a shaper for the ring, internal difference; docs/manufacturing.md) minus the "
            "design's module (xi)")
    values = np.stack(vals, axis=1)
    violation = np.stack(viol, axis=1)
    stage_deg = {}
    for name, (s0, s1) in (("picking", (p0, p1)), ("planting", (g0, g1))):
        stage_deg[name] = np.stack([psi_deg[s0], psi_deg[s1]], axis=-1)  # (P, J, 2)
    stage_deg["picking"] = np.where(st["has_pick"][..., None], stage_deg["picking"], np.nan)
    metrics = {"notes": notes, "ground_y_mm": st["ground_y"], "stages_deg": stage_deg,
               "u_top_mm": u_top, "u_bottom_mm": u_bot, "hole_widths_mm": widths,
               "spacings_mm": spacings, "forward_sign": fwd_sign,
               "block_upper_mm": setup.sample + (u_top - u_bot) / 2,
               "block_lower_mm": setup.sample - (u_top - u_bot) / 2}
    return TransplanterEvaluation(names, units, lims, values, violation <= 0, violation, metrics)


def _forward_inclination(B, kmin, ground, fwd_sign, advance_per_turn, check_height,
                         rate=None):
    """Angle (deg) between the forward ground direction and the chord of the absolute
    path from where the tip leaves the ground to where it is ``check_height`` above it
    (all designs at once; ``advance_per_turn`` mm, shared or (P,)). With ``rate`` (dB/dpsi
    at the samples, mm/rad) both crossings are located on the path's cubic Hermite
    segments between the samples (``geometry.refine``), else at the first sample past
    them."""
    from plantmech.geometry.periodic import hermite_basis
    from plantmech.geometry.refine import hermite_crossing

    P, S = B.shape
    idx = np.mod(kmin[:, None] + np.arange(S)[None, :], S)  # from the lowest point on
    z = np.take_along_axis(B, idx, axis=1)
    y = z.imag
    advance = np.reshape(np.asarray(advance_per_turn, dtype=float), (-1, 1))  # (1 or P, 1)
    x = z.real * fwd_sign[:, None] + advance * np.arange(S)[None, :] / S
    up = y >= ground[:, None]
    k0 = np.argmax(up, axis=1)
    hi = (y >= (ground + check_height)[:, None]) & (np.arange(S)[None, :] > k0[:, None])
    k1 = np.argmax(hi, axis=1)
    rows = np.arange(P)
    ends = []
    for k, level in ((k0, ground), (k1, ground + check_height)):
        yk, xk = y[rows, k], x[rows, k]
        if rate is None:
            ends.append((xk, yk))
            continue
        h = TWO_PI / S
        j = np.maximum(k - 1, 0)  # the segment j -> k holds the crossing (k > 0)
        rj, rk = rate[rows, idx[rows, j]], rate[rows, idx[rows, k]]
        adv = advance[:, 0] / S
        dxj, dxk = rj.real * fwd_sign * h + adv, rk.real * fwd_sign * h + adv
        s_ = hermite_crossing(y[rows, j], yk, rj.imag * h, rk.imag * h, level)
        xs = hermite_basis(x[rows, j], xk, dxj, dxk, s_, 1.0)[0]
        ys = hermite_basis(y[rows, j], yk, rj.imag * h, rk.imag * h, s_, 1.0)[0]
        ends.append((np.where(k > 0, xs, xk), np.where(k > 0, ys, yk)))
    (xa, ya), (xb, yb) = ends
    ang = np.degrees(np.arctan2(yb - ya, xb - xa))
    return np.where(up.any(axis=1) & hi.any(axis=1), ang, np.nan)


def _hole_width(B, start, end, fwd_sign, advances, rate=None, ground=None):
    """Horizontal extent (mm) of the absolute path under the ground for each machine
    advance per carrier turn (P, len(advances)). Only the samples under the ground enter
    (a short run of the cycle), grouped by design. With ``rate`` (dB/dpsi, mm/rad) and
    ``ground`` (P,) the extent is the path's between the samples too (``geometry.refine``):
    the cubic Hermite segments' extremes between the samples under the ground and the
    points where the path crosses the ground (on the segments entering and leaving)."""
    P, S = B.shape
    rows, cols = np.nonzero(_span_mask(S, start, end))  # row-major: design by design
    out = np.full((P, len(advances)), -np.inf)  # a design with no sample: -inf, as max - min
    if rows.size == 0:
        return out
    t = np.mod(cols - start[rows], S) / S
    x = B.real[rows, cols] * fwd_sign[rows]
    xa = x[None, :] + advances[:, None] * t[None, :]  # (A, N)
    has = np.bincount(rows, minlength=P) > 0
    first = np.searchsorted(rows, np.flatnonzero(has))
    hi_x = np.maximum.reduceat(xa, first, axis=1).T  # (designs with samples, A)
    lo_x = np.minimum.reduceat(xa, first, axis=1).T
    if rate is not None:
        from plantmech.geometry.periodic import hermite_basis
        from plantmech.geometry.refine import hermite_crossing, hermite_extreme

        h = TWO_PI / S
        adv = advances[:, None]

        def xs(p, c, tt):  # x of the absolute path and its slope per sample at (p, c)
            return (B.real[p, c] * fwd_sign[p] + adv * tt,
                    rate.real[p, c] * fwd_sign[p] * h + adv / S)

        # between consecutive samples under the ground: the extremes of the segments next
        # to the largest and the smallest sample (the curve's lie there)
        inside = cols != end[rows]
        nxt = np.mod(cols + 1, S)
        x0, d0 = xs(rows, cols, t)
        x1, d1 = xs(rows, nxt, t + 1.0 / S)
        group = (np.cumsum(has) - 1)[rows]  # row of hi_x / lo_x of each sample
        tol = 1e-9 * (1.0 + np.abs(xa))
        for ext, largest, fold in ((hi_x, True, np.maximum), (lo_x, False, np.minimum)):
            at = ext.T[:, group]  # (A, N): the design's sampled extreme
            near = inside[None, :] & ((np.abs(x0 - at) <= tol) | (np.abs(x1 - at) <= tol))
            a_i, n_i = np.nonzero(near)
            v = hermite_extreme(x0[a_i, n_i], x1[a_i, n_i], d0[a_i, n_i], d1[a_i, n_i],
                                largest=largest)[1]
            fold.at(ext, (group[n_i], a_i), v)
        # where the path crosses the ground: entering (the segment start - 1 -> start)
        # and leaving (end -> end + 1)
        p = np.flatnonzero(has)
        g = np.asarray(ground, dtype=float)[p]
        for c0, tt0 in ((np.mod(start[p] - 1, S), -1.0 / S),
                        (end[p], np.mod(end[p] - start[p], S) / S)):
            c1 = np.mod(c0 + 1, S)
            s_ = hermite_crossing(B.imag[p, c0], B.imag[p, c1], rate.imag[p, c0] * h,
                                  rate.imag[p, c1] * h, g)
            xa0, da0 = xs(p, c0, tt0)
            xa1, da1 = xs(p, c1, tt0 + 1.0 / S)
            xc = hermite_basis(xa0, xa1, da0, da1, s_[None, :], 1.0)[0].T
            hi_x, lo_x = np.maximum(hi_x, xc), np.minimum(lo_x, xc)
    out[has] = hi_x - lo_x
    return out


def box_parts(setup: FieldSetup, P: int) -> list[np.ndarray]:
    """The solid parts of the seedling box for P designs, as polygons (P, 4) (complex, mm):
    the mat on the floor and the floor plate (slotted over ``door_length`` at the door).
    They share the floor line: the box is their union."""
    col = lambda v: np.broadcast_to(np.asarray(v, float), (P,))  # noqa: E731
    u = np.exp(1j * np.radians(col(setup.box_inclination_deg)))[:, None]
    o = (col(setup.box_x) + 1j * col(setup.box_y))[:, None]
    L, t, door, fl = setup.box_length, setup.mat_thickness, setup.door_length, setup.floor_thickness
    return [o + np.asarray(corners, complex)[None, :] * u
            for corners in ([0, L, L + 1j * t, 1j * t],
                            [door - 1j * fl, L - 1j * fl, L + 0j, door + 0j])]


def outline_layers(arm, setup: FieldSetup) -> tuple[dict, dict]:
    """The arm's outline layers (name -> polygon (K, 2) or (P, K, 2), mm, arm frame) and
    the same without the needle (the last ``needle_length`` of A -> B, which may pass the
    seedling door) for the box check: the design file's outline or ``default_outline``."""
    if not setup.outline:
        return default_outline(arm), default_outline(arm, needle_cut=setup.needle_length)
    import shapely

    layers = {k: np.asarray(v, float) for k, v in setup.outline.items()}
    a0 = arm.take(0)
    a = a0.H1 * np.exp(1j * a0.break_angle)
    d = (a0.S - a) / abs(a0.S - a)
    cut_at = a0.S - setup.needle_length * d
    big = 1e4
    keep = shapely.Polygon([(p.real, p.imag) for p in (
        cut_at + 1j * d * big - d * big, cut_at - 1j * d * big - d * big,
        cut_at - 1j * d * big, cut_at + 1j * d * big)])
    cut = {}
    for k, v in layers.items():
        part = shapely.Polygon(v).intersection(keep)
        if not part.is_empty:
            cut[k] = np.asarray(part.exterior.coords)[:-1]
    return layers, cut


def _interference(motion: TransplanterMotion, setup: FieldSetup):
    """Smallest clearance (mm) between parts of different arms on the same layer (i) and
    between an arm without its needle and the seedling box (ii), for every design; -1
    where outlines overlap. Exact polygon clearances over every sample, all designs at
    once (``geometry.polygons.smallest_clearance``)."""
    from plantmech.geometry.polygons import smallest_clearance

    P, J, S = motion.B.shape
    layers, cut = outline_layers(motion.arm_geometry, setup)
    rot = motion.arm_direction  # arm frame -> world: rot z + centre
    shift = motion.centre

    def polygon(coords):
        xy = np.asarray(coords, float)
        return np.atleast_2d(xy[..., 0] + 1j * xy[..., 1])  # (P or 1, K)

    same_layer = [(polygon(c), polygon(c)) for c in layers.values()]
    clear_arms = np.full(P, np.inf if J > 1 else np.nan)
    for j in range(J):
        for jj in range(j + 1, J):
            clear_arms = np.minimum(clear_arms, smallest_clearance(
                same_layer, (rot[:, j], shift[:, j]), (rot[:, jj], shift[:, jj])))
    poses = (rot.reshape(P, J * S), shift.reshape(P, J * S))
    parts = box_parts(setup, P)
    clear_box = smallest_clearance([(polygon(c), part) for c in cut.values() for part in parts],
                                   poses, (1.0, 0.0))
    return clear_arms, clear_box
