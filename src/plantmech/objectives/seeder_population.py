"""Section-4.1 objectives and gear checks of a whole population of seeder trains at
once (arrays over designs x samples; no Python loop per design or per sample).

The one implementation of the section-4.1 values: ``objectives.seeder``'s one-design
tables are its rows with P = 1. Section points are either given as carrier angles or
located on each design's tip path (``locate_sections``). Used by the forward and inverse
jobs, the optimizer (issue 6), studies and the app.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from plantmech.mechanisms.seeder_batch import PopulationMotion, periodic_spline_matrix
from plantmech.objectives import relative_violation

TWO_PI = 2.0 * np.pi
LETTERS = ("a", "b", "c", "d", "e", "f")


def refine_minimum(values: np.ndarray, k: np.ndarray, step: float):
    """Sub-sample minimum of cyclic rows ``values`` (P, S) near their samples k (P, m)
    (the refinement ``locate_sections`` applies in its kernel, in NumPy):
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


def _local_minima(d2: np.ndarray, candidates: int) -> np.ndarray:
    """Sample indices (..., candidates) of the ``candidates`` deepest local minima of the
    cyclic rows d2 (..., S), deepest first (a row with fewer repeats its deepest)."""
    local = (d2 <= np.roll(d2, 1, axis=-1)) & (d2 <= np.roll(d2, -1, axis=-1))
    ranked = np.where(local, d2, np.inf)
    order = np.argsort(ranked, axis=-1)[..., :candidates]
    count = local.sum(axis=-1, keepdims=True)
    return np.where(np.arange(candidates) < np.maximum(count, 1), order, order[..., :1])


def _ordered_passes(angle: np.ndarray, miss: np.ndarray) -> np.ndarray:
    """Index (P, K) of the candidate pass (angles and misses (P, K, C)) of each point that
    keeps the K points in their cyclic order along the cycle with the smallest total miss;
    with no such combination, each point's first candidate (its closest pass)."""
    P, K, C = angle.shape
    combos = np.indices((C,) * K).reshape(K, -1).T  # (C^K, K)
    cols = np.arange(K)
    out = np.empty((P, K), dtype=np.int64)
    chunk = max(1, 2**22 // (len(combos) * K))  # designs per (chunk, C^K, K) temporary
    for lo in range(0, P, chunk):
        a = angle[lo:lo + chunk, cols, combos]  # (chunk, C^K, K)
        turn = np.mod(np.diff(np.concatenate([a, a[..., :1]], axis=-1), axis=-1),
                      TWO_PI).sum(axis=-1)
        cost = miss[lo:lo + chunk, cols, combos].sum(axis=-1)
        cost = np.where(np.abs(turn - TWO_PI) > 1e-9, np.inf, cost)
        best = np.argmin(cost, axis=1)
        none = ~np.isfinite(cost[np.arange(len(a)), best])
        out[lo:lo + chunk] = np.where(none[:, None], 0, combos[best])
    return out


def locate_sections(tip: np.ndarray, psi: np.ndarray, points: np.ndarray,
                    reference: np.ndarray | None = None,
                    window: float = np.radians(40.0), candidates: int = 4,
                    return_miss: bool = False):
    """(P, K) carrier angles (rad, in [0, 2 pi)) where each design's tip (P, S, 2) passes
    closest to each section point (K, 2) mm, sampled at the carrier angles psi (S,) rad
    (ascending; the refinement takes psi[1] - psi[0] as the step).

    One algorithm for one design and for a population: the closest sample among each
    point's candidates, refined between samples by the vertex of the parabola through the
    squared distances at it and its two neighbours (``refine_minimum``; one pass per design
    in ``seeder_kernel.locate_rows``). The candidates: with ``reference`` ((K,) rad, where
    a base design passes the points), the samples within +-``window`` of it; without, the
    ``candidates`` closest local approaches of the tip to each point, of which the
    combination that keeps the points in their order along the cycle with the smallest
    total miss is taken (an "8" passes near some points twice, near its crossing).
    ``return_miss``: also the distances (P, K) mm the tip misses the points by (at the
    vertex; the closest sample's when the parabola dips below 0, never NaN)."""
    from plantmech.mechanisms.seeder_kernel import locate_rows

    tip = np.ascontiguousarray(np.asarray(tip, dtype=float))
    psi = np.asarray(psi, dtype=float)
    points = np.ascontiguousarray(np.asarray(points, dtype=float).reshape(-1, 2))
    P, S = tip.shape[:2]
    K = len(points)
    if reference is not None:
        reference = np.asarray(reference, dtype=float).reshape(-1)
        near = np.abs(np.angle(np.exp(1j * (psi[None, :] - reference[:, None])))) <= window
        count = near.sum(axis=1)
        # each window is a cyclic run of samples: its first sample follows a sample outside
        first = np.argmax(near & ~np.roll(near, 1, axis=1), axis=1)
        first = np.where(count == S, 0, first)
        angle, miss = _locate(locate_rows, tip, psi, points,
                              np.broadcast_to(first, (P, K)), np.broadcast_to(count, (P, K)))
        return (angle, miss) if return_miss else angle
    d2 = ((tip[:, None, :, :] - points[None, :, None, :]) ** 2).sum(axis=-1)  # (P, K, S)
    cand = _local_minima(d2, candidates)  # (P, K, C)
    C = cand.shape[-1]
    angle, miss = _locate(locate_rows, tip, psi, np.repeat(points, C, axis=0),
                          cand.reshape(P, K * C), np.ones((P, K * C), dtype=np.int64))
    angle, miss = angle.reshape(P, K, C), miss.reshape(P, K, C)
    pick = _ordered_passes(angle, miss)[..., None]
    angle = np.take_along_axis(angle, pick, axis=2)[..., 0]
    miss = np.take_along_axis(miss, pick, axis=2)[..., 0]
    return (angle, miss) if return_miss else angle


def _locate(locate_rows, tip, psi, points, first, count):
    """``seeder_kernel.locate_rows`` on candidate runs (P, K): (angle, miss) (P, K)."""
    P, K = first.shape
    angle, miss = np.empty((P, K)), np.empty((P, K))
    locate_rows(tip, psi, points, np.ascontiguousarray(first, dtype=np.int64),
                np.ascontiguousarray(count, dtype=np.int64), angle, miss)
    return angle, miss


def section_table(psi, angle, section_psi, rate, angle_scale: float = 1.0,
                  rate_scale: float = 1.0, travel_m_s=None, full: bool = True) -> np.ndarray:
    """The section table (P, ``SECTION_COLUMNS``) of P designs sampled at carrier angles
    psi (S,) rad (ascending in [0, 2 pi), any spacing): attitude rel = (angle -
    angle[:, 0]) * angle_scale (deg) from angles (P, S), tip velocity rate * rate_scale
    (m/s) from rates (P, S, 2), sections a..f at ``section_psi`` ((6,) or (P, 6) rad),
    travel speed ``travel_m_s`` (m/s, shared or (P,); None: zero-speed seeding at e, the
    horizontal tip speed there, Eq. 18). Columns (``section_column``): per attitude
    section ab, bc, cd, de, ea its start, end, min, max and signed swing (deg, the value
    farthest from the start less the start); vx_e, vy_e (m/s at e), travel, the seeding
    section's peak static speed (de), the return section's least static and dynamic
    (Eq. 17) speed (ef), the peak dynamic speed over de, the cycle's peak and least
    static speed (m/s); section ends interpolated and included. One pass per design
    (``seeder_kernel.section_table_rows``): the one-design tables of ``objectives.seeder``,
    the forward population and the inverse population all read their sections here.
    ``full`` False: only the columns the section-4.1 objectives read (``section_values``:
    the swings of ab and de as |swing|, the speeds at e and over de and ef), the others NaN;
    the same numbers, ~40 % less work for the optimizer's populations."""
    from plantmech.mechanisms.seeder_kernel import SECTION_COLUMNS, section_table_rows

    angle = np.ascontiguousarray(np.asarray(angle, dtype=float))
    P = angle.shape[0]
    sec = np.ascontiguousarray(np.broadcast_to(np.asarray(section_psi, dtype=float), (P, 6)))
    given = travel_m_s is not None
    travel = np.ascontiguousarray(np.broadcast_to(
        np.asarray(travel_m_s if given else 0.0, dtype=float), (P,)))
    out = np.empty((P, SECTION_COLUMNS))
    section_table_rows(np.ascontiguousarray(psi, dtype=float), angle, float(angle_scale),
                       np.ascontiguousarray(np.asarray(rate, dtype=float)),
                       float(rate_scale), sec, travel, given, bool(full), out)
    return out


ATTITUDE_SECTION_NAMES = ("picking_ab", "transport_bc", "transport_cd", "seeding_de",
                          "return_efca")


def section_column(name: str, stat: str | None = None) -> int:
    """Column of ``section_table``: an attitude section's statistic
    (``section_column("seeding_de", "swing")``) or a speed column (``"peak_static_de"``)."""
    from plantmech.mechanisms.seeder_kernel import SECTION_STATS, SPEED_COLUMNS

    if stat is None:
        return 5 * len(ATTITUDE_SECTION_NAMES) + SPEED_COLUMNS.index(name)
    return 5 * ATTITUDE_SECTION_NAMES.index(name) + SECTION_STATS.index(stat)


def section_values(psi, angle, section_psi, rate, angle_scale: float = 1.0,
                   rate_scale: float = 1.0, travel_m_s=None) -> np.ndarray:
    """The section-4.1 objective columns (P, 8) of ``section_table``: picking swing over ab
    and seeding swing over de (deg, largest |change| from the section's start), attitude
    at e (deg, signed), horizontal tip speed at e, travel speed, seeding peak static speed
    over de, return minimum static and dynamic speed over ef (m/s)."""
    t = section_table(psi, angle, section_psi, rate, angle_scale, rate_scale, travel_m_s,
                      full=False)
    c = section_column
    return np.c_[np.abs(t[:, c("picking_ab", "swing")]), np.abs(t[:, c("seeding_de", "swing")]),
                 t[:, c("seeding_de", "end")], t[:, c("vx_e")], t[:, c("travel")],
                 t[:, c("peak_static_de")], t[:, c("least_static_ef")],
                 t[:, c("least_dynamic_ef")]]


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
