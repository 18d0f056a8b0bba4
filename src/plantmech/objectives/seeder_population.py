"""Section-4.1 objectives and gear checks of a whole population of seeder trains at
once (arrays over designs x samples; no Python loop per design or per sample).

The same quantities as ``objectives.seeder`` for one design; section points are
either given as carrier angles or located on each design's tip path near reference
angles. Used by the optimizer (issue 6) and the app.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from plantmech.mechanisms.seeder_batch import PopulationMotion, periodic_spline_matrix
from plantmech.objectives import relative_violation

TWO_PI = 2.0 * np.pi
LETTERS = ("a", "b", "c", "d", "e", "f")


def refine_minimum(values: np.ndarray, k: np.ndarray, step: float):
    """Sub-sample minimum of cyclic rows ``values`` (P, S) near their samples k (P, m):
    the vertex of the parabola through k - 1, k, k + 1. Returns (offset from sample k in
    the units of ``step`` (within +-step / 2), value at the vertex), each (P, m)."""
    rows = np.arange(values.shape[0])[:, None]
    S = values.shape[1]
    a, b, c = values[rows, (k - 1) % S], values[rows, k], values[rows, (k + 1) % S]
    curv = a - 2.0 * b + c
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(curv > 0, 0.5 * (a - c) / curv, 0.0)
    t = np.clip(t, -0.5, 0.5)
    return t * step, b - 0.25 * (a - c) * t


def locate_sections(tip: np.ndarray, psi: np.ndarray, points: np.ndarray,
                    reference: np.ndarray, window: float = np.radians(40.0)) -> np.ndarray:
    """(P, 6) carrier angles (rad) where each design's tip passes closest to each
    section point (6, 2), searched within +-window of the reference angles (6,), refined
    between samples (``refine_minimum``)."""
    P = tip.shape[0]
    out = np.empty((P, len(points)))
    step = float(psi[1] - psi[0])
    for j, (pt, ref) in enumerate(zip(points, reference, strict=True)):  # 6 points
        d2 = (tip[..., 0] - pt[0]) ** 2 + (tip[..., 1] - pt[1]) ** 2
        near = np.abs(np.angle(np.exp(1j * (psi - ref)))) <= window
        k = np.argmin(np.where(near[None, :], d2, np.inf), axis=1)
        shift, _ = refine_minimum(d2, k[:, None], step)
        out[:, j] = np.mod(psi[k] + shift[:, 0], TWO_PI)
    return out


def _mask(psi, start, end):
    """(P, S) membership of carrier angles psi (S,) in clockwise sections [start, end]
    given per design (P,)."""
    span = np.mod(end - start, TWO_PI)[:, None]
    return np.mod(psi[None, :] - start[:, None], TWO_PI) <= span


def _at(psi, values, where):
    """values (P, S) at angles ``where`` (P,) or (P, k), linearly interpolated between the
    uniform samples psi (S,) (periodic)."""
    S = values.shape[1]
    w = np.asarray(where, dtype=float)
    squeeze = w.ndim == 1
    f = np.mod(w[:, None] if squeeze else w, TWO_PI) / (psi[1] - psi[0])
    k = np.floor(f).astype(int) % S
    t = f - np.floor(f)
    rows = np.arange(values.shape[0])[:, None]
    out = (1.0 - t) * values[rows, k] + t * values[rows, (k + 1) % S]
    return out[:, 0] if squeeze else out


def section_swing(psi, rel, start, end) -> np.ndarray:
    """(P,) largest |rel - rel(start)| over the clockwise sections [start, end] (P,) of
    rows ``rel`` (P, S) sampled at psi (S,), both section ends included."""
    s = _at(psi, rel, start)
    dev = np.where(_mask(psi, start, end), np.abs(rel - s[:, None]), 0.0)
    return np.maximum(dev.max(axis=1), np.abs(_at(psi, rel, end) - s))


def section_extreme(psi, values, start, end, largest: bool) -> np.ndarray:
    """(P,) largest (or smallest) of rows ``values`` (P, S) over the clockwise sections
    [start, end] (P,), the values at both section ends (interpolated) included."""
    ends = _at(psi, values, np.c_[start, end])
    if largest:
        return np.maximum(np.where(_mask(psi, start, end), values, -np.inf).max(axis=1),
                          ends.max(axis=1))
    return np.minimum(np.where(_mask(psi, start, end), values, np.inf).min(axis=1),
                      ends.min(axis=1))


def pitch_curve_metrics(nodes, radii, a, contact0=0.0, kind: str = "spline",
                        dense: int = 2048, turn_scale=None) -> dict:
    """Shape of a gear (P, N radii) and of its mate at centre distance a (P,), vectorized:
    ``shapes`` (gear, mate) as ``manufacturability.GearShape`` (signed radius of curvature
    on the material, radius, body angle, perimeter), ``mu`` (P, dense) the angle (rad)
    between the pitch tangent and the normal to the radius vector at the contact, and per
    curve ``min_kappa_r`` (min curvature x radius: 1 for a circle, negative where concave),
    ``concave_spans`` and ``min_radius_mm``.

    The mate is the polar curve rho = a - r, phi' = r / (a - r), phi'' = a r' / (a - r)^2
    in the gear's body angle t (one gear turn is one mate turn in both papers' closed pairs).
    """
    from plantmech.gears.manufacturability import shape_pair

    t = contact0 + np.linspace(0.0, TWO_PI, dense, endpoint=False)
    R = np.atleast_2d(radii)
    r, r1, r2 = (R @ periodic_spline_matrix(nodes, t, nu, kind).T for nu in (0, 1, 2))
    shapes, mu = shape_pair(t, r, r1, r2, a)
    out = {"shapes": list(shapes), "mu": mu}
    for shape in shapes:
        kappa = 1.0 / shape.curvature_radius
        concave = kappa < 0
        starts = concave & ~np.roll(concave, 1, axis=1)
        out[shape.name] = {"min_kappa_r": (kappa * shape.radius).min(axis=1),
                           "concave_spans": starts.sum(axis=1) + (concave.all(axis=1)),
                           "min_radius_mm": shape.radius.min(axis=1)}
    out["pressure_proxy_deg"] = np.degrees(mu).max(axis=1)
    return out


def add_manufacturability(add, pair: str, pm: dict, names: tuple[str, str], rules) -> object:
    """Add the manufacturability checks of one pair (from ``pitch_curve_metrics``) through
    ``add(name, value, limit, upper, unit)``: the largest module its pitch curves can be cut
    with (``cuttable_module_<pair>``, at least the smallest module) and the working pressure
    angle. Returns the ``PairVerdict``."""
    from plantmech.gears.manufacturability import CuttingRules, PairShape, assess_pair

    rules = rules or CuttingRules()
    for shape, name in zip(pm["shapes"], names, strict=True):
        shape.name = name
    v = assess_pair(PairShape(pair, tuple(pm["shapes"]), pm["mu"]), rules)
    add(f"cuttable_module_{pair}", v.module_high, rules.min_module_mm, False, "mm")
    add(f"working_pressure_angle_{pair}", v.working_pressure_angle_deg,
        rules.max_working_pressure_angle_deg, True, "deg")
    return v


@dataclass
class PopulationEvaluation:
    """Objective values of P designs: ``values`` (P, K) in the units of ``units``,
    ``ok`` (P, K), ``violation`` (P, K) >= 0 (relative amount beyond the limit)."""

    names: list[str]
    units: list[str]
    limits: list[str]
    values: np.ndarray
    ok: np.ndarray
    violation: np.ndarray
    metrics: dict = field(default_factory=dict)

    @property
    def feasible(self) -> np.ndarray:
        return self.ok.all(axis=1)


def evaluate_population(motion: PopulationMotion, section_psi: np.ndarray,
                        carrier_speed_deg_s: float = 360.0, travel_m_s=None,
                        attitude=None, speed=None, gear2: dict | None = None,
                        gear3: dict | None = None, rules=None,
                        curve_samples: int = 720) -> PopulationEvaluation:
    """Every section-4.1 objective for all designs.

    section_psi: (6,) or (P, 6) carrier angles (rad) of a-f. travel_m_s: None =
    zero-speed seeding at e per design (Eq. 18, horizontal tip velocity at e), else the
    machine's travel speed (m/s), shared or (P,).
    gear2/gear3: optional dicts(nodes, radii, contact0, kind) to add the pitch-curve
    manufacturability checks of each pair (``add_manufacturability`` with ``rules``, a
    ``manufacturability.CuttingRules``), evaluated at ``curve_samples`` body angles per curve.
    """
    from plantmech.design import Attitude, SpeedLimits

    attitude = attitude or Attitude()
    speed = speed or SpeedLimits()
    psi = motion.carrier_angle
    P = motion.tip.shape[0]
    sec = np.broadcast_to(np.asarray(section_psi, dtype=float), (P, 6))
    A = dict(zip(LETTERS, sec.T, strict=True))
    rel = np.degrees(motion.arm_angle - motion.arm_angle[:, :1])  # attitude (P, S)
    names, units, limits, vals, viol = [], [], [], [], []

    def add(name, value, lim, upper, unit, note_scale=None):
        names.append(name)
        units.append(unit)
        limits.append(f"{'<' if upper else '>'} {lim:g} {unit}")
        vals.append(value)
        lo, hi = (None, lim) if upper else (lim, None)
        viol.append(relative_violation(value, lo, hi,
                                       abs(lim) if note_scale is None else note_scale, np.nan))
        return value

    add("picking_swing", section_swing(psi, rel, A["a"], A["b"]),
        attitude.picking_swing_max_deg, True, "deg")
    add("seeding_swing", section_swing(psi, rel, A["d"], A["e"]),
        attitude.seeding_swing_max_deg, True, "deg")
    sowing = _at(psi, rel, A["e"])
    add("sowing_angle", np.abs(sowing), attitude.sowing_angle_max_deg, True, "deg")
    v = motion.tip_rate * (np.radians(carrier_speed_deg_s) / 1000.0)  # (P, S, 2) m/s
    vx_e = _at(psi, v[..., 0], A["e"])
    travel = vx_e if travel_m_s is None else np.broadcast_to(np.asarray(travel_m_s, float), (P,))
    static = np.hypot(v[..., 0], v[..., 1])
    dynamic = np.hypot(v[..., 0] - travel[:, None], v[..., 1])
    add("seeding_peak_speed", section_extreme(psi, static, A["d"], A["e"], True),
        speed.seeding_max_m_s, True, "m/s")
    add("return_min_speed_static", section_extreme(psi, static, A["e"], A["f"], False),
        speed.return_min_m_s, False, "m/s")
    add("return_min_speed_dynamic", section_extreme(psi, dynamic, A["e"], A["f"], False),
        speed.return_min_m_s, False, "m/s")
    metrics = {"zero_speed_travel_m_s": vx_e, "travel_m_s": travel, "sowing_angle_deg": sowing,
               "closure_error_rad": motion.closure_error, "a1_mm": motion.a1,
               "a2_mm": motion.a2}
    for label, g, a, pair in (("gear2", gear2, motion.a1, "sun_gear2"),
                              ("gear3", gear3, motion.a2, "gear3_planet")):
        if g is None:
            continue
        pm = pitch_curve_metrics(g["nodes"], g["radii"], a, g.get("contact0", 0.0),
                                 g.get("kind", "spline"), dense=curve_samples)
        mate = "sun" if label == "gear2" else "planet"
        add_manufacturability(add, pair, pm, (label, mate), rules)
        metrics[label] = {k: v for k, v in pm.items() if k not in ("shapes", "mu")}
    values = np.stack(vals, axis=1)
    violation = np.stack(viol, axis=1)
    ok = violation <= 0.0
    return PopulationEvaluation(names, units, limits, values, ok, violation, metrics)
