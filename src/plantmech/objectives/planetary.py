"""Objectives of a generic planetary train's motion, for P designs at once.

What any train with an arm can be asked (docs/architecture.md, "Train model"): the tip
path's extent (width and height, mm), its loops (self-crossings of the closed path,
count), the arm's attitude range (max - min of its absolute angle over a turn, deg) and
the tip speed (largest and smallest, m/s), each as a (P,) array of arm 1; ``checks``
holds them to the limits of a design file.
"""

from __future__ import annotations

import numpy as np

from plantmech.objectives import Check, range_check
from plantmech.trains.model import TrainMotion

#: points of the closed tip path on which self-crossings are counted.
LOOP_SAMPLES = 720


def self_crossings(path: np.ndarray, samples: int = LOOP_SAMPLES) -> np.ndarray:
    """Proper crossings of each closed polyline ``path`` (P, S) complex (mm), resampled to
    ``samples`` points: pairs of non-adjacent segments whose ends lie strictly on both
    sides of each other (orientation signs), counted once. (P,) integers."""
    P, S = path.shape
    idx = np.linspace(0, S, samples, endpoint=False).astype(int)
    z = path[:, idx]
    a, b = z, np.roll(z, -1, axis=1)  # segment i: a_i -> b_i
    n = samples
    i, j = np.triu_indices(n, k=2)
    keep = ~((i == 0) & (j == n - 1))  # the closing segment touches the first
    i, j = i[keep], j[keep]
    count = np.zeros(P, dtype=int)
    step = max(1000, 2_000_000 // P)  # bounded temporaries: ~2e6 segment pairs at a time
    for lo in range(0, len(i), step):
        ii, jj = i[lo:lo + step], j[lo:lo + step]
        p1, p2, p3, p4 = a[:, ii], b[:, ii], a[:, jj], b[:, jj]

        def cross(u, v, w):
            return ((v - u).conjugate() * (w - u)).imag

        d1, d2 = cross(p3, p4, p1), cross(p3, p4, p2)
        d3, d4 = cross(p1, p2, p3), cross(p1, p2, p4)
        hit = (d1 * d2 < 0) & (d3 * d4 < 0)
        count += hit.sum(axis=1)
    return count


def motion_objectives(motion: TrainMotion, carrier_speed_deg_s: float) -> dict:
    """(P,) arrays of arm 1's objectives: path_width_mm, path_height_mm, loops,
    attitude_range_deg, max_tip_speed_m_s, min_tip_speed_m_s; and the largest distance
    (mm) between the arms' paths after the carrier phase shift (0 for identical arms,
    NaN when the samples per turn are not a multiple of the arms)."""
    tip = motion.tip[:, 0, :]
    speed = np.abs(motion.velocity(carrier_speed_deg_s)[:, 0, :])
    J = motion.tip.shape[1]
    S = motion.tip.shape[2]
    spread = np.zeros(tip.shape[0])
    if S % J:  # the shifted samples are not sampled: not computable
        spread[:] = np.nan
    for j in range(1, J if S % J == 0 else 1):  # arm j at psi is arm 1 at psi + 2 pi j / J
        shift = S * j // J
        spread = np.maximum(spread, np.abs(np.roll(motion.tip[:, j, :], shift, axis=1)
                                           - tip).max(axis=1))
    return {
        "path_width_mm": np.ptp(tip.real, axis=1),
        "path_height_mm": np.ptp(tip.imag, axis=1),
        "loops": self_crossings(tip).astype(float),
        "attitude_range_deg": np.degrees(np.ptp(motion.arm_angle[:, 0, :], axis=1)),
        "max_tip_speed_m_s": speed.max(axis=1),
        "min_tip_speed_m_s": speed.min(axis=1),
        "arm_phase_deviation_mm": spread,
    }


UNITS = {"path_width_mm": "mm", "path_height_mm": "mm", "loops": "",
         "attitude_range_deg": "deg", "max_tip_speed_m_s": "m/s",
         "min_tip_speed_m_s": "m/s"}


def checks(values: dict, limits, design: int = 0) -> list[Check]:
    """The objectives of design ``design`` that ``limits`` (a ``PlanetaryLimits``) bounds,
    as checks (open intervals)."""
    out = []
    for name, unit in UNITS.items():
        rng = getattr(limits, name)
        if rng is None:
            continue
        out.append(range_check(name, float(values[name][design]), rng.min, rng.max, unit))
    return out


def design_evaluation(design, samples: int | None = None) -> list[dict]:
    """Every check of one planetary design file as rows {name, value, unit, limit, ok,
    violation, note}: its [limits] checks (``checks``; violation: the relative one of
    ``objectives.relative_violation``) and, per pair, the pitch-curve manufacturability
    rules of ``gears.manufacturability`` (``trains.gearing.assess``): the module window
    (``cuttable_module_<pair>``: the largest module the curves allow, mm, against the
    smallest the pair needs) and the working pressure angle (``working_pressure_angle_
    <pair>``, deg), with the relative violations of ``manufacturability.violation``.
    ``samples``: carrier samples (default the file's). A train that cannot be built (a pair
    that does not roll or close) gives every row value None, not ok, violation inf, and the
    reason as its note; the rows are the same in number and order for every design with
    the same structure (an optimizer's columns)."""
    from plantmech.gears.manufacturability import violation
    from plantmech.objectives import relative_violation
    from plantmech.trains.gearing import assess, gear_names
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import TrainSpecError, build_from_design

    names = gear_names(design)
    limited = [n for n in UNITS if getattr(design.limits, n) is not None]
    try:
        built = build_from_design(design)
    except TrainSpecError as exc:
        note = f"the train cannot be built: {exc}"
        rows = [{"name": n, "value": None, "unit": UNITS[n], "limit": "", "ok": False,
                 "violation": np.inf, "note": note} for n in limited]
        for a, b in names:
            rows += [{"name": f"{c}_{a}_{b}", "value": None, "unit": u, "limit": "",
                      "ok": False, "violation": np.inf, "note": note}
                     for c, u in (("cuttable_module", "mm"), ("working_pressure_angle", "deg"))]
        return rows
    motion = simulate(built, samples or design.samples)
    values = motion_objectives(motion, design.carrier.speed_deg_s)
    rows = []
    for c in checks(values, design.limits):
        rng = getattr(design.limits, c.name)
        rows.append(dict(c.as_dict(), violation=float(relative_violation(
            values[c.name][0], rng.min, rng.max))))
    verdicts, rules = assess(design, built)
    for v in verdicts:
        g = violation(v, rules)[0]
        lo, hi = float(v.module_low[0]), float(v.module_high[0])
        w = float(v.working_pressure_angle_deg[0])
        rows.append({"name": f"cuttable_module_{v.name}", "value": round(hi, 6), "unit": "mm",
                     "limit": f">= {lo:g} mm", "ok": bool(hi >= lo), "violation": float(g[0])})
        lim = rules.max_working_pressure_angle_deg
        rows.append({"name": f"working_pressure_angle_{v.name}", "value": round(w, 6),
                     "unit": "deg", "limit": f"<= {lim:g} deg", "ok": bool(w <= lim),
                     "violation": float(g[1])})
    return rows
