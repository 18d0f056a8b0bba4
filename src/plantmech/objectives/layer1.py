"""The seeder's layer-1 evaluation (seed 000, docs/optimization.md): Table 1, attitude and
speed checks of inverse designs of candidate trajectories, one (``inverse_speed_objectives``,
the pieces of ``workflows.seeder_inverse_checks``) or P at once
(``seeder_inverse_checks_population``), their bounds and relative violations, and where the
seeding point can be (``seeding_point_placement``). Units: mm, deg, m/s."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from plantmech.mechanisms.seeder_trains import inverse_design_of, inverse_settings

if TYPE_CHECKING:
    from plantmech.design import SeederDesign


def _pitch_tangent_angle_deg(res) -> list[float]:
    """Largest pitch tangent angle mu (deg) of the sun-gear 2 and gear 3-planet pairs of a
    single inverse design, as ``seeder_inverse.pitch_tangent_angle`` (samples in a
    toothless dwell, where the radii are NaN, are left out)."""
    from plantmech.mechanisms.seeder_inverse import pitch_tangent_angle

    radii = np.stack([res.r1, res.r2, res.r3, res.r4])[None]
    with np.errstate(invalid="ignore"):
        mu = pitch_tangent_angle(radii, np.array([res.a1]), 2 * np.pi / len(res.r1),
                                 nan_ok=bool(np.isnan(radii).any()))
    return [round(float(np.degrees(v)), 6) for v in mu[0]]


def inverse_speed_objectives(job) -> dict:
    """Section 4.1 objectives 4-5 of a feasible inverse design (seed 000): the tip velocity
    of the realized train (the periodic spline's slopes over the uniform carrier angle
    psi, m/s at the design's carrier speed, deg/s clockwise), the static and dynamic
    (Eq. 17) speed v_A (m/s) per sample, the travel speed v_c (m/s; Eq. 18's zero-speed
    seeding at e when the design gives none) and the three speed checks, all from one
    section table (``objectives.seeder.section_speeds``). The same
    evaluation as ``seeder_inverse_checks`` (the optimizer's layer 1), kept apart so the
    app can show the speed objectives live while a type-value point is dragged.
    ``job``: a ``workflows.SeederInverseJob`` (its design, result, sections and summary's
    attitude)."""
    from plantmech.geometry.periodic import periodic_spline_node_slopes
    from plantmech.objectives.seeder import section_speeds, speed_checks

    res, d = job.result, job.design
    if not res.feasible or res.tip_realized is None:
        raise ValueError("speed objectives need a feasible inverse design")
    psi = res.carrier_angle
    vel = periodic_spline_node_slopes(res.tip_realized, 2 * np.pi / len(psi)) * np.radians(
        d.operation.carrier_speed_deg_s) / 1000.0
    sec = {k: float(res.point_carrier_angle[i]) for k, i in job.sections.items()}
    # one section table: the speeds and, with no travel speed given, Eq. 18's from its e
    speeds, travel = section_speeds(psi, vel, sec, d.operation.travel_speed_m_s)
    return {"velocity_m_s": vel, "static_m_s": np.hypot(vel[:, 0], vel[:, 1]),
            "dynamic_m_s": np.hypot(vel[:, 0] - travel, vel[:, 1]), "travel_m_s": travel,
            "speeds": speeds, "checks": speed_checks(speeds, d.speed)}


def _span_deg(diagnostic) -> float:
    """Carrier angle (deg) a diagnostic covers: the backward turn of a carrier that would
    have to turn back, else the clockwise span from its first to its last sample (the
    samples' angles where the reported ones are refined between samples)."""
    angles = diagnostic.sample_angle_deg or diagnostic.carrier_angle_deg
    if not angles:
        return 0.0
    a, b = angles
    if diagnostic.kind == "carrier_not_monotonic":
        return abs(b - a)
    return (b - a) % 360.0


def seeding_point_placement(design: SeederDesign, max_shift: int = 4,
                            tolerance: float = 0.01) -> dict:
    """Where the seeding point e can be (docs/optimization.md, "Where the seeding point can
    be"): for e and the next ``max_shift`` type-value points, the least static speed that
    gives the return section's minimum as vertical speed there (``seeding_speed_need`` on
    the inverse design's motion). If e itself allows objectives 4 and 5 together it stays;
    otherwise e (and f with it) moves on to the nearest point whose need is within
    ``tolerance`` of the smallest. Returns {shift, rows, reason}."""
    from plantmech.objectives.seeder import seeding_speed_need

    _, res = inverse_design_of(design)
    if not res.feasible:
        raise ValueError("the trajectory's inverse design is infeasible: fix it before "
                         "placing the seeding point")
    t = design.trajectory
    n = len(t.points)
    # f moves with e and must stay before a (section order)
    max_shift = max(0, min(max_shift, (t.sections.a - t.sections.f) % n - 1))
    psi = res.carrier_angle
    phi, arm = np.unwrap(res.carrier_abs), np.unwrap(res.arm_angle)
    rows = []
    for k in range(max_shift + 1):
        i = (t.sections.e + k) % n
        x = float(np.mod(res.point_carrier_angle[i], 2 * np.pi))
        ph, th = float(np.interp(x, psi, phi)), float(np.interp(x, psi, arm))
        along, need = seeding_speed_need(res.L1, ph, th, design.operation.carrier_speed_deg_s,
                                         design.speed.return_min_m_s)
        rows.append({"shift": k, "point": f"q{i}",
                     "rho_mm": float(np.hypot(*t.points[i])),
                     "along_arm_m_s": float(along), "arm_deg": float(np.degrees(np.angle(
                         np.exp(1j * th)))), "least_speed_m_s": float(need)})
    limit = design.speed.seeding_max_m_s
    need = np.array([r["least_speed_m_s"] for r in rows])
    if need[0] <= limit:
        return {"shift": 0, "rows": rows, "reason": (
            f"e stays at q{t.sections.e}: a {design.speed.return_min_m_s:g} m/s vertical "
            f"speed there needs {need[0]:.3f} m/s, within the {limit:g} m/s seeding limit")}
    ok = np.flatnonzero((need <= need.min() * (1 + tolerance)) & (need <= limit))
    if not len(ok):
        return {"shift": 0, "rows": rows, "reason": (
            f"e stays at q{t.sections.e}: no point within {max_shift} of it lets a "
            f"{design.speed.return_min_m_s:g} m/s vertical speed stay under {limit:g} m/s")}
    k = int(ok[0])
    return {"shift": k, "rows": rows, "reason": (
        f"seeding point e moved from q{t.sections.e} to {rows[k]['point']} (f with it): at "
        f"q{t.sections.e} a {design.speed.return_min_m_s:g} m/s vertical speed needs "
        f"{need[0]:.3f} m/s, above the {limit:g} m/s seeding limit (objectives 4 and 5 "
        f"exclude each other there); {rows[k]['point']} needs {need[k]:.3f} m/s")}


LAYER1_NAMES = ("small_ring_height", "small_ring_width", "large_ring_height",
                "large_ring_width", "cd_central_angle", "sowing_height_difference",
                "centre_to_trench_bottom", "picking_swing", "seeding_swing", "sowing_angle",
                "seeding_peak_speed", "return_min_speed_static", "return_min_speed_dynamic")


def layer1_bounds(design: SeederDesign) -> list[tuple[str, float | None, float | None, str]]:
    """(name, lower, upper, unit) of every layer-1 check (``LAYER1_NAMES`` order): Table 1,
    section 4.1's attitude and speed objectives (open intervals; None: unbounded)."""
    L, A, S = design.planning_limits, design.attitude, design.speed
    out = []
    for name in LAYER1_NAMES[:7]:
        lim = getattr(L, f"{name}_deg" if name == "cd_central_angle" else f"{name}_mm")
        out.append((name, lim.min, lim.max, "deg" if name == "cd_central_angle" else "mm"))
    out += [("picking_swing", None, A.picking_swing_max_deg, "deg"),
            ("seeding_swing", None, A.seeding_swing_max_deg, "deg"),
            ("sowing_angle", None, A.sowing_angle_max_deg, "deg"),
            ("seeding_peak_speed", None, S.seeding_max_m_s, "m/s"),
            ("return_min_speed_static", S.return_min_m_s, None, "m/s"),
            ("return_min_speed_dynamic", S.return_min_m_s, None, "m/s")]
    return out


def _check_violation(name: str, value: float, design: SeederDesign) -> float:
    """Relative violation of one layer-1 check (0 when met)."""
    from plantmech.objectives import relative_violation

    if not np.isfinite(value):
        return 10.0
    _, lo, hi, _ = next(b for b in layer1_bounds(design) if b[0] == name)
    return float(relative_violation(value, lo, hi))


def seeder_inverse_checks_population(design: SeederDesign, points, samples: int = 360,
                                     pitch_margin_mm: float = 0.0) -> dict:
    """``seeder_inverse_checks`` for P candidate trajectories at once: the design with its
    type-value points replaced by each row of ``points`` (P, N, 2) mm. Inverse design
    (``inverse_population``, with the design's toothless dwell if it has one), Table 1,
    attitude and speeds as arrays over designs. Returns names, units, limits
    (lists) and values, ok, violation (P, 13), infeasible (P,) (the inverse design's
    error grading, 0 when feasible), objectives (P, 3)."""
    from plantmech.geometry.trajectory_batch import TrajectoryBatch
    from plantmech.mechanisms.seeder_inverse import _node_slopes, inverse_population
    from plantmech.objectives import limit_text, relative_violation
    from plantmech.objectives.seeder_inverse_population import (
        attitude_values,
        planning_values,
        speed_values,
    )

    gt = design.gear_train
    sections = design.trajectory.sections.model_dump()
    curves = TrajectoryBatch(points)
    # a toothless dwell as the one-design path places it (``inverse_settings``: the same
    # type-value points for every row, on each row's own carrier law)
    inv = inverse_population(curves, samples, gt.a1_mm, gt.a2_mm, gt.split_exponent,
                             gt.min_pitch_radius_mm + pitch_margin_mm,
                             dwell=inverse_settings(design).dwell)
    plan, _ = planning_values(curves, sections)
    psi = inv.psi
    att = attitude_values(psi, np.degrees(inv.arm_angle_realized), inv.point_carrier_angle,
                          sections)
    vel = _node_slopes(inv.tip_realized, 2 * np.pi / len(psi)) * np.radians(
        design.operation.carrier_speed_deg_s) / 1000.0
    speeds, _ = speed_values(psi, vel, inv.point_carrier_angle, sections,
                             design.operation.travel_speed_m_s)
    raw = np.c_[plan, att, speeds]
    bounds = layer1_bounds(design)
    lo = np.array([np.nan if b[1] is None else b[1] for b in bounds])
    hi = np.array([np.nan if b[2] is None else b[2] for b in bounds])
    with np.errstate(invalid="ignore"):
        ok = (np.isnan(lo) | (raw > lo)) & (np.isnan(hi) | (raw < hi)) & np.isfinite(raw)
    values = np.round(raw, 6)  # as the single-design checks report them
    viol = np.stack([relative_violation(values[:, k], b[1], b[2], nan=10.0)
                     for k, b in enumerate(bounds)], axis=1)
    bad = ~inv.feasible
    values[bad], ok[bad], viol[bad] = np.nan, False, 10.0
    objectives = np.where(bad[:, None], 1e3, values[:, 7:10])
    mu = np.where(bad[:, None], np.nan, np.round(np.degrees(inv.pitch_tangent_angle), 6))
    return {"names": list(LAYER1_NAMES), "units": [b[3] for b in bounds],
            "limits": [limit_text(b[1], b[2], b[3]) for b in bounds], "values": values,
            "ok": ok, "violation": viol, "infeasible": inv.error_score,
            "objectives": objectives, "pitch_tangent_angle": mu}
