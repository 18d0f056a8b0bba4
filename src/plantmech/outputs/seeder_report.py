"""Summary, tables and plots of a seeder inverse design."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from plantmech.gears.pitch import body_polar_curve
from plantmech.mechanisms.seeder_inverse import InverseResult
from plantmech.mechanisms.seeder_trains import gear_body_angles
from plantmech.objectives.inverse_evaluation import summary
from plantmech.outputs.files import write_csv, write_json

# gear_body_angles and summary live in their layers; imported here as before issue 16
__all__ = ["RATIO_GAPS", "gear_body_angles", "motion_table", "pitch_curve_table",
           "speed_ratio", "summary", "trajectory_table", "write_inverse_outputs"]

DEG = 180.0 / np.pi


def pitch_curve_table(res: InverseResult, step_deg: float = 0.5) -> dict[str, np.ndarray]:
    grid = np.radians(np.arange(0.0, 360.0, step_deg))
    ang = gear_body_angles(res)
    table = {"angle_deg": np.degrees(grid)}
    for col, key, r in (("r1_mm", "sun", res.r1), ("r2_mm", "gear2", res.r2),
                        ("r3_mm", "gear3", res.r3), ("r4_mm", "planet", res.r4)):
        ok = np.isfinite(r)
        vals = body_polar_curve(ang[key][ok], r[ok], grid)
        if key == "sun" and res.dwell is not None:
            # toothless sector: body angles the contact never visits while meshing
            a = np.mod(ang["sun"], 2 * np.pi)
            dwell_a = a[~ok]
            lo, hi = dwell_a.min(), dwell_a.max()
            if hi - lo < np.pi:
                vals = np.where((grid >= lo) & (grid <= hi), np.nan, vals)
        table[col] = vals
    return table


#: motion.csv columns with a gap (empty cell) where the gears stand still in the sun's
#: toothless dwell: the speed ratio omega_carrier / omega_gear is not defined there.
RATIO_GAPS = ("ratio", "stage1_ratio", "stage2_ratio")


def speed_ratio(rate: np.ndarray) -> np.ndarray:
    """1 / rate, NaN (a gap in the CSV) where the rate is 0 (gears stopped in the dwell)."""
    rate = np.asarray(rate, dtype=float)
    return np.divide(1.0, rate, out=np.full_like(rate, np.nan), where=rate != 0)


def motion_table(res: InverseResult) -> dict[str, np.ndarray]:
    with np.errstate(divide="ignore"):
        return {
            "carrier_angle_deg": res.carrier_angle * DEG,
            "tip_x_mm": res.tip_realized[:, 0],
            "tip_y_mm": res.tip_realized[:, 1],
            "planned_x_mm": res.tip[:, 0],
            "planned_y_mm": res.tip[:, 1],
            "arm_angle_deg": res.arm_angle_realized * DEG,
            "planet_rel_deg": res.planet_rel_realized * DEG,
            "ratio": speed_ratio(res.total_ratio),
            "stage1_ratio": speed_ratio(res.stage1_ratio),
            "stage2_ratio": speed_ratio(res.stage2_ratio),
        }


def trajectory_table(traj, samples: int) -> dict[str, np.ndarray]:
    """The planned curve sampled uniformly in arc length (start at q0)."""
    s, u = traj.arc_length_samples(samples)
    xy = traj(u)
    return {
        "arc_length_mm": s,
        "x_mm": xy[:, 0],
        "y_mm": xy[:, 1],
        "curvature_1_per_mm": traj.curvature(u),
        "point_index": traj.point_index_of(u),
    }


def write_inverse_outputs(out: Path, res: InverseResult, summ: dict, traj,
                          samples: int) -> list[Path]:
    """Write summary.json and trajectory.csv always; motion and pitch curves only for
    feasible designs."""
    written = [out / "summary.json", out / "trajectory.csv"]
    write_json(written[0], summ)
    write_csv(written[1], trajectory_table(traj, samples))
    if res.feasible:
        write_csv(out / "motion.csv", motion_table(res), gaps=RATIO_GAPS)
        write_csv(out / "pitch_curves.csv", pitch_curve_table(res), fmt="%.5f",
                  gaps=("r1_mm",))
        written += [out / "motion.csv", out / "pitch_curves.csv"]
    else:
        for stale in ("motion.csv", "pitch_curves.csv", "pitch_curves.png", "ratios.png"):
            p = out / stale
            if p.exists():
                p.unlink()  # never leave pitch curves of an earlier, different design
    return written
