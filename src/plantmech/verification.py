"""Independent checks of a design: the inverse result's pitch curves are
re-interpolated and simulated forward by ``seeder_forward`` (a different
integration path), and the tip is compared with the trajectory."""

from __future__ import annotations

import numpy as np

from plantmech.geometry.periodic import convexity
from plantmech.mechanisms.seeder_forward import simulate

# train_from_inverse lives with the seeder's other train builders; imported here as before
from plantmech.mechanisms.seeder_trains import train_from_inverse

__all__ = ["round_trip", "train_from_inverse"]


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
