"""Summary and tables of a seeder forward simulation (units in every key)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from plantmech.mechanisms.seeder_forward import shaft_offset
from plantmech.outputs.files import write_csv, write_json
from plantmech.outputs.seeder_report import RATIO_GAPS, speed_ratio

DEG = 180.0 / np.pi


def forward_summary(job) -> dict:
    d, res, tr, m = job.design, job.result, job.train, job.metrics
    sp = m["speeds"]
    out = {
        "mechanism": "sugarcane_seeder",
        "name": d.name,
        "source": "train" if d.train is not None else "inverse design of the trajectory",
        "objectives": [c.as_dict() for c in job.checks],
        "all_objectives_met": all(c.ok for c in job.checks),
        "max_speed_seeding_m_s": sp["max_speed_seeding_m_s"],
        "min_speed_return_static_m_s": sp["min_speed_return_static_m_s"],
        "min_speed_return_dynamic_m_s": sp["min_speed_return_dynamic_m_s"],
        "zero_speed_travel_m_s": m["zero_speed"]["zero_speed_travel_m_s"],
        "travel_speed_used_m_s": job.travel_m_s,
        "zero_speed_seeding": m["zero_speed"],
        "speeds_m_s": sp,
        "carrier_speed_deg_s": d.operation.carrier_speed_deg_s,
        "closure_error_rad": res.closure_error,
        "closure_restoration": [f.as_dict() for f in job.closure_fixes],
        "convexity": m["convexity"],
        "manufacturing": m["manufacturing"],
        "ratio_range": m["ratio_range"],
        "attitude_deg": m["attitude_deg"],
        "train": {
            "L1_mm": tr.L1, "L2_mm": tr.L2, "a1_mm": tr.a1, "a2_mm": tr.a2,
            "shaft_offset_deg": shaft_offset(tr) * DEG,
            "initial_carrier_angle_deg": tr.carrier0 * DEG,
            "initial_arm_angle_deg": tr.arm0 * DEG,
            "dwell": None if tr.dwell_start is None else {
                "start_deg": tr.dwell_start * DEG, "sector_deg": tr.dwell_theta1 * DEG},
        },
        "section_carrier_angle_deg": {k: v * DEG for k, v in job.section_psi.items()},
        "samples": int(len(res.carrier_angle)),
    }
    if job.section_distance_mm is not None:
        out["section_point_miss_mm"] = job.section_distance_mm
    if "deviation_from_trajectory_mm" in m:
        out["deviation_from_trajectory_mm"] = m["deviation_from_trajectory_mm"]
        out["return_points_speed"] = m["return_points"]
    return out


def forward_motion_table(job) -> dict[str, np.ndarray]:
    res = job.result
    speed = job.design.operation.carrier_speed_deg_s
    v = res.velocity(speed)
    dyn = res.dynamic_tip(speed, job.travel_m_s)
    with np.errstate(divide="ignore"):
        return {
            "carrier_angle_deg": res.carrier_angle * DEG,
            "time_s": res.time(speed),
            "tip_x_mm": res.tip[:, 0],
            "tip_y_mm": res.tip[:, 1],
            "vx_m_s": v[:, 0],
            "vy_m_s": v[:, 1],
            "speed_m_s": np.hypot(v[:, 0], v[:, 1]),
            "dynamic_x_mm": dyn[:, 0],
            "dynamic_y_mm": dyn[:, 1],
            "dynamic_speed_m_s": res.speed(speed, job.travel_m_s),
            "arm_angle_deg": res.arm_angle * DEG,
            "attitude_deg": (res.arm_angle - res.arm_angle[0]) * DEG,
            "gear2_angle_deg": res.gear2_angle * DEG,
            "planet_rel_deg": res.planet_rel * DEG,
            "ratio": speed_ratio(res.total_ratio),
            "stage1_ratio": speed_ratio(res.stage1_rate),
            "stage2_ratio": speed_ratio(res.stage2_rate),
        }


def write_forward_outputs(out: Path, job) -> list[Path]:
    written = [out / "summary.json", out / "motion.csv"]
    write_json(written[0], job.summary)
    write_csv(written[1], forward_motion_table(job), gaps=RATIO_GAPS)
    return written
