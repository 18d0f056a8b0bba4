"""Summary, tables and plots of a transplanting mechanism (seed 001)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from plantmech.outputs.files import write_csv, write_json

DEG = 180.0 / np.pi
ROMAN = ["I", "II", "III", "IV", "V", "VI"]


def arm_phase_deviation(motion, k: int = 0) -> list[float]:
    """max |B_j(psi) - B_0(psi + 2 pi j / J)| (mm) for each arm j: zero when the arms
    repeat each other's motion after the carrier phase shift between them."""
    B = motion.B[k]
    J, S = B.shape
    out = []
    for j in range(J):
        shift = S * j / J
        if abs(shift - round(shift)) < 1e-9:
            ref = np.roll(B[0], -int(round(shift)))
        else:
            psi = motion.carrier_angle
            x = np.mod(psi + 2 * np.pi * j / J, 2 * np.pi)
            xp = np.r_[psi, 2 * np.pi]
            ref = (np.interp(x, xp, np.r_[B[0].real, B[0, 0].real])
                   + 1j * np.interp(x, xp, np.r_[B[0].imag, B[0, 0].imag]))
        out.append(float(np.abs(B[j] - ref).max()))
    return out


def stages_table(job, k: int = 0) -> dict:
    """Stage intervals per arm in carrier angle (deg): picking, conveying, planting,
    return (start, end), clockwise from the start."""
    st = job.evaluation.metrics["stages_deg"]
    out = {}
    J = job.motion.B.shape[1]
    for j in range(J):
        pick = st["picking"][k, j]
        plant = st["planting"][k, j]
        arm = {"picking": _pair(pick), "planting": _pair(plant)}
        if np.all(np.isfinite(pick)):
            arm["conveying"] = [float(pick[1]), float(plant[0])]
            arm["return"] = [float(plant[1]), float(pick[0])]
        out[f"arm_{ROMAN[j]}"] = arm
    return out


def _pair(v):
    return [float(x) for x in v] if np.all(np.isfinite(v)) else None


def transplanter_summary(job, k: int = 0) -> dict:
    d, m, ev = job.design, job.motion, job.evaluation
    vals = dict(zip(ev.names, ev.values[k], strict=True))
    met = ev.metrics

    def num(x):
        return None if x is None or not np.isfinite(x) else float(x)

    out = {
        "mechanism": d.mechanism,
        "name": d.name,
        "objectives": [c.as_dict() for c in ev.checks(k)],
        "all_objectives_met": bool(ev.ok[k].all()),
        "trajectory_height_mm": num(vals["trajectory_height"]),
        "picking_angle_deg": num(vals["picking_angle"]),
        "pushing_angle_deg": num(vals["pushing_angle"]),
        "angle_difference_deg": num(vals["angle_difference"]),
        "forward_inclination_deg": num(vals["forward_inclination"]),
        "hole_width_mm": num(vals["hole_width"]),
        "module_mm": num(vals["module"]),
        "stages_deg": stages_table(job, k),
        "arm_phase_deviation_mm": arm_phase_deviation(m, k),
        "seedling_block_mm": {"upper": num(met["block_upper_mm"][k]),
                              "lower": num(met["block_lower_mm"][k])},
        "hole_width_by_spacing_mm": {f"{s:g}": float(w) for s, w in
                                     zip(met["spacings_mm"], met["hole_widths_mm"][k],
                                         strict=True)},
        "ground_y_mm": float(met["ground_y_mm"][k]),
        "centre_distance_mm": float(m.centre_distance[k]),
        "closure_error_rad": float(m.closure_error[k]),
        "perimeter_mm": job.perimeter_mm,
        "gearbox_radius_mm": job.gearbox_radius_mm,
        "carrier_speed_deg_s": d.drive.carrier_speed_deg_s,
        "samples": int(len(m.carrier_angle)),
    }
    g = getattr(d, "internal_gear", None)  # the differential's lobed internal gear
    if g is not None:
        rp = job.pair.planet_radius[k]
        ratio = d.drive.speed_ratio or (g.lobes - 1) / g.lobes
        out["speed_ratio_omega1_omega2"] = ratio
        out["internal_pitch_radius_mm"] = {"min": float(job.pair.R[k].min()),
                                           "max": float(job.pair.R[k].max())}
        out["planet_pitch_radius_mm"] = {"min": float(rp.min()), "max": float(rp.max())}
        out["teeth"] = {"internal": g.teeth, "planet": g.teeth // g.lobes if g.teeth else None}
    rate = m.planet_rate[k, 0]
    out["ratio_planet_per_carrier"] = {"min": float(rate.min()), "max": float(rate.max())}
    return out


def motion_table(job, k: int = 0) -> dict[str, np.ndarray]:
    m = job.motion
    v = m.velocity(job.design.drive.carrier_speed_deg_s)[k]
    d = job.design
    cols = {"carrier_angle_deg": m.carrier_angle * DEG,
            "time_s": m.carrier_angle * DEG / d.drive.carrier_speed_deg_s}
    g = getattr(d, "internal_gear", None)  # the differential's internal gear turns
    if g is not None:
        ratio = d.drive.speed_ratio or (g.lobes - 1) / g.lobes
        cols["internal_gear_angle_deg"] = m.carrier_angle * DEG * ratio  # theta_1, clockwise
    J = m.B.shape[1]
    sign = job.evaluation.metrics["forward_sign"][k]
    advance = d.field.plant_spacing_mm * J  # mm per carrier turn
    for j in range(J):
        tag = f"arm{j + 1}"
        cols[f"{tag}_tip_x_mm"] = m.B[k, j].real
        cols[f"{tag}_tip_y_mm"] = m.B[k, j].imag
        cols[f"{tag}_break_x_mm"] = m.A[k, j].real
        cols[f"{tag}_break_y_mm"] = m.A[k, j].imag
        cols[f"{tag}_needle_angle_deg"] = m.needle_angle[k, j]
        cols[f"{tag}_planet_angle_deg"] = np.mod(m.planet_angle[k, j] * DEG, 360.0)
        cols[f"{tag}_absolute_x_mm"] = (m.B[k, j].real * sign
                                        + advance * m.carrier_angle / (2 * np.pi))
        cols[f"{tag}_speed_m_s"] = np.abs(v[j])
        cols[f"{tag}_planet_ratio"] = m.planet_rate[k, j]
    return cols


def write_transplanter_outputs(out: Path, job) -> list[Path]:
    written = [out / "summary.json", out / "motion.csv"]
    write_json(written[0], job.summary)
    write_csv(written[1], motion_table(job))
    return written
