"""The seeder's inverse design evaluated (seed 000): the inverse design of a design file's
trajectory with Table 1's planning checks, the attitude per section and, optionally, the
manufacturability of its pitch curves (``run_seeder_inverse``), as plain numbers
(``summary``: what summary.json holds), and the layer-1 checks of one candidate
trajectory for the optimizer (``seeder_inverse_checks``). Units: mm, deg, m/s."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.design import SeederDesign
from plantmech.gears.manufacturability import rules_for
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.mechanisms.seeder_inverse import InverseResult
from plantmech.mechanisms.seeder_trains import inverse_design_of, train_from_inverse
from plantmech.objectives.layer1 import (
    LAYER1_NAMES,
    _check_violation,
    _pitch_tangent_angle_deg,
    _span_deg,
    inverse_speed_objectives,
)
from plantmech.objectives.seeder import attitude_by_section, attitude_checks, planning_checks

DEG = 180.0 / np.pi


def summary(res: InverseResult, design, planning, attitude, attitude_checks,
            extra: dict | None = None) -> dict:
    out = {
        "mechanism": "sugarcane_seeder",
        "name": design.name,
        "feasible": res.feasible,
        "diagnostics": [d.as_dict() for d in res.diagnostics],
        "L1_mm": res.L1, "L2_mm": res.L2, "a1_mm": res.a1, "a2_mm": res.a2,
        "closure_error_rad": res.closure_error or {"stage1": None, "stage2": None},
        "trajectory_checks": [c.as_dict() for c in planning],
    }
    if res.carrier_angle is not None:
        out["initial"] = {
            "carrier_angle_deg": float(res.carrier_abs[0] * DEG),
            "arm_angle_deg": float(res.arm_angle[0] * DEG),
            "point_B_mm": [float(res.L1 * np.cos(res.carrier_abs[0])),
                           float(res.L1 * np.sin(res.carrier_abs[0]))],
            "tip_mm": [float(res.tip[0, 0]), float(res.tip[0, 1])],
        }
        out["point_carrier_angle_deg"] = [round(float(v), 4)
                                          for v in res.point_carrier_angle * DEG]
    if attitude is not None:
        out["attitude_deg"] = attitude
        out["objectives"] = [c.as_dict() for c in attitude_checks]
    if res.r1 is not None:
        ratios = {}
        with np.errstate(divide="ignore"):
            inv = [1 / res.total_ratio, 1 / res.stage1_ratio, 1 / res.stage2_ratio]
        for k, v in zip(("total_i0", "stage1_i1", "stage2_i2"), inv, strict=True):
            fin = v[np.isfinite(v)]
            ratios[k] = {"min": float(fin.min()), "max": float(fin.max())}
        out["ratio_range"] = ratios
        out["pitch_radius_mm"] = {
            k: {"min": float(np.nanmin(r)), "max": float(np.nanmax(r))}
            for k, r in (("r1_sun", res.r1), ("r2", res.r2), ("r3", res.r3),
                         ("r4_planet", res.r4))}
        dev = np.hypot(*(res.tip_realized - res.tip).T)
        out["realized_vs_planned_max_deviation_mm"] = float(dev.max())
    if res.dwell is not None:
        d = dict(res.dwell)
        for k in ("theta1", "carrier_start", "carrier_end", "planned_rel_rotation", "theta2"):
            if k in d:
                v = d.pop(k)
                d[k + "_deg"] = None if v is None else float(v * DEG)
        out["dwell"] = d
        if "lock_radius_jump" in d:
            from plantmech.mechanisms.seeder_inverse import dwell_lock_check

            out["dwell_checks"] = [dwell_lock_check(res.dwell)]
    if extra:
        out.update(extra)
    return out


@dataclass
class SeederInverseJob:
    design: SeederDesign
    trajectory: ClosedTrajectory
    result: InverseResult
    summary: dict

    @property
    def sections(self) -> dict[str, int]:
        return self.design.trajectory.sections.model_dump()


class InfeasibleDesign(Exception):
    """The inverse design behind a forward job is infeasible (see its diagnostics)."""

    def __init__(self, job: SeederInverseJob):
        super().__init__("the inverse design is infeasible")
        self.job = job


def run_seeder_inverse(design: SeederDesign, manufacturability: bool = True,
                       speeds: bool = False, estimate: bool = False) -> SeederInverseJob:
    """Inverse design of the trajectory, Table 1, attitude, (``speeds``) the speed objectives
    of the designed train (``inverse_speed_objectives``, after the attitude in the
    summary's objectives) and (``manufacturability``) the manufacturability of the designed
    pitch curves (``objectives.seeder.gear_checks``): with both, the seeder's whole set of
    checks (``seeder_checks``); ``estimate``: the error estimate of a feasible design
    (``objectives.inverse_estimate``: summary "error_estimate" and its checks
    "error_estimate_checks")."""
    traj, res = inverse_design_of(design)
    sections = design.trajectory.sections.model_dump()
    planning = planning_checks(traj, sections, design.planning_limits)
    att = checks = None
    if res.arm_angle is not None:
        arm = res.arm_angle_realized if res.arm_angle_realized is not None else res.arm_angle
        att = attitude_by_section(res.carrier_angle, np.degrees(arm),
                                  res.point_carrier_angle, sections)
        checks = attitude_checks(att, design.attitude)
    summ = summary(res, design, planning, att, checks or [])
    job = SeederInverseJob(design, traj, res, summ)
    if speeds and res.feasible and res.tip_realized is not None:
        summ["objectives"] += [c.as_dict() for c in inverse_speed_objectives(job)["checks"]]
    if res.feasible and manufacturability:  # can the designed pitch curves be cut?
        from plantmech.objectives.seeder import gear_checks

        metrics, g_checks = gear_checks(train_from_inverse(res), rules_for(design))
        summ["manufacturing"] = metrics["manufacturing"]
        summ["manufacturing_checks"] = [c.as_dict() for c in g_checks]
    if res.feasible and estimate:
        from plantmech.mechanisms.seeder_trains import inverse_settings
        from plantmech.objectives.inverse_estimate import estimate_rows, seeder_estimate

        summ["error_estimate"] = seeder_estimate(design.trajectory.points,
                                                 inverse_settings(design), res,
                                                 design.trajectory.error_estimate_limit_mm)
        summ["error_estimate_checks"] = estimate_rows(summ["error_estimate"])
    return job


def seeder_checks(summary: dict) -> list[dict]:
    """The seeder's one set of checks, in one order, from a job's summary: Table 1's
    planning checks (of the trajectory, when the design has one), the attitude and speed
    objectives, the manufacturability of the pitch curves (17 for a feasible design with a
    trajectory), and where the job made them the dwell's lock and the error estimate.
    ``inverse``, ``design`` (its full-resolution check) and the app show these."""
    return (list(summary.get("trajectory_checks", [])) + list(summary.get("objectives", []))
            + list(summary.get("manufacturing_checks", []))
            + list(summary.get("dwell_checks", []))
            + list(summary.get("error_estimate_checks", [])))


def seeder_inverse_checks(design: SeederDesign, samples: int = 720,
                          pitch_margin_mm: float = 0.0) -> dict:
    """Layer-1 evaluation of one candidate trajectory: Table 1 planning checks, the three
    attitude objectives and the three speed objectives of the inverse-designed train (its
    path is the planned one, its timing the inverse's carrier law — which the path fixes:
    docs/optimization.md). Values NaN and large violations when the inverse design is
    infeasible."""

    d = design.model_copy(deep=True)
    d.trajectory.samples = samples
    # a coarse cycle can miss a narrow dip of a pitch radius: optimizers ask for a margin
    d.gear_train.min_pitch_radius_mm += pitch_margin_mm
    names = list(LAYER1_NAMES)
    try:
        job = run_seeder_inverse(d, manufacturability=False)
    except Exception:  # a candidate whose curve cannot even be fitted
        job = None
    if job is None or not job.result.feasible:
        # graded: errors, plus how much of the cycle they cover (an optimizer needs a slope)
        n_err = 10.0
        if job is not None:
            errs = [x for x in job.result.diagnostics if x.severity == "error"]
            n_err = len(errs) + sum(_span_deg(x) for x in errs) / 30.0
        return {"names": names, "units": [""] * len(names), "limits": [""] * len(names),
                "values": [np.nan] * len(names), "ok": [False] * len(names),
                "violation": [10.0] * len(names), "infeasible": float(max(n_err, 1.0)),
                "objectives": [1e3, 1e3, 1e3], "pitch_tangent_angle": [np.nan, np.nan]}
    res = job.result
    checks = [c for c in job.summary["trajectory_checks"]]
    checks += job.summary["objectives"]
    checks += [c.as_dict() for c in inverse_speed_objectives(job)["checks"]]
    by = {c["name"]: c for c in checks}
    values, ok, viol, units, limits = [], [], [], [], []
    for n in names:
        c = by[n]
        v = np.nan if c["value"] is None else float(c["value"])
        values.append(v)
        ok.append(bool(c["ok"]))
        units.append(c["unit"])
        limits.append(c["limit"])
        viol.append(_check_violation(n, v, design))
    objectives = [values[names.index(n)] for n in ("picking_swing", "seeding_swing",
                                                   "sowing_angle")]
    return {"names": names, "units": units, "limits": limits, "values": values, "ok": ok,
            "violation": viol, "infeasible": 0.0, "objectives": objectives,
            "pitch_tangent_angle": _pitch_tangent_angle_deg(res)}
