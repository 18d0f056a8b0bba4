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
    between samples (the parabola of ``refine_minimum``), one pass per design
    (``seeder_kernel.locate_rows``)."""
    from plantmech.mechanisms.seeder_kernel import locate_rows

    psi = np.asarray(psi, dtype=float)
    points = np.ascontiguousarray(np.asarray(points, dtype=float).reshape(-1, 2))
    reference = np.asarray(reference, dtype=float).reshape(-1)
    near = np.abs(np.angle(np.exp(1j * (psi[None, :] - reference[:, None])))) <= window
    count = near.sum(axis=1)
    # each point's window as its ascending sample indices (padded rows): the kernel scans
    # those only, in the order the full mask would
    order = np.argsort(~near, axis=1, kind="stable")
    out = np.empty((tip.shape[0], len(points)))
    locate_rows(np.ascontiguousarray(tip, dtype=float), psi, points,
                np.ascontiguousarray(order, dtype=np.int64), count.astype(np.int64), out)
    return out


def section_values(psi, angle, section_psi, rate, angle_scale: float = 1.0,
                   rate_scale: float = 1.0, travel_m_s=None) -> np.ndarray:
    """Section-4.1 values (P, 8) of P designs sampled at uniform carrier angles psi (S,):
    attitude rel = (angle - angle[:, 0]) * angle_scale (deg) from angles (P, S), tip
    velocity rate * rate_scale (m/s) from rates (P, S, 2), sections a..f at
    ``section_psi`` ((6,) or (P, 6) rad), travel speed ``travel_m_s`` (m/s, shared or (P,);
    None: zero-speed seeding at e, the horizontal tip speed there, Eq. 18). Columns:
    picking swing over ab and seeding swing over de (deg, largest change from the
    section's start), attitude at e (deg, signed), horizontal tip speed at e, travel speed,
    seeding peak static speed over de, return minimum static and dynamic speed over ef
    (m/s); section ends interpolated and included. One pass per design
    (``seeder_kernel.section_objectives_rows``): the forward population and the inverse
    population (layer 1) both evaluate their sections here."""
    from plantmech.mechanisms.seeder_kernel import section_objectives_rows

    angle = np.ascontiguousarray(np.asarray(angle, dtype=float))
    P = angle.shape[0]
    sec = np.ascontiguousarray(np.broadcast_to(np.asarray(section_psi, dtype=float), (P, 6)))
    given = travel_m_s is not None
    travel = np.ascontiguousarray(np.broadcast_to(
        np.asarray(travel_m_s if given else 0.0, dtype=float), (P,)))
    out = np.empty((P, 8))
    section_objectives_rows(np.asarray(psi, dtype=float), angle,
                            float(angle_scale),
                            np.ascontiguousarray(np.asarray(rate, dtype=float)),
                            float(rate_scale), sec, travel, given, out)
    return out


def pitch_curve_metrics(nodes, radii, a, contact0=0.0, kind: str = "spline",
                        dense: int = 2048, rules=None,
                        names: tuple[str, str] = ("gear", "mate")) -> dict:
    """Shape of a gear (P, N radii at ``nodes``) and of its mate at centre distance a (P,),
    at ``dense`` body angles from ``contact0`` (shared or (P,)), and what it allows
    (``gears.manufacturability``): per curve ("gear", "mate") ``min_kappa_r`` (min
    curvature x radius: 1 for a circle, negative where concave), ``concave_spans`` and
    ``min_radius_mm``; ``pressure_proxy_deg`` (the largest angle between the pitch tangent
    and the normal to the radius vector); with ``rules`` (``CuttingRules``) the pair's
    ``module_high`` (mm, the largest module its curves can be cut with) and
    ``working_pressure_angle_deg``, bounds named by ``names``.

    The mate is the polar curve rho = a - r, phi' = r / (a - r), phi'' = a r' / (a - r)^2
    in the gear's body angle t (one gear turn is one mate turn in both papers' closed pairs),
    as ``manufacturability.shape_pair``; one fused pass per design (``seeder_kernel``): no
    (P, dense) arrays.
    """
    from plantmech.gears.manufacturability import module_bounds, module_high
    from plantmech.mechanisms.seeder_kernel import pitch_extremes_rows

    R = np.ascontiguousarray(np.atleast_2d(np.asarray(radii, dtype=float)))
    P = R.shape[0]
    nodes = np.asarray(nodes, dtype=float)
    slopes = np.ascontiguousarray(R @ periodic_spline_matrix(nodes, nodes, 1, kind).T)
    row = lambda v: np.ascontiguousarray(  # noqa: E731
        np.broadcast_to(np.asarray(v, dtype=float), (P,)))
    ext = np.empty((P, 14))
    pitch_extremes_rows(np.r_[nodes, nodes[0] + TWO_PI], R, slopes,
                        row(contact0), row(a), int(dense), ext)
    out = {}
    for key, col in (("gear", 0), ("mate", 6)):
        out[key] = {"min_kappa_r": ext[:, col + 4], "concave_spans": ext[:, col + 5],
                    "min_radius_mm": ext[:, col + 2]}
    out["pressure_proxy_deg"] = np.degrees(ext[:, 12])
    if rules is not None:
        bounds = {}
        for name, col in zip(names, (0, 6), strict=True):
            bounds.update(module_bounds(name, ext[:, col], ext[:, col + 1], ext[:, col + 2],
                                        ext[:, col + 3], rules))
        out["module_high"] = np.minimum(np.full(P, np.inf), module_high(bounds))
        out["working_pressure_angle_deg"] = rules.pressure_angle_deg + np.degrees(ext[:, 13])
    return out


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
    manufacturability checks of each pair (``pitch_curve_metrics`` with ``rules``, a
    ``manufacturability.CuttingRules``: the largest module the pair can be cut with and its
    working pressure angle), evaluated at ``curve_samples`` body angles per curve.
    """
    from plantmech.design import Attitude, SpeedLimits

    attitude = attitude or Attitude()
    speed = speed or SpeedLimits()
    psi = motion.carrier_angle
    vals = section_values(psi, motion.arm_angle, section_psi, motion.tip_rate,
                          np.degrees(1.0), np.radians(carrier_speed_deg_s) / 1000.0,
                          travel_m_s)
    names, units, limits, vals_, viol = [], [], [], [], []

    def add(name, value, lim, upper, unit, note_scale=None):
        names.append(name)
        units.append(unit)
        limits.append(f"{'<' if upper else '>'} {lim:g} {unit}")
        vals_.append(value)
        lo, hi = (None, lim) if upper else (lim, None)
        viol.append(relative_violation(value, lo, hi,
                                       abs(lim) if note_scale is None else note_scale, np.nan))
        return value

    add("picking_swing", vals[:, 0], attitude.picking_swing_max_deg, True, "deg")
    add("seeding_swing", vals[:, 1], attitude.seeding_swing_max_deg, True, "deg")
    add("sowing_angle", np.abs(vals[:, 2]), attitude.sowing_angle_max_deg, True, "deg")
    add("seeding_peak_speed", vals[:, 5], speed.seeding_max_m_s, True, "m/s")
    add("return_min_speed_static", vals[:, 6], speed.return_min_m_s, False, "m/s")
    add("return_min_speed_dynamic", vals[:, 7], speed.return_min_m_s, False, "m/s")
    metrics = {"zero_speed_travel_m_s": vals[:, 3], "travel_m_s": vals[:, 4],
               "sowing_angle_deg": vals[:, 2], "closure_error_rad": motion.closure_error,
               "a1_mm": motion.a1, "a2_mm": motion.a2}
    for label, g, a, pair in (("gear2", gear2, motion.a1, "sun_gear2"),
                              ("gear3", gear3, motion.a2, "gear3_planet")):
        if g is None:
            continue
        from plantmech.gears.manufacturability import CuttingRules

        rules = rules or CuttingRules()
        pm = pitch_curve_metrics(g["nodes"], g["radii"], a, g.get("contact0", 0.0),
                                 g.get("kind", "spline"), curve_samples, rules,
                                 (label, "sun" if label == "gear2" else "planet"))
        add(f"cuttable_module_{pair}", pm.pop("module_high"), rules.min_module_mm, False,
            "mm")
        add(f"working_pressure_angle_{pair}", pm.pop("working_pressure_angle_deg"),
            rules.max_working_pressure_angle_deg, True, "deg")
        metrics[label] = pm
    values = np.stack(vals_, axis=1)
    violation = np.stack(viol, axis=1)
    ok = violation <= 0.0
    return PopulationEvaluation(names, units, limits, values, ok, violation, metrics)
