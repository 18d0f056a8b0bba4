"""Manufacturability findings of a generated gear set and its one verdict.

A finding is a failed check, one dict ``{gear, check, value, limit, unit, where, why}``:
``gear`` the gear (or pair) it concerns, ``check`` a stable name, ``value`` what was
measured, ``limit`` what it had to meet (``unit`` of both), ``where`` the place as
``{"body_angle_deg": ..., "tooth": ...}`` (body angle of the gear, deg counter-clockwise
from its body's +x axis; teeth numbered as in ``outline.teeth_on_outline``) or, for a
pair, ``{"contact_angle_deg": ...}`` (gear A's contact body angle), and ``why`` one
sentence. The verdict is "ok" when there is no finding, else "not manufacturable".
Every check and its limit is described in docs/manufacturing.md.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.gears.manufacturability import CuttingRules
from plantmech.gears.outline import tooth_number

VERDICT_OK, VERDICT_NOT_OK = "ok", "not manufacturable"
#: the check of a finding that says files asked for were not written (e.g. STEP without
#: the extra): the gears may be fine, the verdict says "files not written"
NOT_WRITTEN, VERDICT_NOT_WRITTEN = "files_not_written", "files not written"


@dataclass(frozen=True)
class CutLimits:
    """Limits the cut gears must meet.

    min_tip_land: smallest top land (x module) of a tooth on the cut outline (0.2 m, the
    usual rule against pointed teeth, ISO 21771 / Litvin & Fuentes);
    max_working_pressure_angle_deg: tool pressure angle + atan(|dr/dtheta| / r) (deg;
    45, the project's limit, docs/conventions.md);
    max_interference: deepest overlap of the turning gears (x module, 0.01 m);
    backlash band: circumferential free play over the cycle between
    ``min_backlash_fraction`` x B and ``max_backlash_factor`` x B + ``max_backlash_extra``
    x module (B the backlash asked for, mm)."""

    min_tip_land: float = 0.2
    # the default of the pitch-curve rules; run_gears passes the design's (cut_limits)
    max_working_pressure_angle_deg: float = CuttingRules.max_working_pressure_angle_deg
    max_interference: float = 0.01
    min_backlash_fraction: float = 0.5
    max_backlash_factor: float = 2.0
    max_backlash_extra: float = 0.02


def finding(gear: str, check: str, value, limit, unit: str, where: dict, why: str) -> dict:
    """One failed check (module docstring)."""
    def num(x):
        return None if x is None else (round(float(x), 6) if np.ndim(x) == 0 else x)

    return {"gear": gear, "check": check, "value": num(value), "limit": num(limit),
            "unit": unit, "where": where, "why": why}


def _place(angle_deg, tooth_angles) -> dict:
    if angle_deg is None:
        return {}
    where = {"body_angle_deg": round(float(angle_deg), 2)}
    k = tooth_number(tooth_angles, angle_deg) if tooth_angles is not None else None
    if k is not None:
        where["tooth"] = k
    return where


def gear_findings(check: dict, teeth: dict | None, limits: CutLimits = CutLimits()) -> list:
    """Findings of one gear: from its pitch-curve checks (``teeth.gear_checks``: undercut,
    pointed equivalent teeth, cutter fit in concave spans, working pressure angle) and from
    its cut outline (``outline.teeth_on_outline``: tip land of every tooth)."""
    name, m = check["name"], check["module_mm"]
    ang = None if teeth is None else teeth["angle_deg"]
    out = []
    if check["undercut"]:
        out.append(finding(
            name, "undercut", check["min_equivalent_teeth"], check["undercut_limit_teeth"],
            "teeth", _place(check["min_equivalent_teeth_at_deg"], ang)
            | {"spans_deg": check["undercut_at_deg"]},
            "the pitch curve there curves like a spur gear of fewer teeth than the rack "
            "limit 2 h_a / sin^2(alpha): the cutter's tip removes the flank's root"))
    if check["pointed"]:
        out.append(finding(
            name, "pointed_equivalent", check["min_equivalent_top_land_mm"],
            limits.min_tip_land * m, "mm", _place(check["min_equivalent_top_land_at_deg"], ang)
            | {"spans_deg": check["pointed_at_deg"]},
            "the equivalent spur gear of the pitch curve there has a top land below "
            f"{limits.min_tip_land:g} m: its teeth come to a point"))
    if not check["cutter_fits"]:
        out.append(finding(
            name, "cutter_fit", check["min_concave_curvature_radius_mm"],
            check["cutter_pitch_radius_mm"], "mm",
            _place(check["min_concave_curvature_at_deg"], ang),
            "a concave span's radius of curvature is below the shaper cutter's pitch radius: "
            "the cutter gouges the neighbouring teeth"))
    if check["max_pressure_angle_deg"] > limits.max_working_pressure_angle_deg:
        out.append(finding(
            name, "working_pressure_angle", check["max_pressure_angle_deg"],
            limits.max_working_pressure_angle_deg, "deg",
            _place(check["max_pressure_angle_at_deg"], ang),
            "the pitch curve is so steep there that the teeth push mostly along the radius "
            "(large radial force, the mesh locks near 90 deg)"))
    if teeth is not None and len(teeth["angle_deg"]) < check["teeth"]:
        # teeth gouged away or merged into a toothless bump: where the widest gap between
        # neighbouring tooth centres is
        a = np.sort(teeth["angle_deg"])
        gaps = np.diff(np.r_[a, a[:1] + 360.0]) if len(a) else np.array([360.0])
        k = int(np.argmax(gaps))
        mid = float(np.mod(a[k] + gaps[k] / 2, 360.0)) if len(a) else 0.0
        out.append(finding(
            name, "tooth_count", len(a), check["teeth"], "teeth",
            {"body_angle_deg": round(mid, 2)} | ({"tooth": k + 1} if len(a) else {}),
            f"the cut outline carries {len(a)} teeth where {check['teeth']} were cut: the "
            f"widest gap ({gaps[k]:.1f} deg, after tooth {k + 1}) has lost its teeth"))
    if teeth is not None and len(teeth["tip_land_mm"]):
        land = teeth["tip_land_mm"]
        bad = np.flatnonzero(land < limits.min_tip_land * m)
        if len(bad):
            k = int(bad[np.argmin(land[bad])])
            out.append(finding(
                name, "pointed_teeth", land[k], limits.min_tip_land * m, "mm",
                {"body_angle_deg": round(float(ang[k]), 2), "tooth": k + 1,
                 "teeth": [int(i) + 1 for i in bad]},
                f"{len(bad)} of the cut teeth have a top land below {limits.min_tip_land:g} m "
                "(measured on the cut outline): pointed or cut short"))
    return out


def mesh_findings(mesh: dict, module: float, backlash: float,
                  limits: CutLimits = CutLimits()) -> list:
    """Findings of one pair's mesh check (``teeth.mesh_check``): interference and the
    circumferential backlash band (``CutLimits``)."""
    name, out = mesh["pair"], []
    if mesh["max_interference_mm"] >= limits.max_interference * module:
        out.append(finding(
            name, "mesh_interference", mesh["max_interference_mm"],
            limits.max_interference * module, "mm",
            {"contact_angle_deg": round(mesh["worst_at_contact_angle_deg"], 2)},
            "the teeth overlap while the pair turns by its rolling law"))
    lo = limits.min_backlash_fraction * backlash
    hi = limits.max_backlash_factor * backlash + limits.max_backlash_extra * module
    if mesh["min_circumferential_backlash_mm"] is None:
        out.append(finding(
            name, "backlash_min", None, lo, "mm", {},
            "the outlines overlap at every position of the cycle: no free play anywhere"))
        return out
    if mesh["min_circumferential_backlash_mm"] < lo:
        out.append(finding(
            name, "backlash_min", mesh["min_circumferential_backlash_mm"], lo, "mm",
            {"contact_angle_deg": round(mesh["min_circumferential_backlash_at_deg"], 2)},
            "the circumferential free play drops below the band asked for: the teeth bind"))
    if mesh["max_circumferential_backlash_mm"] > hi:
        out.append(finding(
            name, "backlash_max", mesh["max_circumferential_backlash_mm"], hi, "mm",
            {"contact_angle_deg": round(mesh["max_circumferential_backlash_at_deg"], 2)},
            "the circumferential free play grows beyond the band asked for: lost motion "
            "(flanks gouged or teeth missing there)"))
    return out


def verdict(findings: list) -> str:
    """"ok" when nothing was found, "files not written" when the only findings are files
    asked for and not written, else "not manufacturable": the ``label`` of a gears
    record's verdict (``workflows.run_gears``; the verdict itself is every command's,
    ``outputs.verdict``)."""
    if not findings:
        return VERDICT_OK
    if all(f["check"] == NOT_WRITTEN for f in findings):
        return VERDICT_NOT_WRITTEN
    return VERDICT_NOT_OK


def headline(record: dict) -> str:
    """The verdict line of a gears record (``run_gears``: its verdict's ``text``), as
    ``plantmech gears`` prints it after "verdict: " and the app's Make panel shows it."""
    findings, v = record["findings"], record["verdict"]
    if v["ok"] and not findings:
        return "ok - every gear can be cut, the pairs mesh, every file is what it claims"
    places = {f["gear"] for f in findings}
    return (f"NOT MET - {v['label']}: {len(findings)} findings on {len(places)} gears "
            "or pairs")


def describe(f: dict) -> str:
    """One line for a finding: gear, check, value against limit, place and why."""
    where = f["where"]
    place = ", ".join(f"{k[:-4].replace('_', ' ')} {v} deg" if k.endswith("_deg") else
                      f"{k} {v}" for k, v in where.items() if k not in ("spans_deg", "teeth"))
    if f["value"] is None and f["limit"] is None:  # nothing measured: what and why
        return f"{f['gear']}: {f['check']}" + (f" at {place}" if place else "") + f": {f['why']}"
    val = "n/a" if f["value"] is None else f"{f['value']:.4g}"
    lim = "n/a" if f["limit"] is None else f"{f['limit']:.4g}"
    return (f"{f['gear']}: {f['check']} {val} {f['unit']} (limit {lim} {f['unit']})"
            + (f" at {place}" if place else "") + f": {f['why']}")
