"""Checks of the sugarcane seeder: Table 1 planning limits and section 4.1
attitude objectives (seed 000). Angles in degrees at this boundary."""

from __future__ import annotations

import numpy as np

from plantmech.geometry.trajectory import ClosedTrajectory, segment_self_intersections
from plantmech.objectives import Check, range_check


def _loops(traj: ClosedTrajectory, n: int = 600):
    """Split the "8" at its self-crossing: (crossing point, [(u0, u1), (u1, u0+period)]).

    Crossings are found on an n-gon and refined on the curve by Newton's method on
    traj(u_i) = traj(u_j).
    """
    u = np.linspace(0.0, traj.period, n, endpoint=False)
    hits = segment_self_intersections(traj(u))
    if len(hits) != 1:
        return None, len(hits)
    i, j, _ = hits[0]
    h = u[1] - u[0]
    ui, uj = u[i] + 0.5 * h, u[j] + 0.5 * h
    start = (ui, uj)
    for _ in range(20):
        f = traj(ui) - traj(uj)
        jac = np.c_[traj(ui, 1), -traj(uj, 1)]
        try:
            step = np.linalg.solve(jac, f)
        except np.linalg.LinAlgError:  # tangential crossing: keep the polygon estimate
            ui, uj = start
            break
        ui, uj = ui - step[0], uj - step[1]
        if np.abs(step).max() < 1e-12:
            break
    if not (abs(ui - start[0]) < h and abs(uj - start[1]) < h):
        ui, uj = start  # Newton wandered off this crossing
    ui, uj = np.mod(ui, traj.period), np.mod(uj, traj.period)
    if uj < ui:
        ui, uj = uj, ui
    return (traj(ui), [(ui, uj), (uj, ui + traj.period)]), 1


def _contains(span, u, period):
    u0, u1 = span
    x = u0 + np.mod(u - u0, period)
    return x <= u1


def planning_checks(traj: ClosedTrajectory, sections: dict[str, int], limits) -> list[Check]:
    """Table 1 of seed 000, computed from the fitted curve (mm, deg)."""
    checks: list[Check] = []
    loops, count = _loops(traj)
    ua = traj.point_parameter(sections["a"])
    ue = traj.point_parameter(sections["e"])
    small = large = None
    note = ""
    if loops is None:
        note = (f"the trajectory crosses itself {count} times; an '8' crosses once, "
                "so its two ring buckles are undefined")
    else:
        _, spans = loops
        in_a = [_contains(s, ua, traj.period) for s in spans]
        in_e = [_contains(s, ue, traj.period) for s in spans]
        if in_a[0] != in_a[1] and in_e[0] != in_e[1] and in_a != in_e:
            small = spans[int(np.argmax(in_a))]
            large = spans[int(np.argmax(in_e))]
        else:
            note = "points a and e lie in the same loop of the '8'"

    def extent(span):
        if span is None:
            return None, None
        uu = np.linspace(span[0], span[1], 4000)
        xy = traj(uu)
        return float(np.ptp(xy[:, 1])), float(np.ptp(xy[:, 0]))

    sh, sw = extent(small)
    lh, lw = extent(large)
    L = limits
    checks.append(range_check("small_ring_height", sh, L.small_ring_height_mm.min,
                              L.small_ring_height_mm.max, "mm", note if sh is None else
                              "vertical extent of the loop through a, b"))
    checks.append(range_check("small_ring_width", sw, L.small_ring_width_mm.min,
                              L.small_ring_width_mm.max, "mm", note if sw is None else
                              "horizontal extent of the loop through a, b"))
    checks.append(range_check("large_ring_height", lh, L.large_ring_height_mm.min,
                              L.large_ring_height_mm.max, "mm", note if lh is None else
                              "vertical extent of the loop through d, e, f"))
    checks.append(range_check("large_ring_width", lw, L.large_ring_width_mm.min,
                              L.large_ring_width_mm.max, "mm", note if lw is None else
                              "horizontal extent of the loop through d, e, f"))
    pc, pd = traj.points[sections["c"]], traj.points[sections["d"]]
    central = abs(np.degrees(np.angle(np.exp(1j * (np.arctan2(pd[1], pd[0])
                                                    - np.arctan2(pc[1], pc[0]))))))
    checks.append(range_check("cd_central_angle", central, L.cd_central_angle_deg.min,
                              L.cd_central_angle_deg.max, "deg",
                              "angle at the rotation centre between c and d"))
    pe = traj.points[sections["e"]]
    checks.append(range_check("sowing_height_difference", abs(pd[1] - pe[1]),
                              L.sowing_height_difference_mm.min,
                              L.sowing_height_difference_mm.max, "mm", "|y_d - y_e|"))
    uu = np.linspace(0.0, traj.period, 20000, endpoint=False)
    bottom = float(-traj(uu)[:, 1].min())
    checks.append(range_check("centre_to_trench_bottom", bottom,
                              L.centre_to_trench_bottom_mm.min,
                              L.centre_to_trench_bottom_mm.max, "mm",
                              "rotation centre above the lowest trajectory point"))
    return checks


def _section_mask(psi, p_start, p_end):
    span = np.mod(p_end - p_start, 2 * np.pi)
    return np.mod(psi - p_start, 2 * np.pi) <= span


def attitude_by_section(psi, arm_deg, point_psi, sections: dict[str, int]) -> dict:
    """Arm (cane) attitude per section, degrees relative to the initial attitude
    (arm collinear with the carrier at the farthest point, seed 000 §3.4)."""
    ref = arm_deg[0]
    rel = arm_deg - ref
    pp = {k: point_psi[v] for k, v in sections.items()}

    def at(p):
        return float(np.interp(p, np.r_[psi, 2 * np.pi], np.r_[rel, rel[0]]))

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
