"""Open-chain three-bar model shared by every seeder model (seed 000 Eq. 12-16):
carrier O->B of length L1 at absolute angle carrier_abs, arm B->A of length L2 at
absolute angle arm. Arrays broadcast; the last axis of results is (x, y) in mm."""

from __future__ import annotations

import numpy as np


def tip_position(L1, L2, carrier_abs, arm) -> np.ndarray:
    """Tip A (mm)."""
    return np.stack([L1 * np.cos(carrier_abs) + L2 * np.cos(arm),
                     L1 * np.sin(carrier_abs) + L2 * np.sin(arm)], axis=-1)


def tip_rate(L1, L2, carrier_abs, arm, ratio) -> np.ndarray:
    """d A / d psi (mm/rad) for a clockwise carrier turn psi (d carrier_abs = -d psi)
    and a planet turning ``ratio`` = d psi_4 / d psi relative to the carrier, so the
    arm turns (ratio - 1) d psi (Eq. 16)."""
    turn = ratio - 1.0
    return np.stack([L1 * np.sin(carrier_abs) - L2 * turn * np.sin(arm),
                     -L1 * np.cos(carrier_abs) + L2 * turn * np.cos(arm)], axis=-1)
