"""Can these pitch curves be cut? The manufacturability rules of non-circular gears, in one place.

The conditions are the standard ones of the non-circular gear literature (Litvin & Fuentes,
*Gear Geometry and Applied Theory*, 2nd ed., ch. 9 "Noncircular gears": generation by a rack
or a shaper, the equivalent spur gear of each span, the pressure angle of a non-circular pair),
applied to the pitch curves *before* any tooth is cut, vectorised over P designs so an optimizer
can require them. docs/manufacturing.md states each rule with its numbers.

Every rule becomes a bound on the module m (mm) of a gear pair, so one number decides a pair:
the **module window** [m_lo, m_hi]. A pair can be cut iff m_hi >= m_lo and its working pressure
angle is within its limit.

- **Convex spans, no undercut, no pointed teeth.** The equivalent spur gear of a convex span
  with radius of curvature rho has z_eq = 2 rho / m teeth; a rack of addendum ha m and pressure
  angle alpha does not undercut it while z_eq >= 2 ha / sin^2(alpha) (17.1 at 20 deg, ha = 1),
  and its top land stays above ``min_top_land`` m while z_eq >= the pointed-tooth limit
  (``pointed_teeth``). So m <= 2 rho_min / z_min.
- **Concave spans** can only be cut by a shaper cutter whose pitch radius is below the span's
  radius of curvature, and the span meshes with it like an internal gear with the cutter as
  pinion: 2 |rho| / m >= z_cutter_min + dz_min, so m <= 2 |rho|min / (z_c + dz).
- **Internal pairs**: where the ring curves around the planet, the local pair is an internal
  spur pair z_ring,eq / z_planet,eq; tip and trochoid interference need their difference
  2 (rho_ring - rho_planet) / m >= dz_min.
- **Hub**: below the root (dedendum hf m) at least ``hub_modules`` modules of material and a
  bore of ``min_bore_mm``: r_min - (hf + hub) m >= bore / 2.
- **Tooth count**: at least ``min_teeth`` on the perimeter P: m <= P / (pi min). And the
  design's own minimum module (strength), ``min_module_mm``: the window's lower end.
- **Working pressure angle** alpha + max atan(|dr/dtheta| / r) <= limit: two rolling pitch
  curves share their tangent at the contact on the line of centres, so the angle between the
  contact normal and the line of motion of the driven point grows by atan(|r'| / r) (the
  angle mu between the tangent and the normal to the radius vector). It does not depend on m.
"""

from __future__ import annotations

import functools
from dataclasses import asdict, dataclass, field

import numpy as np

from plantmech.gears.modules import FIRST_SERIES


def _inv(a):
    return np.tan(a) - a


@dataclass(frozen=True)
class CuttingRules:
    """Tooth system and the limits of what the workshop can cut (module-relative sizes are
    multiples of m)."""

    pressure_angle_deg: float = 20.0  # tool pressure angle alpha
    addendum: float = 1.0  # ha, x m
    dedendum: float = 1.25  # hf, x m
    min_cutter_teeth: int = 12  # smallest shaper cutter for concave spans and internal gears
    min_internal_difference: float = 8.0  # dz: ring - planet (or span - cutter) equivalent teeth
    min_top_land: float = 0.25  # x m, a tooth thinner at its tip is "pointed"
    max_working_pressure_angle_deg: float = 45.0
    hub_modules: float = 1.5  # material below the root, x m
    min_bore_mm: float = 3.0
    min_teeth: int = 8
    min_module_mm: float = 1.0  # strength: the design's smallest acceptable module

    @property
    def alpha(self) -> float:
        return float(np.radians(self.pressure_angle_deg))

    @property
    def undercut_teeth(self) -> float:
        """Smallest rack-cut tooth count free of undercut: 2 ha / sin^2(alpha)."""
        return 2.0 * self.addendum / np.sin(self.alpha) ** 2

    @functools.cached_property
    def pointed_teeth(self) -> float:
        """Smallest tooth count whose standard tooth keeps a top land of ``min_top_land`` m:
        s_a = d_a (pi / (2 z) + inv(alpha) - inv(alpha_a)), d = z m, d_a = d + 2 ha m
        (bisection on z; the top land grows with z). Computed once per rules object (61
        evaluations; the rules are frozen)."""
        a = self.alpha

        def land(z):
            za = z + 2 * self.addendum
            aa = np.arccos(z * np.cos(a) / za)
            return za * (np.pi / (2 * z) + _inv(a) - _inv(aa)) - self.min_top_land

        lo, hi = 1.0, 200.0
        if land(lo) >= 0:
            return lo
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if land(mid) >= 0 else (mid, hi)
        return hi

    @property
    def min_equivalent_teeth(self) -> float:
        """z_eq a convex span needs: no undercut and no pointed tooth."""
        return max(self.undercut_teeth, self.pointed_teeth)

    def record(self) -> dict:
        return {**asdict(self), "undercut_teeth": round(float(self.undercut_teeth), 3),
                "pointed_teeth": round(float(self.pointed_teeth), 3)}


@dataclass
class GearShape:
    """One pitch curve of P designs sampled at N body angles.

    ``curvature_radius`` (P, N) mm, signed on the gear's material: positive where the material
    is convex (an external gear's convex span, an internal gear's inward bulge), negative where
    it is concave; ``radius`` (P, N) pitch radius r (mm); ``angle`` (N,) or (P, N) body angle
    (rad) for locating findings; ``perimeter`` (P,) mm."""

    name: str
    curvature_radius: np.ndarray
    radius: np.ndarray
    angle: np.ndarray
    perimeter: np.ndarray
    internal: bool = False
    toothed: np.ndarray | None = None  # (P, N) bool: False on a toothless sector


@dataclass
class PairShape:
    """A gear pair: its two gears, ``mu`` (P, N) the angle (rad) between the pitch tangent and
    the normal to the radius vector at the contact, and for internal pairs ``internal_difference``
    (P, N): 2 (rho_ring - rho_planet) (mm) where the ring curves around the planet (+inf
    elsewhere); ``module`` (P,) mm when the design fixes it (else the window decides)."""

    name: str
    gears: tuple[GearShape, GearShape]
    mu: np.ndarray
    internal_difference: np.ndarray | None = None
    module: np.ndarray | None = None


@dataclass
class PairVerdict:
    """Arrays over P designs for one pair; ``limits`` name each bound's binding gear and
    place."""

    name: str
    module_low: np.ndarray
    module_high: np.ndarray
    module: np.ndarray  # chosen (or fixed) module, mm; nan where none fits
    teeth: dict = field(default_factory=dict)  # gear -> (P,) tooth count at the module
    working_pressure_angle_deg: np.ndarray = None
    bounds: dict = field(default_factory=dict)  # reason -> (P,) module bound, mm
    where: dict = field(default_factory=dict)  # reason -> (gear, (P,) body angle deg)

    @property
    def module_ok(self) -> np.ndarray:
        return self.module_high >= self.module_low

    def ok(self, rules: CuttingRules) -> np.ndarray:
        return self.module_ok & (self.working_pressure_angle_deg
                                 <= rules.max_working_pressure_angle_deg) & np.isfinite(self.module)


def rules_for(design, tool: dict | None = None) -> CuttingRules:
    """The cutting rules of a design file: its [manufacturing] table, the tool pressure angle
    and working-pressure-angle limit of [gear_checks] (seeder) or [limits] (transplanters:
    (xiv), and (xi) as the smallest module, (xv) as the internal difference); ``tool``
    (pressure_angle_deg, addendum, dedendum) overrides the tooth proportions (CLI options)."""
    m = design.manufacturing
    kw = {"addendum": m.addendum, "dedendum": m.dedendum, "min_cutter_teeth": m.min_cutter_teeth,
          "min_internal_difference": m.min_internal_difference, "min_top_land": m.min_top_land,
          "hub_modules": m.hub_modules, "min_bore_mm": m.min_bore_mm,
          "min_module_mm": m.min_module_mm}
    checks = getattr(design, "gear_checks", None)  # the seeder's [gear_checks]
    if checks is not None:
        kw["pressure_angle_deg"] = checks.tool_pressure_angle_deg
        kw["max_working_pressure_angle_deg"] = checks.max_working_pressure_angle_deg
    else:
        lim = design.limits
        kw["max_working_pressure_angle_deg"] = lim.max_working_pressure_angle_deg
        kw["min_module_mm"] = lim.min_module_mm
        kw["min_internal_difference"] = lim.min_internal_teeth_difference
    if m.pressure_angle_deg is not None:
        kw["pressure_angle_deg"] = m.pressure_angle_deg
    kw.update({k: v for k, v in (tool or {}).items() if v is not None})
    return CuttingRules(**kw)


def _argmin_angle(values: np.ndarray, angle: np.ndarray) -> np.ndarray:
    k = np.argmin(values, axis=1)
    ang = np.broadcast_to(angle, values.shape)
    return np.degrees(np.mod(np.take_along_axis(ang, k[:, None], 1)[:, 0], 2 * np.pi))


def module_bounds(name: str, convex_min, concave_min, radius_min, perimeter,
                  rules: CuttingRules, internal: bool = False) -> dict:
    """Upper module bounds (mm, (P,)) of one gear from its extremes: the smallest convex
    and concave (magnitude) radius of curvature on its toothed spans (inf where none), its
    smallest pitch radius and its perimeter (mm, (P,) each): undercut / pointed teeth,
    shaper-cut concave spans, the hub (external gears) and the tooth count."""
    bounds = {f"undercut/pointed {name}": 2.0 * np.asarray(convex_min)
              / rules.min_equivalent_teeth,
              # an internal gear is cut by a shaper everywhere: its concave spans too
              f"concave span {name}": 2.0 * np.asarray(concave_min)
              / (rules.min_cutter_teeth + rules.min_internal_difference)}
    if not internal:  # a ring's material (its rim) lies outside: no hub question
        bounds[f"hub {name}"] = ((np.asarray(radius_min) - rules.min_bore_mm / 2.0)
                                 / (rules.dedendum + rules.hub_modules))
    bounds[f"teeth {name}"] = np.asarray(perimeter) / (np.pi * rules.min_teeth)
    return bounds


def module_high(bounds: dict) -> np.ndarray:
    """The largest module (P,) mm all ``bounds`` allow (a NaN bound does not bind)."""
    high = None
    for b in bounds.values():
        b = np.where(np.isnan(b), np.inf, b)
        high = b if high is None else np.minimum(high, b)
    return high


def _gear_bounds(g: GearShape, rules: CuttingRules) -> tuple[dict, dict]:
    """Upper module bounds (mm, (P,)) of one gear and where each binds (body angle, deg)."""
    rho = np.asarray(g.curvature_radius, dtype=float)
    mask = np.ones_like(rho, dtype=bool) if g.toothed is None else g.toothed
    big = np.inf
    convex = np.where(mask & (rho > 0), rho, big)
    concave = np.where(mask & (rho < 0), -rho, big)
    r = np.where(mask, g.radius, big)
    return gear_bounds(g.name, (convex.min(axis=1), _argmin_angle(convex, g.angle)),
                       (concave.min(axis=1), _argmin_angle(concave, g.angle)),
                       (r.min(axis=1), _argmin_angle(r, g.angle)), g.perimeter, rules,
                       g.internal)


def gear_bounds(name: str, convex, concave, radius, perimeter, rules: CuttingRules,
                internal: bool = False) -> tuple[dict, dict]:
    """Upper module bounds (mm, (P,)) of one gear and where each binds, from its extremes
    on its toothed spans: ``convex``, ``concave`` and ``radius`` are each ((P,) smallest
    value (mm; inf where none), (P,) body angle of the first smallest, deg) of the convex
    and concave (magnitude) radius of curvature and the pitch radius; ``perimeter`` (P,)
    mm. ``_gear_bounds`` (from the sampled shape) and a fused kernel's reductions
    (``trains.fused``) both end here."""
    bounds = module_bounds(name, convex[0], concave[0], radius[0], perimeter, rules, internal)
    where = {f"undercut/pointed {name}": (name, convex[1]),
             f"concave span {name}": (name, concave[1])}
    if not internal:
        where[f"hub {name}"] = (name, radius[1])
    where[f"teeth {name}"] = (name, np.full(np.shape(convex[0])[0], np.nan))
    return bounds, where


def assess_pair(pair: PairShape, rules: CuttingRules) -> PairVerdict:
    """Module window, chosen module and working pressure angle of P designs of one pair."""
    bounds, where = {}, {}
    for g in pair.gears:
        b, w = _gear_bounds(g, rules)
        bounds.update(b)
        where.update(w)
    if pair.internal_difference is not None:
        d = np.asarray(pair.internal_difference, dtype=float)
        bounds[f"internal difference {pair.name}"] = d.min(axis=1) / rules.min_internal_difference
        where[f"internal difference {pair.name}"] = (pair.gears[0].name,
                                                     _argmin_angle(d, pair.gears[0].angle))
    mu = np.abs(np.asarray(pair.mu, dtype=float))
    return pair_verdict(pair.name, [(g.name, g.perimeter) for g in pair.gears], bounds, where,
                        (mu.max(axis=1), _argmin_angle(-mu, pair.gears[0].angle)),
                        pair.module, rules)


def pair_verdict(name: str, perimeters: list, bounds: dict, where: dict, mu, module,
                 rules: CuttingRules) -> PairVerdict:
    """The verdict of a pair from its gears' module ``bounds`` and ``where`` they bind
    (``gear_bounds``, and the internal difference's), its gears' ``perimeters`` [(name,
    (P,) mm)], driver first, ``mu`` ((P,) largest |mu| rad, (P,) its body angle deg on the
    first gear) and the fixed ``module`` (None: the window chooses)."""
    P = np.shape(mu[0])[0]
    high = np.minimum(np.full(P, np.inf), module_high(bounds))
    low = np.full(P, rules.min_module_mm)
    if module is not None:
        module = np.broadcast_to(np.asarray(module, dtype=float), (P,)).copy()
        low = np.maximum(low, module)  # the fixed module must fit: m <= m_hi
    else:
        module = choose_module(perimeters[0][1], low, high)
    teeth = {g: np.where(np.isfinite(module), np.round(np.asarray(perim)
                                                       / (np.pi * np.where(
                                                           np.isfinite(module), module,
                                                           1.0))), np.nan)
             for g, perim in perimeters}
    work = rules.pressure_angle_deg + np.degrees(mu[0])
    where["working pressure angle"] = (perimeters[0][0], mu[1])
    return PairVerdict(name, low, high, module, teeth, work, bounds, where)


def shape_from_polar(name: str, t, rho, drho, ddrho, dphi=None, ddphi=None,
                     internal: bool = False, toothed=None) -> GearShape:
    """GearShape of P polar pitch curves (rho(t), phi(t)) sampled at N uniform parameters t
    (rad, (N,)) with their t-derivatives ((P, N) each; phi = t when ``dphi`` is None): the
    signed radius of curvature on the material side, the body angle phi (running integral of
    phi'), the perimeter (integral of the arc speed over one period of t: for a mate, t must
    span one turn of the mate, as it does for the closed pairs of both papers' trains)."""
    from plantmech.geometry.periodic import polar_curvature_radius

    rho, drho, ddrho = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (rho, drho, ddrho))
    t = np.asarray(t, dtype=float)
    h = 2 * np.pi / t.size
    if dphi is None:  # phi = t: phi' = 1, phi'' = 0 as numbers (no (P, N) tables of them)
        dphi, ddphi, phi = 1.0, 0.0, np.broadcast_to(t, rho.shape)
    else:
        dphi, ddphi = np.atleast_2d(dphi), np.atleast_2d(ddphi)
        phi = t[0] + np.cumsum(dphi, axis=1) * h - dphi * h
    rc = polar_curvature_radius(rho, drho, ddrho, dphi, ddphi)
    perimeter = np.sqrt(drho**2 + (rho * dphi) ** 2).sum(axis=1) * h
    return GearShape(name, -rc if internal else rc, rho, phi, perimeter, internal, toothed)


def shape_pair(t, r, r1, r2, a, names=("gear", "mate")) -> tuple[tuple[GearShape, GearShape],
                                                                 np.ndarray]:
    """(gear, mate) shapes and the contact angle mu (P, N) (rad) of P external pairs from the
    gear's radius r(t) and its t-derivatives ((P, N) each) at centre distance a ((P,) or
    scalar, mm): the mate is rho = a - r, phi' = r / (a - r), phi'' = a r' / (a - r)^2."""
    r, r1, r2 = (np.atleast_2d(x) for x in (r, r1, r2))
    a = np.reshape(np.asarray(a, dtype=float), (-1, 1))
    gear = shape_from_polar(names[0], t, r, r1, r2)
    mate = shape_from_polar(names[1], t, a - r, -r1, -r2, r / (a - r), a * r1 / (a - r) ** 2)
    return (gear, mate), np.arctan(np.abs(r1) / r)


def choose_module(perimeter, low, high) -> np.ndarray:
    """The largest standard module in [low, high] (ISO 54 first choice) turned into a whole
    tooth count on ``perimeter`` (m = P / (pi z), z = ceil(P / (pi m_std)), so m <= m_std);
    where no standard module fits, the window's largest whole-tooth module; nan if none.
    Vectorised over designs (P,)."""
    P = np.atleast_1d(np.asarray(perimeter, dtype=float))
    low = np.broadcast_to(np.asarray(low, dtype=float), P.shape)
    high = np.broadcast_to(np.asarray(high, dtype=float), P.shape)
    std = np.asarray(FIRST_SERIES)
    fits = (std[None, :] <= high[:, None]) & (std[None, :] >= low[:, None])
    m0 = np.where(fits.any(axis=1), np.where(fits, std[None, :], -np.inf).max(axis=1),
                  np.minimum(high, P / np.pi))
    with np.errstate(divide="ignore", invalid="ignore"):
        m = P / (np.pi * np.ceil(P / (np.pi * m0) - 1e-9))
        # the whole tooth count pushed m below the window: take the largest fit
        z = np.floor(P / (np.pi * low) + 1e-9)
        m = np.where(m < low, np.where(z >= 1, P / (np.pi * z), np.nan), m)
    return np.where((high >= low) & (m >= low) & (m <= high), m, np.nan)


def violation(v: PairVerdict, rules: CuttingRules, margin: float = 0.0) -> np.ndarray:
    """(P, 2) relative violations for optimizers: module window (1 - m_hi / (m_lo (1 +
    margin))) and working pressure angle (relative to its limit); 0 where met."""
    need = v.module_low * (1.0 + margin)
    with np.errstate(divide="ignore", invalid="ignore"):
        mod = np.where(np.isfinite(v.module_high), np.maximum(0.0, 1.0 - v.module_high / need),
                       0.0)
    lim = rules.max_working_pressure_angle_deg * (1.0 - margin)
    pa = np.maximum(0.0, (v.working_pressure_angle_deg - lim) / lim)
    return np.stack([np.nan_to_num(mod, nan=1.0), pa], axis=1)


def binding(v: PairVerdict, k: int = 0) -> tuple[str, str, float]:
    """(reason, gear, body angle deg) of the tightest upper module bound of design k."""
    name = min(v.bounds, key=lambda n: v.bounds[n][k] if np.isfinite(v.bounds[n][k]) else np.inf)
    gear, ang = v.where[name]
    return name, gear, float(ang[k])


def findings(v: PairVerdict, rules: CuttingRules, k: int = 0) -> list[dict]:
    """What cannot be cut in design k of this pair: [{gear, check, value, limit, unit, where,
    body_angle_deg, why}] (empty when the pair can be cut); ``where`` says the place in
    words, ``body_angle_deg`` (deg, to 0.1; None where there is no one place) in a number."""
    out = []
    lo, hi = float(v.module_low[k]), float(v.module_high[k])
    if not hi >= lo:
        reason, gear, ang = binding(v, k)
        where = f"body angle {ang:.1f} deg" if np.isfinite(ang) else ""
        out.append({"gear": gear, "pair": v.name, "check": "module window",
                    "value": round(hi, 4), "limit": round(lo, 4), "unit": "mm", "where": where,
                    "body_angle_deg": round(float(ang), 1) if np.isfinite(ang) else None,
                    "why": f"{reason} allows a module of at most {hi:.3f} mm, the pair needs "
                           f"at least {lo:.3f} mm (strength or tooth count)"})
    w = float(v.working_pressure_angle_deg[k])
    if w > rules.max_working_pressure_angle_deg:
        gear, ang = v.where["working pressure angle"]
        out.append({"gear": gear, "pair": v.name, "check": "working pressure angle",
                    "value": round(w, 2), "limit": rules.max_working_pressure_angle_deg,
                    "unit": "deg", "where": f"body angle {float(ang[k]):.1f} deg",
                    "body_angle_deg": round(float(ang[k]), 1),
                    "why": f"tool {rules.pressure_angle_deg:g} deg + pitch tangent "
                           f"{w - rules.pressure_angle_deg:.1f} deg off the normal to the "
                           "radius: the teeth push almost along the radius"})
    return out


def pair_record(v: PairVerdict, rules: CuttingRules, k: int = 0) -> dict:
    """JSON-ready summary of design k of one pair."""
    reason, gear, ang = binding(v, k)
    m = float(v.module[k])
    return {"pair": v.name, "module_window_mm": [round(float(v.module_low[k]), 4),
                                                 round(float(v.module_high[k]), 4)],
            "module_mm": round(m, 4) if np.isfinite(m) else None,
            "teeth": {g: int(z[k]) for g, z in v.teeth.items() if np.isfinite(z[k])},
            "tightest_bound": {"reason": reason, "gear": gear,
                               "body_angle_deg": round(ang, 2) if np.isfinite(ang) else None},
            "working_pressure_angle_deg": round(float(v.working_pressure_angle_deg[k]), 3),
            "ok": bool(v.ok(rules)[k]), "findings": findings(v, rules, k)}
