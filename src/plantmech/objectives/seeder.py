"""Checks of the sugarcane seeder: Table 1 planning limits and section 4.1
attitude objectives (seed 000). Angles in degrees at this boundary."""

from __future__ import annotations

import numpy as np

from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.objectives import Check, limit_text, range_check


def planning_checks(traj: ClosedTrajectory, sections: dict[str, int], limits) -> list[Check]:
    """Table 1 of seed 000, computed from the fitted curve (mm, deg): the population
    code's ``planning_values`` for this one curve."""
    from plantmech.objectives.seeder_inverse_population import planning_values

    values, reason = planning_values(traj.batch, sections)
    v = [None if not np.isfinite(x) else float(x) for x in values[0]]
    note = reason[0]
    L = limits
    rows = [
        ("small_ring_height", L.small_ring_height_mm, "mm", "vertical extent of the loop "
         "through a, b"),
        ("small_ring_width", L.small_ring_width_mm, "mm", "horizontal extent of the loop "
         "through a, b"),
        ("large_ring_height", L.large_ring_height_mm, "mm", "vertical extent of the loop "
         "through d, e, f"),
        ("large_ring_width", L.large_ring_width_mm, "mm", "horizontal extent of the loop "
         "through d, e, f"),
        ("cd_central_angle", L.cd_central_angle_deg, "deg",
         "angle at the rotation centre between c and d"),
        ("sowing_height_difference", L.sowing_height_difference_mm, "mm", "|y_d - y_e|"),
        ("centre_to_trench_bottom", L.centre_to_trench_bottom_mm, "mm",
         "rotation centre above the lowest trajectory point"),
    ]
    return [range_check(name, x, lim.min, lim.max, unit, text if x is not None else note)
            for (name, lim, unit, text), x in zip(rows, v, strict=True)]


LETTERS = "abcdef"


def section_mask(psi, p_start, p_end) -> np.ndarray:
    """Carrier angles psi (rad) within the clockwise section [p_start, p_end] (rad): the
    section pass's membership rule, (psi - p_start) mod 2 pi <= (p_end - p_start) mod 2 pi."""
    span = np.mod(p_end - p_start, 2 * np.pi)
    return np.mod(psi - p_start, 2 * np.pi) <= span


def _one(psi, arm_deg=None, velocity=None, section_psi=None, travel_m_s=None) -> np.ndarray:
    """Row 0 of ``seeder_population.section_table`` for one design (P = 1): arm angles
    (S,) deg (none: zeros), tip velocities (S, 2) m/s (none: zeros), section angles (6,)
    rad of a..f."""
    from plantmech.objectives.seeder_population import section_table

    S = len(psi)
    arm = np.zeros(S) if arm_deg is None else np.asarray(arm_deg, dtype=float)
    vel = np.zeros((S, 2)) if velocity is None else np.asarray(velocity, dtype=float)
    return section_table(psi, arm[None], np.asarray(section_psi, dtype=float),
                         vel[None], travel_m_s=travel_m_s)[0]


def _attitude_table(row, arm0: float) -> dict:
    """The attitude dict of one section-table row (deg, to 4 decimals)."""
    from plantmech.objectives.seeder_population import ATTITUDE_SECTION_NAMES, section_column

    out = {}
    for name in ATTITUDE_SECTION_NAMES:
        start, end, low, high, swing = (float(row[section_column(name, k)]) for k in (
            "start", "end", "min", "max", "swing"))
        out[name] = {"start": round(start, 4), "end": round(end, 4), "min": round(low, 4),
                     "max": round(high, 4), "change": round(end - start, 4),
                     "swing_from_start": round(swing, 4)}
    at_e = float(row[section_column("seeding_de", "end")])
    out["sowing_angle"] = round(at_e, 4)
    out["sowing_angle_to_horizontal"] = round(at_e + arm0, 4)
    out["initial_attitude"] = round(arm0, 4)
    return out


def attitude_by_section(psi, arm_deg, point_psi, sections: dict[str, int]) -> dict:
    """Arm (cane) attitude per section, degrees relative to the initial attitude
    (arm collinear with the carrier at the farthest point, seed 000 §3.4): per section
    (ab, bc, cd, de, ea) start, end, min, max, change and the signed swing from the start
    (the section table of ``seeder_population.section_table`` for this one design) at the
    carrier angles psi (S,) rad of the arm angles ``arm_deg`` (S,) deg, sections at
    ``point_psi[sections[letter]]`` rad."""
    sec = np.array([point_psi[sections[k]] for k in LETTERS], dtype=float)
    return _attitude_table(_one(psi, arm_deg, None, sec), float(arm_deg[0]))


def locate_section_points(tip, psi, points, sections: dict[str, int],
                          candidates: int = 4) -> tuple[dict, dict]:
    """Carrier angle (rad) at which one design's tip (S, 2) mm passes each section point
    (``points[sections[letter]]``, mm), and the distance (mm) it misses the point by:
    ``seeder_population.locate_sections`` with P = 1 and no reference (the ``candidates``
    closest approaches per point, the combination in cyclic order with the least total
    miss, refined between samples)."""
    from plantmech.objectives.seeder_population import locate_sections

    letters = list(sections)
    pts = np.asarray(points, dtype=float)[[sections[k] for k in letters]]
    angle, miss = locate_sections(np.asarray(tip)[None], psi, pts, candidates=candidates,
                                  return_miss=True)
    return ({k: float(angle[0, i]) for i, k in enumerate(letters)},
            {k: float(miss[0, i]) for i, k in enumerate(letters)})


def attitude_checks(att: dict, limits) -> list[Check]:
    """Section 4.1 objectives 1-3 (degrees)."""
    return [
        range_check("picking_swing", abs(att["picking_ab"]["swing_from_start"]), None,
                    limits.picking_swing_max_deg, "deg",
                    "largest attitude change from a within ab"),
        range_check("seeding_swing", abs(att["seeding_de"]["swing_from_start"]), None,
                    limits.seeding_swing_max_deg, "deg",
                    "largest attitude change from d within de"),
        range_check("sowing_angle", abs(att["sowing_angle"]), None,
                    limits.sowing_angle_max_deg, "deg",
                    "attitude at e relative to the initial attitude (paper's convention)"),
    ]


def _zero_speed(row, sowing_angle_deg: float) -> dict:
    """Eq. 18's travel speeds (m/s) from one section-table row."""
    from plantmech.objectives.seeder_population import section_column

    vx, vy = float(row[section_column("vx_e")]), float(row[section_column("vy_e")])
    v = float(np.hypot(vx, vy))
    return {"zero_speed_travel_m_s": vx,
            "speed_at_e_m_s": v,
            "velocity_direction_at_e_deg": float(np.degrees(np.arctan2(vy, vx))),
            "eq18_as_printed_m_s": v * float(np.sin(np.radians(sowing_angle_deg)))}


def zero_speed_travel(psi, velocity, sowing_angle_deg: float, p_e: float) -> dict:
    """Machine travel speed (m/s) for zero-speed seeding at e (seed 000 Eq. 18), from tip
    velocities (S, 2) m/s at carrier angles psi (S,) rad, e at p_e rad.

    Physically consistent reading: the machine cancels the tip's horizontal velocity at
    e, v_c = x_dot_A(e), so Eq. 17's absolute horizontal velocity x_dot - v_c vanishes
    there. The printed form v_c = v_A cos(pi/2 - beta) = v_A sin(beta) with beta the
    sowing (attitude) angle is reported beside it; both agree only when the tip moves
    along the cane (docs/conventions.md). The e columns of the section table (every
    section point at e: only e is read)."""
    return _zero_speed(_one(psi, None, velocity, np.full(6, float(p_e))), sowing_angle_deg)


def _speeds(row) -> dict:
    """The section-4.1 speed extremes (m/s) of one section-table row."""
    from plantmech.objectives.seeder_population import section_column

    c = section_column
    return {"max_speed_seeding_m_s": float(row[c("peak_static_de")]),
            "min_speed_return_static_m_s": float(row[c("least_static_ef")]),
            "min_speed_return_dynamic_m_s": float(row[c("least_dynamic_ef")]),
            "max_speed_seeding_dynamic_m_s": float(row[c("peak_dynamic_de")]),
            "max_speed_static_m_s": float(row[c("peak_static")]),
            "min_speed_static_m_s": float(row[c("least_static")])}


def section_speeds(psi, velocity, section_psi: dict[str, float],
                   travel_m_s: float | None = None) -> tuple[dict, float]:
    """Static and dynamic (Eq. 17) speed extremes (m/s) of the section-4.1 objectives
    (seeding section de (peak), return section ef (minimum)) and the travel speed v_c (m/s)
    they were taken at, from ONE section-table row: tip velocities (S, 2) m/s at carrier
    angles psi (S,) rad, sections at ``section_psi`` rad (a letter missing: at e), the
    machine travelling at ``travel_m_s`` m/s (None: zero-speed seeding at e, Eq. 18's
    v_c = x_dot_A(e)). Returns (speeds, travel_m_s)."""
    from plantmech.objectives.seeder_population import section_column

    sec = np.array([section_psi.get(k, section_psi["e"]) for k in LETTERS], dtype=float)
    row = _one(psi, None, velocity, sec, None if travel_m_s is None else float(travel_m_s))
    return _speeds(row), float(row[section_column("travel")])


def speed_by_section(psi, velocity, travel_m_s: float, section_psi: dict[str, float]) -> dict:
    """Static and dynamic (Eq. 17) speed extremes (m/s) of the section-4.1 objectives:
    seeding section de (peak) and return section ef (minimum), from tip velocities (S, 2)
    m/s at carrier angles psi (S,) rad, the machine travelling at ``travel_m_s`` m/s,
    sections at ``section_psi`` rad (``section_speeds``' speeds)."""
    return section_speeds(psi, velocity, section_psi, float(travel_m_s))[0]


def section_objectives(psi, arm_deg, velocity, section_psi: dict[str, float],
                       travel_m_s: float | None = None) -> tuple[dict, dict, dict, float]:
    """Attitude per section (deg), zero-speed travel (Eq. 18) and section speeds (m/s) of
    one simulated design from ONE section-table row: arm angles (S,) deg and tip
    velocities (S, 2) m/s at carrier angles psi (S,) rad, sections at ``section_psi`` rad,
    the machine's travel speed (m/s; None: zero-speed seeding at e). Returns (attitude,
    zero_speed, speeds, travel_m_s)."""
    sec = np.array([section_psi[k] for k in LETTERS], dtype=float)
    row = _one(psi, arm_deg, velocity, sec, travel_m_s)
    att = _attitude_table(row, float(arm_deg[0]))
    from plantmech.objectives.seeder_population import section_column

    return (att, _zero_speed(row, att["sowing_angle"]), _speeds(row),
            float(row[section_column("travel")]))


def speeds_at_points(psi, tip, velocity, points, p_start: float, p_end: float,
                     travel_m_s: float) -> dict:
    """Static and dynamic (Eq. 17) speed (m/s) where the tip (S, 2) mm passes each of
    ``points`` (n, 2) mm within the section [p_start, p_end] (rad): the closest sample of
    the section (no interpolation), its carrier angle (deg) and the miss (mm). Returns
    arrays (n,) by name."""
    idx = np.flatnonzero(section_mask(psi, p_start, p_end))
    d = np.hypot(tip[idx][None, :, 0] - points[:, None, 0],
                 tip[idx][None, :, 1] - points[:, None, 1])  # (n, m)
    k = idx[np.argmin(d, axis=1)]
    v = velocity[k]
    return {"carrier_angle_deg": np.degrees(psi[k]), "miss_mm": d.min(axis=1),
            "speed_m_s": np.hypot(v[:, 0], v[:, 1]),
            "dynamic_speed_m_s": np.hypot(v[:, 0] - travel_m_s, v[:, 1])}


def speed_checks(speeds: dict, limits) -> list[Check]:
    """Section 4.1 objectives 4-5 (m/s)."""
    return [
        range_check("seeding_peak_speed", speeds["max_speed_seeding_m_s"], None,
                    limits.seeding_max_m_s, "m/s", "largest static tip speed over de"),
        range_check("return_min_speed_static", speeds["min_speed_return_static_m_s"],
                    limits.return_min_m_s, None, "m/s", "smallest static tip speed over ef"),
        range_check("return_min_speed_dynamic", speeds["min_speed_return_dynamic_m_s"],
                    limits.return_min_m_s, None, "m/s",
                    "smallest tip speed over ef with the machine travelling (Eq. 17)"),
    ]


def mate_curves(train, dense: int = 4096) -> dict:
    """Sampled pitch curves (body angle rad, radius mm) of the sun and planet that
    roll on gears 2 and 3: theta_mate = integral of r / (a - r) (the forward model's
    rolling at ``dense`` carrier angles, ``seeder_forward.simulate``, exact across a
    lock-point break; the samples of the dwell left out), r_mate = a - r, from gear 2's
    turn 0 to its full turn (the sun's end at 360 deg less the toothless sector)."""
    from plantmech.mechanisms.seeder_batch import meshing_angle
    from plantmech.mechanisms.seeder_forward import simulate

    res = simulate(train, samples=dense)
    theta1 = train.dwell_theta1 if train.dwell_start is not None else 0.0
    rolled, _ = meshing_angle(res.carrier_angle, train.dwell_start, theta1)
    keep = ~res.in_dwell
    turn = np.r_[res.gear2_angle[keep], 2 * np.pi]
    out = {}
    for name, curve, c0, a, ang in (
            ("sun", train.gear2, train.gear2_contact0, train.a1,
             np.r_[rolled[keep], 2 * np.pi - theta1]),
            ("planet", train.gear3, train.gear3_contact0, train.a2,
             np.r_[res.planet_rel[keep], 2 * np.pi])):
        out[name] = (ang, a - curve(c0 + turn))
    return out


def gear_checks(train, rules, samples: int = 3600) -> tuple[dict, list]:
    """Can the train's four pitch curves be cut (``gears.manufacturability`` with ``rules``)?
    For each pair (sun-gear 2, gear 3-planet): the largest module its curves allow
    (``cuttable_module_<pair>``, at least the smallest module) and the working pressure angle.
    The sun and planet are the mates of gears 2 and 3 (rho = a - r, phi' = r / (a - r)), as
    in the population path (``seeder_population.pitch_curve_metrics``). Also reports the
    convexity of gears 2 and 3. Returns (metrics, checks)."""
    from plantmech.gears.manufacturability import (
        PairShape,
        assess_pair,
        binding,
        pair_record,
        shape_pair,
    )
    from plantmech.geometry.periodic import convexity

    metrics = {"convexity": {"gear2": convexity(train.gear2), "gear3": convexity(train.gear3)},
               "manufacturing": {"rules": rules.record()}}
    checks = []
    for pair, curve, a, names in (("sun_gear2", train.gear2, train.a1, ("gear2", "sun")),
                                  ("gear3_planet", train.gear3, train.a2, ("gear3", "planet"))):
        t = curve.theta0 + np.linspace(0.0, 2 * np.pi, samples, endpoint=False)
        r, r1, r2 = curve.derivatives(t)
        shapes, mu = shape_pair(t, r[None], r1[None], r2[None], a, names)
        v = assess_pair(PairShape(pair, shapes, mu), rules)
        rec = pair_record(v, rules)
        metrics["manufacturing"][pair] = rec
        reason, gear, ang = binding(v)
        checks.append(Check(f"cuttable_module_{pair}", float(v.module_high[0]),
                            limit_text(rules.min_module_mm, None, "mm"), bool(v.module_ok[0]),
                            "mm", f"largest module the pitch curves can be cut with: {reason}"
                            + (f" at body angle {ang:.1f} deg" if np.isfinite(ang) else "")))
        w = float(v.working_pressure_angle_deg[0])
        checks.append(Check(f"working_pressure_angle_{pair}", w,
                            limit_text(None, rules.max_working_pressure_angle_deg, "deg"),
                            bool(w <= rules.max_working_pressure_angle_deg), "deg",
                            f"tool {rules.pressure_angle_deg:g} deg + max atan(|r'|/r) of the "
                            "pitch curves"))
    return metrics, checks


def ratio_ranges(result) -> dict:
    """Min/max of i = carrier/planet (total) and of each stage's i = driver/follower
    (seed 000 Eq. 9 sense), outside the dwell."""
    m = ~result.in_dwell if result.in_dwell is not None else slice(None)
    out = {}
    for key, rate in (("total_i0", result.total_ratio), ("stage1_i1", result.stage1_rate),
                      ("stage2_i2", result.stage2_rate)):
        inv = 1.0 / rate[m]
        out[key] = {"min": float(inv.min()), "max": float(inv.max())}
    return out


def speed_lower_bound(rho, L1: float, L2: float, carrier_speed_deg_s: float = 360.0):
    """Smallest tip speed (m/s) any gear train can give at distance ``rho`` (mm) from the
    carrier axis: v = |-i L1 e^{i phi} + i (g - 1) L2 e^{i theta}| omega, minimised over the
    ratio g, is L1 omega |sin(theta - phi)|, with theta - phi fixed by rho through
    rho^2 = L1^2 + L2^2 + 2 L1 L2 cos(theta - phi). Zero at the reach circles."""
    rho = np.asarray(rho, dtype=float)
    c = np.clip((rho**2 - L1**2 - L2**2) / (2 * L1 * L2), -1.0, 1.0)
    return L1 * np.radians(carrier_speed_deg_s) * np.sqrt(1.0 - c**2) / 1000.0


def seeding_speed_need(L1: float, carrier_abs, arm_abs, carrier_speed_deg_s: float = 360.0,
                       vertical_min_m_s: float = 1.1):
    """Smallest static tip speed (m/s) that gives a vertical speed |y_dot| of at least
    ``vertical_min_m_s`` at tip states with carrier angle phi and arm angle theta
    (absolute, rad; carrier clockwise at ``carrier_speed_deg_s``). In the three-bar model
    the velocity component along the arm is the carrier's, L1 omega sin(phi - theta),
    whatever the gears; only the component across the arm is free. With zero-speed
    seeding the absolute speed at the seeding point is |y_dot|, so this is the least
    seeding-section speed that lets the return section start above its minimum
    (objectives 4 and 5 at e). Returns (along-arm speed (m/s, signed), needed speed (m/s),
    inf where the arm is vertical and the carrier alone is too slow vertically)."""
    phi, theta = np.asarray(carrier_abs, float), np.asarray(arm_abs, float)
    along = L1 * np.radians(carrier_speed_deg_s) * np.sin(phi - theta) / 1000.0
    vy = along * np.sin(theta)
    c = np.cos(theta)
    sign = np.where(vy >= 0, 1.0, -1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        across = np.where(np.abs(c) > 1e-9, (sign * vertical_min_m_s - vy) / c, np.inf)
    need = np.where(np.abs(vy) >= vertical_min_m_s, np.abs(along), np.hypot(along, across))
    return along, need
