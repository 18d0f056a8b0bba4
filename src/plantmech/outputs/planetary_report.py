"""Summary and tables of a general planetary train's forward run (units in every key)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from plantmech.outputs.files import write_csv, write_json
from plantmech.trains.curves import convexity

DEG = 180.0 / np.pi


def planetary_summary(design, motion, objectives: dict, checks: list) -> dict:
    """summary.json of design 0 of ``motion``: the train as built (centre distances,
    closure, pitch radii, convexity of every gear), the objectives and the checks."""
    built = motion.built
    pairs = []
    for k, (spec, law, drv, fol) in enumerate(zip(built.train.pairs, built.laws,
                                                  built.drivers, built.followers, strict=True)):
        cd, cf = convexity(drv.take(0)), convexity(fol.take(0))
        # r_driver / r_follower; a pair with a given follower rolls its law on the follower
        ratio = law.g[0] if spec.follower is None else 1.0 / law.g[0]
        pairs.append({
            "pair": k, "kind": law.kind, "centre_distance_mm": float(law.a[0]),
            "given": "follower" if spec.follower is not None else "driver",
            "follower_turns": spec.follower_turns,
            "closure_error_rad": float(law.closure_error[0]),
            "ratio_range": [float(ratio.min()), float(ratio.max())],
            "driver_radius_mm": [float(drv.r[0].min()), float(drv.r[0].max())],
            "follower_radius_mm": [float(fol.r[0].min()), float(fol.r[0].max())],
            "driver_convex": bool(cd["convex"][0]),
            "follower_convex": bool(cf["convex"][0]),
        })
    s = motion.built.shafts[0]
    return {
        "mechanism": "planetary",
        "name": design.name,
        "objectives": [c.as_dict() for c in checks],
        "values": {k: float(v[0]) if np.isfinite(v[0]) else None
                   for k, v in objectives.items()},
        "units": {"path_width_mm": "mm", "path_height_mm": "mm", "loops": "count",
                  "attitude_range_deg": "deg", "max_tip_speed_m_s": "m/s",
                  "min_tip_speed_m_s": "m/s", "arm_phase_deviation_mm": "mm"},
        "pairs": pairs,
        "shafts_mm": [[float(z.real), float(z.imag)] for z in s],
        "carrier_speed_deg_s": design.carrier.speed_deg_s,
        "carrier_direction": design.carrier.direction,
        "arms": design.carrier.arms,
        "samples": int(len(motion.carrier_angle)),
    }


def write_planetary_outputs(out: Path, design, motion, summary: dict) -> list[Path]:
    """summary.json, motion.csv (per arm: tip x/y mm, arm angle deg, tip speed m/s; planet
    axis of arm 1) and pitch_curves.csv (every gear's radius over its body angle)."""
    speed = design.carrier.speed_deg_s
    vel = motion.velocity(speed)[0]
    cols = {"carrier_angle_deg": motion.carrier_angle * DEG,
            "planet_x_mm": motion.centre[0, 0].real, "planet_y_mm": motion.centre[0, 0].imag}
    for j in range(motion.tip.shape[1]):
        cols[f"arm{j + 1}_tip_x_mm"] = motion.tip[0, j].real
        cols[f"arm{j + 1}_tip_y_mm"] = motion.tip[0, j].imag
        cols[f"arm{j + 1}_angle_deg"] = motion.arm_angle[0, j] * DEG
        cols[f"arm{j + 1}_speed_m_s"] = np.abs(vel[j])
    write_csv(out / "motion.csv", cols)
    built = motion.built
    gears = {"body_angle_deg": built.drivers[0].theta * DEG,
             "pair1_driver_sun_mm": built.drivers[0].r[0]}
    for k, (spec, drv, fol) in enumerate(zip(built.train.pairs, built.drivers,
                                             built.followers, strict=True)):
        if k and (spec.driver is not None or spec.follower is not None):  # not an idler
            gears[f"pair{k + 1}_driver_mm"] = drv.r[0]
        gears[f"pair{k + 1}_follower_mm"] = fol.r[0]
    write_csv(out / "pitch_curves.csv", gears)
    write_json(out / "summary.json", summary)
    return [out / "summary.json", out / "motion.csv", out / "pitch_curves.csv"]
