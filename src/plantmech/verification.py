"""Independent checks of a design: the inverse result's pitch curves are
re-interpolated and simulated forward by ``seeder_forward`` (a different
integration path), and the tip is compared with the trajectory."""

from __future__ import annotations

import numpy as np

from plantmech.geometry.periodic import RadiusCurve, convexity
from plantmech.mechanisms.seeder_forward import SeederTrain, simulate
from plantmech.outputs.seeder_report import gear_body_angles


def train_from_inverse(res) -> SeederTrain:
    """Build the forward model's train from the inverse design's pitch curves."""
    ang = gear_body_angles(res)
    ok = np.isfinite(res.r2)
    has_dwell = res.dwell is not None
    # With a dwell gears 2-3 have a break (lock point): interpolate on the open turn.
    k0 = 0
    if has_dwell:
        end_k = int(np.flatnonzero(~ok)[-1])
        k0 = (end_k + 1) % len(ok)
    th2 = ang["gear2"][ok]
    th3 = ang["gear3"][ok]
    theta0_2 = ang["gear2"][k0] if has_dwell else None
    theta0_3 = ang["gear3"][k0] if has_dwell else None
    g2 = RadiusCurve.from_samples(th2, res.r2[ok], periodic=not has_dwell, theta0=theta0_2,
                                  name="gear 2")
    g3 = RadiusCurve.from_samples(th3, res.r3[ok], periodic=not has_dwell, theta0=theta0_3,
                                  name="gear 3")
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
