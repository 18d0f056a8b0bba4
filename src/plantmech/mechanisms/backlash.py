"""Angular play (backlash) in a gear train, shared by the seeder (seed 000) and the
transplanters (seed 001)."""

from __future__ import annotations

import numpy as np


def backlash_offset(ratio: np.ndarray, play) -> np.ndarray:
    """Arm angle offset (rad) from an angular play ``play`` (rad, scalar or shaped to
    broadcast against ``ratio``, e.g. (P, 1) or (P, 1, 1)) in the train: inertia-loaded,
    the arm lags the driving flank by half the play while its rotation relative to the
    carrier speeds up (d ratio / d psi > 0) and runs ahead on the other flank by half the
    play while it slows down: -play / 2 * sign(d ratio / d psi), the derivative a periodic
    centred difference over the cycle samples (last axis) of ``ratio`` (..., S) (the
    arm's (planet's) turn relative to the carrier per carrier turn). The flank change is
    taken as instantaneous; its impact on the tip speed is not modelled."""
    slope = np.roll(ratio, -1, axis=-1) - np.roll(ratio, 1, axis=-1)
    return -0.5 * np.asarray(play, dtype=float) * np.sign(slope)
