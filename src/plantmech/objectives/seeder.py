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


def _section_mask(psi, p_start, p_end):
    span = np.mod(p_end - p_start, 2 * np.pi)
    return np.mod(psi - p_start, 2 * np.pi) <= span


def attitude_by_section(psi, arm_deg, point_psi, sections: dict[str, int]) -> dict:
    """Arm (cane) attitude per section, degrees relative to the initial attitude
    (arm collinear with the carrier at the farthest point, seed 000 §3.4)."""
    ref = arm_deg[0]
    rel = arm_deg - ref
    pp = {k: point_psi[v] for k, v in sections.items()}

    table_psi, table_rel = np.append(psi, 2 * np.pi), np.append(rel, rel[0])  # built once

    def at(p):
        return float(np.interp(p, table_psi, table_rel))

    out = {}
    for name, (s, e) in {"picking_ab": ("a", "b"), "transport_bc": ("b", "c"),
                         "transport_cd": ("c", "d"), "seeding_de": ("d", "e"),
                         "return_efca": ("e", "a")}.items():
        m = _section_mask(psi, pp[s], pp[e])
        vals = np.r_[rel[m], at(pp[s]), at(pp[e])]
        start, end = at(pp[s]), at(pp[e])
        out[name] = {
            "start": round(start, 4), "end": round(end, 4),
            "min": round(float(vals.min()), 4), "max": round(float(vals.max()), 4),
            "change": round(end - start, 4),
            "swing_from_start": round(float(vals[np.argmax(np.abs(vals - start))] - start), 4),
        }
    out["sowing_angle"] = round(at(pp["e"]), 4)
    out["sowing_angle_to_horizontal"] = round(at(pp["e"]) + ref, 4)
    out["initial_attitude"] = round(float(ref), 4)
    return out


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


def _periodic_table(psi) -> np.ndarray:
    """The carrier angles psi (rad, ascending in [0, 2 pi)) closed at 2 pi: the abscissae
    of ``_periodic_at``'s interpolation, built once per cycle and shared by its calls."""
    return np.append(psi, 2 * np.pi)


def _periodic_at(table, values, p):
    """Linear interpolation of a sampled periodic quantity ``values`` (one per carrier
    angle) at carrier angle(s) p (rad); ``table``: ``_periodic_table(psi)``. A float for
    a scalar p, an array for an array of angles (one interpolation for all of them)."""
    out = np.interp(np.mod(p, 2 * np.pi), table, np.append(values, values[0]))
    return float(out) if np.ndim(out) == 0 else out


def section_values(psi, values, p_start, p_end, table=None) -> np.ndarray:
    """Samples of ``values`` within the section [p_start, p_end] (clockwise carrier
    angles, rad), including both ends interpolated; ``table``: ``_periodic_table(psi)``
    when the caller has it."""
    m = _section_mask(psi, p_start, p_end)
    ends = _periodic_at(_periodic_table(psi) if table is None else table, values,
                        np.array([p_start, p_end], dtype=float))
    return np.r_[values[m], ends]


def zero_speed_travel(psi, velocity, sowing_angle_deg: float, p_e: float) -> dict:
    """Machine travel speed (m/s) for zero-speed seeding at e (seed 000 Eq. 18).

    Physically consistent reading: the machine cancels the tip's horizontal velocity at
    e, v_c = x_dot_A(e), so Eq. 17's absolute horizontal velocity x_dot - v_c vanishes
    there. The printed form v_c = v_A cos(pi/2 - beta) = v_A sin(beta) with beta the
    sowing (attitude) angle is reported beside it; both agree only when the tip moves
    along the cane (docs/conventions.md)."""
    table = _periodic_table(psi)
    vx = _periodic_at(table, velocity[:, 0], p_e)
    vy = _periodic_at(table, velocity[:, 1], p_e)
    v = float(np.hypot(vx, vy))
    return {"zero_speed_travel_m_s": vx,
            "speed_at_e_m_s": v,
            "velocity_direction_at_e_deg": float(np.degrees(np.arctan2(vy, vx))),
            "eq18_as_printed_m_s": v * float(np.sin(np.radians(sowing_angle_deg)))}


def speed_by_section(psi, velocity, travel_m_s: float, section_psi: dict[str, float]) -> dict:
    """Static and dynamic (Eq. 17) speed extremes (m/s) of the section-4.1 objectives:
    seeding section de (peak) and return section ef (minimum)."""
    static = np.hypot(velocity[:, 0], velocity[:, 1])
    dynamic = np.hypot(velocity[:, 0] - travel_m_s, velocity[:, 1])
    p = section_psi
    table = _periodic_table(psi)  # once for the four sections' eight ends
    de_s = section_values(psi, static, p["d"], p["e"], table)
    ef_s = section_values(psi, static, p["e"], p["f"], table)
    ef_d = section_values(psi, dynamic, p["e"], p["f"], table)
    de_d = section_values(psi, dynamic, p["d"], p["e"], table)
    return {"max_speed_seeding_m_s": float(de_s.max()),
            "min_speed_return_static_m_s": float(ef_s.min()),
            "min_speed_return_dynamic_m_s": float(ef_d.min()),
            "max_speed_seeding_dynamic_m_s": float(de_d.max()),
            "max_speed_static_m_s": float(static.max()),
            "min_speed_static_m_s": float(static.min())}


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
