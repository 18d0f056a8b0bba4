"""Independent checks of a design: the inverse result's pitch curves are
re-interpolated and simulated forward by ``seeder_forward`` (a different
integration path), and the tip is compared with the trajectory."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from plantmech.geometry.periodic import RadiusCurve, convexity
from plantmech.mechanisms.seeder_forward import SeederTrain, simulate
from plantmech.outputs.seeder_report import gear_body_angles


def train_from_inverse(res) -> SeederTrain:
    """Build the forward model's train from the inverse design's pitch curves.

    With a dwell, gears 2 and 3 have a break at the lock point (their ratio jumps when
    meshing stops and restarts): each is interpolated on one open turn from the lock,
    with the inverse design's exact edge radii as the end nodes.
    """
    ang = gear_body_angles(res)
    ok = np.isfinite(res.r2)
    has_dwell = res.dwell is not None
    if not has_dwell:
        g2 = RadiusCurve.from_samples(ang["gear2"][ok], res.r2[ok], name="gear 2")
        g3 = RadiusCurve.from_samples(ang["gear3"][ok], res.r3[ok], name="gear 3")
    else:
        k_lock = int(np.flatnonzero(~ok)[0])
        edges = res.dwell["edge_pitch_radii"]
        curves = []
        for key, name in (("gear2", "r2"), ("gear3", "r3")):
            lock = float(ang[key][k_lock])
            x = lock + np.mod(ang[key][ok] - lock, 2 * np.pi)
            r = getattr(res, name)[ok]
            order = np.argsort(x)
            x, r = x[order], r[order]
            keep = (x > lock + 1e-9) & (x < lock + 2 * np.pi - 1e-9)
            xs = np.r_[lock, x[keep], lock + 2 * np.pi]
            rs = np.r_[edges["meshing_start"][name], r[keep], edges["meshing_end"][name]]
            curves.append(RadiusCurve(lock, CubicSpline(xs, rs), periodic=False))
        g2, g3 = curves
    return SeederTrain(
        L1=res.L1, L2=res.L2, a1=res.a1, a2=res.a2, gear2=g2, gear3=g3,
        gear2_contact0=float(ang["gear2"][0]), gear3_contact0=float(ang["gear3"][0]),
        carrier0=float(res.carrier_abs[0]), arm0=float(res.arm_angle_realized[0]),
        dwell_start=res.dwell["carrier_start"] if has_dwell else None,
        dwell_theta1=res.dwell["theta1"] if has_dwell else 0.0,
    )


def round_trip(job) -> dict:
    """Forward-simulate the designed train; deviations in mm."""
    res = job.result
    train = train_from_inverse(res)
    fwd = simulate(train, samples=len(res.carrier_angle))
    dev_real = np.hypot(*(fwd.tip - res.tip_realized).T)
    dev_plan = np.hypot(*(fwd.tip - res.tip).T)
    return {
        "round_trip_max_deviation_mm": float(dev_plan.max()),
        "round_trip_vs_gear_train_mm": float(dev_real.max()),
        "round_trip_closure_error_rad": fwd.closure_error,
        "convexity": {"gear2": convexity(train.gear2), "gear3": convexity(train.gear3)},
    }
