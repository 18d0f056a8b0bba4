"""Pitch curves of external non-circular gear pairs from their ratio law.

For an external pair on fixed centres (in the carrier frame) at centre distance
``a`` with driver radius r_d and follower radius r_f at the contact point:
r_d + r_f = a and  d(theta_f)/d(theta_d) = r_d / r_f  (pure rolling).
With the paper's ratio i = omega_d / omega_f = r_f / r_d (seed 000, Eq. 9):
r_f = a i / (1 + i),  r_d = a / (1 + i).
Angles in radians, lengths in mm.
"""

from __future__ import annotations

import numpy as np


def radii_from_speed_ratio(a: float, follower_per_driver) -> tuple[np.ndarray, np.ndarray]:
    """(r_driver, r_follower) for angular-speed ratio q = omega_f/omega_d = 1/i (Eq. 9).

    q = 0 (follower at rest: toothless sector) gives r_driver = 0, r_follower = a.
    """
    q = np.asarray(follower_per_driver, dtype=float)
    r_follower = a / (1.0 + q)
    return a - r_follower, r_follower


def toothless_sector_follower_angle(theta1: float, edge_radius: float, a: float) -> float:
    """Seed 000 Eq. 5: angle theta2 (rad) subtended at the follower's centre by the
    driver's toothless arc of central angle theta1 and edge radius R2."""
    half = 0.5 * theta1
    return float(2.0 * np.arctan2(edge_radius * np.sin(half), a - edge_radius * np.cos(half)))


def cumulative_trapezoid_periodic(values: np.ndarray, step: float,
                                  smooth: bool = False) -> np.ndarray:
    """Running integral of a periodic function sampled at n equal steps -> n+1 values.

    smooth=True integrates the periodic cubic spline through the samples (4th order,
    for smooth laws); otherwise the trapezoidal rule (robust across jumps, e.g. at the
    ends of a toothless dwell).
    """
    if smooth:
        from plantmech.geometry.periodic import periodic_spline_running_integral

        return periodic_spline_running_integral(values, step)
    return np.r_[0.0, np.cumsum(0.5 * (values + np.roll(values, -1)) * step)]


def body_polar_curve(body_angle: np.ndarray, radius: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """Radius on a body-angle ``grid`` (rad) of a pitch curve given at contact
    ``body_angle`` samples (monotonic after sorting mod 2 pi). NaN where undefined."""
    ang = np.mod(body_angle, 2 * np.pi)
    order = np.argsort(ang, kind="stable")
    ang, rad = ang[order], radius[order]
    ang = np.r_[ang[-1] - 2 * np.pi, ang, ang[0] + 2 * np.pi]
    rad = np.r_[rad[-1], rad, rad[0]]
    return np.interp(np.mod(grid, 2 * np.pi), ang, rad)
