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
    sides of each other (orientation signs), counted once. (P,) integers.

    With segment i from a_i to a_{i+1} = b_i, one (n, n) table per design holds every
    orientation: M[i, j] = d_j x (a_i - a_j), the side of segment j's line on which point
    a_i lies (d_j = b_j - a_j). The ends of segment i straddle line j where
    S[i, j] = M[i, j] M[i + 1, j] < 0, so segments i and j cross properly where S[i, j]
    and S[j, i] both hold."""
    P, S = path.shape
    idx = np.linspace(0, S, samples, endpoint=False).astype(int)
    z = path[:, idx]
    n = samples
    ax, ay = z.real, z.imag
    d = np.roll(z, -1, axis=1) - z
    dx, dy = d.real, d.imag
    upper = np.triu(np.ones((n, n), dtype=bool), k=2)
    upper[0, n - 1] = False  # the closing segment touches the first
    count = np.zeros(P, dtype=int)
    step = max(1, 4_000_000 // (n * n))  # bounded temporaries: ~4e6 entries at a time
    for lo in range(0, P, step):
        sl = slice(lo, lo + step)
        M = (dx[sl, None, :] * (ay[sl, :, None] - ay[sl, None, :])
             - dy[sl, None, :] * (ax[sl, :, None] - ax[sl, None, :]))
        straddle = M * np.roll(M, -1, axis=1) < 0
        hit = straddle & straddle.transpose(0, 2, 1) & upper
        count[sl] = hit.sum(axis=(1, 2))
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
    violation, note}: ``population_evaluation`` of the one design (P = 1)."""
    return population_evaluation([design], samples)[0]


def population_evaluation(designs: list, samples: int | None = None) -> list[list[dict]]:
    """Every check of P planetary design files, one list of rows {name, value, unit, limit,
    ok, violation, note} per design: its [limits] checks (``checks``; violation: the
    relative one of ``objectives.relative_violation``) and, per pair, the pitch-curve
    manufacturability rules of ``gears.manufacturability`` (``trains.gearing.assess``): the
    module window (``cuttable_module_<pair>``: the largest module the curves allow, mm,
    against the smallest the pair needs) and the working pressure angle
    (``working_pressure_angle_<pair>``, deg), with the relative violations of
    ``manufacturability.violation``. ``samples``: carrier samples (default each file's).

    The designs sharing a train structure (``trains.spec.structure_key``: everything but
    the numbers) are built, simulated and judged as ONE population (``trains.model``,
    (P, J, S) arrays). A design whose train cannot be built (a pair that does not roll or
    close) gives every row value None, not ok, violation inf, and the reason as its note;
    it is found by halving the population that holds it, so the others are still
    evaluated together. The rows are the same in number and order for every design with
    the same structure (an optimizer's columns)."""
    from plantmech.trains.spec import structure_key

    groups: dict = {}
    for i, d in enumerate(designs):
        groups.setdefault((structure_key(d), samples or d.samples), []).append(i)
    out: list = [None] * len(designs)
    for (_, n), members in groups.items():
        for i, rows in zip(members, _evaluate_group([designs[i] for i in members], n),
                           strict=True):
            out[i] = rows
    return out


def _refused_rows(design, reason: str) -> list[dict]:
    """The rows of a design whose train cannot be built: every value None, violation inf."""
    from plantmech.trains.gearing import gear_names

    note = f"the train cannot be built: {reason}"
    rows = [{"name": n, "value": None, "unit": UNITS[n], "limit": "", "ok": False,
             "violation": np.inf, "note": note}
            for n in UNITS if getattr(design.limits, n) is not None]
    for a, b in gear_names(design):
        rows += [{"name": f"{c}_{a}_{b}", "value": None, "unit": u, "limit": "",
                  "ok": False, "violation": np.inf, "note": note}
                 for c, u in (("cuttable_module", "mm"), ("working_pressure_angle", "deg"))]
    return rows


def _evaluate_group(designs: list, samples: int) -> list[list[dict]]:
    """``population_evaluation`` of designs sharing one structure: one build, one
    simulation, one manufacturability assessment of the (P, ...) arrays."""
    from plantmech.gears.manufacturability import violation
    from plantmech.objectives import relative_violation
    from plantmech.trains.gearing import assess
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import TrainSpecError, build_from_designs

    try:
        built = build_from_designs(designs)
    except TrainSpecError as exc:
        if len(designs) == 1:
            return [_refused_rows(designs[0], str(exc))]
        half = len(designs) // 2  # find the refused ones; evaluate the rest together
        return _evaluate_group(designs[:half], samples) + _evaluate_group(designs[half:],
                                                                          samples)
    first = designs[0]
    motion = simulate(built, samples)
    values = motion_objectives(motion, first.carrier.speed_deg_s)
    verdicts, rules = assess(first, built)
    graded = [violation(v, rules) for v in verdicts]  # (P, 2) each
    lim = rules.max_working_pressure_angle_deg
    out = []
    for i, design in enumerate(designs):
        rows = []
        for c in checks(values, design.limits, i):
            rng = getattr(design.limits, c.name)
            rows.append(dict(c.as_dict(), violation=float(relative_violation(
                values[c.name][i], rng.min, rng.max))))
        for v, g in zip(verdicts, graded, strict=True):
            lo, hi = float(v.module_low[i]), float(v.module_high[i])
            w = float(v.working_pressure_angle_deg[i])
            rows.append({"name": f"cuttable_module_{v.name}", "value": round(hi, 6),
                         "unit": "mm", "limit": f">= {lo:g} mm", "ok": bool(hi >= lo),
                         "violation": float(g[i, 0])})
            rows.append({"name": f"working_pressure_angle_{v.name}", "value": round(w, 6),
                         "unit": "deg", "limit": f"<= {lim:g} deg", "ok": bool(w <= lim),
                         "violation": float(g[i, 1])})
        out.append(rows)
    return out
