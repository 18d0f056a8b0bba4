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

    Segment i runs from a_i to a_{i+1}; M(i, j) = d_j x (a_i - a_j) is the side of segment
    j's line on which point a_i lies (d_j = a_{j+1} - a_j), and segments i and j cross
    properly where M(i, j) M(i + 1, j) < 0 and M(j, i) M(j + 1, i) < 0. Only pairs whose
    bounding boxes overlap can cross (a crossing point lies in both), so the pairs are
    found by a sweep over the segments sorted by their smallest x (``np.searchsorted`` on
    all designs' rows at once), then tested exactly: O(n log n + crossing candidates) per
    design instead of every one of the n^2 / 2 pairs (tests/test_objectives_planetary.py
    holds it to the all-pairs count). A population of ``curves.KERNEL_POINTS`` points or
    more, or of several designs once the fused passes are loaded, is counted by
    ``trains.fused.crossings`` (the same sweep per design, compiled)."""
    P, S = path.shape
    idx = np.linspace(0, S, samples, endpoint=False).astype(int)
    z = path[:, idx]
    n = samples
    ax, ay = z.real, z.imag
    import sys

    from plantmech.trains.curves import use_kernels

    # a population (or designs whose train pass loaded numba already: a sub-population of
    # a large grid, 32 x 720 points, costs nothing to import): per design, one sorted
    # sweep (the same counts)
    if use_kernels(P * n) or (P > 1 and "plantmech.trains.fused" in sys.modules):
        from plantmech.trains.fused import crossings

        return crossings(np.ascontiguousarray(ax), np.ascontiguousarray(ay)).astype(int)
    bx, by = np.roll(ax, -1, axis=1), np.roll(ay, -1, axis=1)
    xlo, xhi = np.minimum(ax, bx), np.maximum(ax, bx)
    ylo, yhi = np.minimum(ay, by), np.maximum(ay, by)
    order = np.argsort(xlo, axis=1, kind="stable")
    xs = np.take_along_axis(xlo, order, axis=1)
    xe = np.take_along_axis(xhi, order, axis=1)
    # one sorted key over all rows: row p shifted past row p - 1 (the shift's rounding is
    # covered by the margin; the candidates are then tested exactly)
    lo = float(np.min(xs)) if P else 0.0
    width = float(np.max(xe) - lo) + 1.0 if P else 1.0
    shift = (np.arange(P) * 2.0 * width)[:, None]
    key = (xs - lo + shift).ravel()
    margin = 1e-9 * 2.0 * width * max(P, 1)
    ends = np.searchsorted(key, (xe - lo + shift).ravel() + margin, side="right")
    first = np.arange(P * n) + 1
    counts = np.maximum(ends - first, 0)
    k = np.repeat(np.arange(P * n), counts)  # candidate pairs in sorted order: k < m
    m = np.arange(len(k)) - np.repeat(np.cumsum(counts) - counts, counts) + k + 1
    row = k // n
    i = order.ravel()[k]
    j = order.ravel()[m]
    gap = np.abs(i - j)
    keep = ((gap > 1) & (gap < n - 1) & (ylo[row, i] <= yhi[row, j])
            & (ylo[row, j] <= yhi[row, i]))
    row, i, j = row[keep], i[keep], j[keep]
    dx, dy = bx - ax, by - ay
    i1, j1 = (i + 1) % n, (j + 1) % n

    def side(p, q):  # M(p, q) for the pairs' rows
        return dx[row, q] * (ay[row, p] - ay[row, q]) - dy[row, q] * (ax[row, p] - ax[row, q])

    hit = (side(i, j) * side(i1, j) < 0) & (side(j, i) * side(j1, i) < 0)
    return np.bincount(row[hit], minlength=P).astype(int)


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
    (P, J, S) arrays), in sub-populations of ``chunk_designs(grid)`` designs (their
    tables a few MB each: a 1000-design population of a 16384-point grid would otherwise
    page-fault 131 MB per temporary). A design whose train cannot be built (a pair that
    does not roll or close) gives every row value None, not ok, violation inf, and the
    reason as its note; it is found by halving the population that holds it, so the
    others are still evaluated together. The rows are the same in number and order for
    every design with the same structure (an optimizer's columns)."""
    from plantmech.trains.spec import structure_key

    groups: dict = {}
    for i, d in enumerate(designs):
        groups.setdefault((structure_key(d), samples or d.samples), []).append(i)
    out: list = [None] * len(designs)
    jobs = []
    for (_, n), members in groups.items():
        size = chunk_designs(designs[members[0]].train.grid)
        jobs += [(members[start:start + size], n) for start in range(0, len(members), size)]

    def run(job):
        part, n = job
        return part, _evaluate_group([designs[i] for i in part], n)

    for part, rows in _mapped(run, jobs):
        for i, r in zip(part, rows, strict=True):
            out[i] = r
    return out


def _mapped(fn, jobs: list):
    """``map(fn, jobs)``, on ``PLANTMECH_KERNEL_THREADS`` threads when that asks for more
    than one and there are several sub-populations (the fused kernels release the GIL;
    each job's numbers are its own, so the results do not depend on the threads); one
    thread by default (``mechanisms.seeder_kernel.kernel_threads``: on a shared machine the
    optimizer's worker processes already fill the cores)."""
    import os

    if len(jobs) < 2 or os.environ.get("PLANTMECH_KERNEL_THREADS", "1").strip() in ("", "1"):
        return map(fn, jobs)
    from concurrent.futures import ThreadPoolExecutor

    from plantmech.mechanisms.seeder_kernel import kernel_threads

    threads = min(kernel_threads(), len(jobs))
    if threads < 2:
        return map(fn, jobs)
    with ThreadPoolExecutor(threads) as pool:
        return list(pool.map(fn, jobs))


#: grid points (designs x pitch-curve grid) of one sub-population: each (P, grid) table
#: then stays within a few MB (2**19 doubles = 4 MB), reused from the heap instead of fresh
#: pages and near the cache (measured on Table 4, grid 16384, 2 cores shared, load ~3:
#: 110 designs/s as one population of 64, 200/s in populations of 32)
CHUNK_POINTS = 2**19


def chunk_designs(grid: int) -> int:
    """How many designs of a pitch-curve ``grid`` one sub-population holds (at least 1):
    a large population is evaluated as populations of this size, one after the other
    (every design's numbers are its own: they do not depend on the others)."""
    return max(1, CHUNK_POINTS // max(int(grid), 1))


def structure_population(designs: list, samples: int) -> tuple[list[list[dict]], list]:
    """``population_evaluation`` of designs that share one train structure (variants of
    one file: only numbers differ), with arm 1's motion of each: (rows per design, [(tip,
    tip rate, arm angle) or None]) (``_evaluate_group``)."""
    from plantmech.trains.spec import structure_key

    if len({structure_key(d) for d in designs}) > 1:
        raise ValueError("structure_population: the designs do not share one train structure")
    motions: list = []
    rows: list = []
    size = chunk_designs(designs[0].train.grid) if designs else 1
    for start in range(0, len(designs), size):
        rows += _evaluate_group(designs[start:start + size], samples, motions)
    return rows, motions


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


def _evaluate_group(designs: list, samples: int, motions: list | None = None
                    ) -> list[list[dict]]:
    """``population_evaluation`` of designs sharing one structure: one build, one
    simulation, one manufacturability assessment of the (P, ...) arrays. ``motions``: a
    list that gets, per design in order, arm 1's (tip, tip rate, arm angle) over the
    carrier samples (complex mm, complex mm/rad, rad; None for a train that cannot be
    built)."""
    from plantmech.trains.model import simulate, simulate_tips
    from plantmech.trains.spec import TrainSpecError, build_from_designs

    try:
        built = build_from_designs(designs, grouped=True)  # grouped by structure_key
    except TrainSpecError as exc:
        if len(designs) == 1:
            if motions is not None:
                motions.append(None)
            return [_refused_rows(designs[0], str(exc))]
        half = len(designs) // 2  # find the refused ones; evaluate the rest together
        return (_evaluate_group(designs[:half], samples, motions)
                + _evaluate_group(designs[half:], samples, motions))
    motion = simulate_tips(built, samples) or simulate(built, samples)  # tips: all it reads
    if motions is not None:
        motions.extend((motion.tip[i, 0], motion.tip_rate[i, 0], motion.arm_angle[i, 0])
                       for i in range(len(designs)))
    return judged(designs, built, motion)


def judged(designs: list, built, motion) -> list[list[dict]]:
    """The rows of ``population_evaluation`` for designs already built (``built``) and
    simulated (``motion``) together: their [limits] checks and each pair's pitch-curve
    manufacturability rules (for a caller that keeps the motion, e.g. the app)."""
    from plantmech.gears.manufacturability import violation
    from plantmech.objectives import relative_violation
    from plantmech.trains.gearing import assess

    first = designs[0]
    values = motion_objectives(motion, first.carrier.speed_deg_s)
    verdicts, rules = assess(first, built)
    graded = [violation(v, rules) for v in verdicts]  # (P, 2) each
    lim = rules.max_working_pressure_angle_deg
    # per pair, its (P,) numbers as Python floats once (a row per design reads them)
    pairs = [(v.name, v.module_low.tolist(), v.module_high.tolist(),
              v.working_pressure_angle_deg.tolist(), g[:, 0].tolist(), g[:, 1].tolist())
             for v, g in zip(verdicts, graded, strict=True)]
    out = []
    for i, design in enumerate(designs):
        rows = []
        for c in checks(values, design.limits, i):
            rng = getattr(design.limits, c.name)
            rows.append(dict(c.as_dict(), violation=float(relative_violation(
                values[c.name][i], rng.min, rng.max))))
        for name, low, high, angle, g_module, g_angle in pairs:
            lo, hi, w = low[i], high[i], angle[i]
            rows.append({"name": f"cuttable_module_{name}", "value": round(hi, 6),
                         "unit": "mm", "limit": f">= {lo:g} mm", "ok": bool(hi >= lo),
                         "violation": g_module[i]})
            rows.append({"name": f"working_pressure_angle_{name}", "value": round(w, 6),
                         "unit": "deg", "limit": f"<= {lim:g} deg", "ok": bool(w <= lim),
                         "violation": g_angle[i]})
        out.append(rows)
    return out
