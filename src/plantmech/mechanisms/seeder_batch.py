"""Population forward kinematics of the second-order seeder train: P designs that
share the interpolation angles of their pitch curves are simulated at once with
array operations only (no Python loop per design or per sample).

Same model and conventions as ``seeder_forward``: pitch-curve radii of gears 2 and 3
at common node angles, r1 = a1 - r2, r4 = a2 - r3, rolling in the carrier frame, an
optional toothless dwell. Both interpolants (periodic cubic spline, periodic Hermite
with centred-difference tangents) are linear in the node radii, so they are applied
to the whole population as one matrix product; centre distances that close each pair
are solved for all designs at once (safeguarded Newton).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from plantmech.gears.closure import solve_centre_distances
from plantmech.geometry.periodic import (  # noqa: F401 (re-export)
    periodic_interpolant_rows,
    periodic_spline_matrix,
)
from plantmech.mechanisms.backlash import backlash_offset
from plantmech.mechanisms.three_bar import tip_position, tip_rate

TWO_PI = 2.0 * np.pi


@dataclass
class PopulationMotion:
    carrier_angle: np.ndarray  # (S,)
    tip: np.ndarray  # (P, S, 2) mm
    arm_angle: np.ndarray  # (P, S) rad
    total_ratio: np.ndarray  # (P, S)
    tip_rate: np.ndarray  # (P, S, 2) mm/rad
    closure_error: np.ndarray  # (P, 2) rad: stage 1, stage 2
    a1: np.ndarray | None = None  # (P,) mm, as given or solved
    a2: np.ndarray | None = None
    gear2_angle: np.ndarray | None = None  # (P, S) rad
    in_dwell: np.ndarray | None = None  # (S,)


def _hermite(y0, y1, d0, d1, h, s):
    """Cubic Hermite value at fraction s of an interval of width h."""
    h00 = 2 * s**3 - 3 * s**2 + 1
    h10 = s**3 - 2 * s**2 + s
    h01 = -2 * s**3 + 3 * s**2
    h11 = s**3 - s**2
    return h00 * y0 + h10 * h * d0 + h01 * y1 + h11 * h * d1


def _hermite_slope(y0, y1, d0, d1, h, s):
    """d/ds of ``_hermite``."""
    return ((6 * s**2 - 6 * s) * (y0 - y1) + (3 * s**2 - 4 * s + 1) * h * d0
            + (3 * s**2 - 2 * s) * h * d1)


def _radii_along(nodes, radii, contact0, t, kind):
    """Radii (P, D) mm and slopes (mm/rad) of each design's gear at body angles
    contact0 + t: one shared matrix for a shared contact angle, per-row evaluation of
    the same interpolant for per-design contact angles (P,)."""
    c = np.asarray(contact0, dtype=float)
    if c.ndim == 0:
        return tuple(radii @ periodic_spline_matrix(nodes, float(c) + t, nu, kind).T
                     for nu in (0, 1))
    at = c.reshape(-1, 1) + t[None, :]
    return periodic_interpolant_rows(nodes, radii, at, kind)


def simulate_population(nodes, radii2, radii3, L1, L2, a1, a2, carrier0, arm0,
                        contact2_0=np.pi, contact3_0=0.0, samples: int = 3600,
                        dense: int = 4096, kind: str = "spline",
                        dwell_start: float | None = None, dwell_sector: float = 0.0,
                        backlash=None) -> PopulationMotion:
    """Simulate P trains. radii2, radii3: (P, N) mm at ``nodes`` (N,) rad; L1, L2,
    carrier0, arm0 scalars or (P,); a1, a2 likewise, or None to solve the centre
    distance that closes each pair (Eq. 8; a1 for a sun turn of 2 pi - dwell_sector).
    contact2_0, contact3_0: body angles (rad) of gears 2 and 3 at their contacts at
    psi = 0, shared or (P,) (a per-design phase). ``dwell_start``/``dwell_sector`` (rad,
    shared): the toothless dwell. ``backlash``: None or the angular play (rad, scalar or
    (P,)) of the arm against the carrier (``backlash_offset``)."""
    r2n = np.atleast_2d(np.asarray(radii2, dtype=float))
    r3n = np.atleast_2d(np.asarray(radii3, dtype=float))
    P = r2n.shape[0]
    col = lambda v: np.broadcast_to(np.asarray(v, dtype=float), (P,))[:, None]  # noqa: E731
    t = np.linspace(0.0, TWO_PI, dense + 1)
    nodes = np.asarray(nodes, dtype=float)
    r2, dr2 = _radii_along(nodes, r2n, contact2_0, t, kind)  # (P, D+1)
    r3, dr3 = _radii_along(nodes, r3n, contact3_0, t, kind)
    theta1 = float(dwell_sector) if dwell_start is not None else 0.0
    if a1 is None:
        a1 = solve_centre_distances(r2[:, :-1], TWO_PI - theta1)
    if a2 is None:
        a2 = solve_centre_distances(r3[:, :-1], TWO_PI)
    a1_flat, a2_flat = np.broadcast_to(a1, (P,)).copy(), np.broadcast_to(a2, (P,)).copy()
    L1, L2, a1, a2 = col(L1), col(L2), col(a1), col(a2)
    carrier0, arm0 = col(carrier0), col(arm0)
    f_sun = r2 / (a1 - r2)  # d psi / d psi_2 while meshing
    f_pl = r3 / (a2 - r3)  # d psi_4 / d psi_2
    sun = CubicSpline(t, f_sun, axis=1).antiderivative()(t)
    planet = CubicSpline(t, f_pl, axis=1).antiderivative()(t)
    closure = np.c_[np.abs(sun[:, -1] + theta1 - TWO_PI), np.abs(planet[:, -1] - TWO_PI)]
    psi = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    # carrier angle -> meshing carrier angle (the dwell removes theta1 from the cycle)
    if theta1 > 0:
        start = float(dwell_start)
        in_dwell = (psi >= start) & (psi < start + theta1)
        target = np.where(psi >= start + theta1, psi - theta1, np.where(in_dwell, start, psi))
    else:
        in_dwell = np.zeros(samples, dtype=bool)
        target = psi
    # Invert psi(psi_2) at the targets for every design with one flat searchsorted.
    span = TWO_PI - theta1
    scale = (span / sun[:, -1])[:, None]  # map each design's meshing turn onto [0, span]
    sun_n = sun * scale
    offs = (np.arange(P) * 10.0)[:, None]
    flat = (sun_n + offs).ravel()
    k = np.searchsorted(flat, (target[None, :] + offs).ravel(), side="right") - 1
    k = k.reshape(P, samples) - (np.arange(P) * (dense + 1))[:, None]
    k = np.clip(k, 0, dense - 1)
    rows = np.arange(P)[:, None]
    h = t[1] - t[0]
    y0, y1 = sun_n[rows, k], sun_n[rows, k + 1]
    d0, d1 = f_sun[rows, k] * scale, f_sun[rows, k + 1] * scale
    s = (target[None, :] - y0) / np.maximum(y1 - y0, 1e-300)
    for _ in range(3):  # Newton on the Hermite cubic of psi(psi_2) within the interval
        val = _hermite(y0, y1, d0, d1, h, s) - target[None, :]
        s = np.clip(s - val / _hermite_slope(y0, y1, d0, d1, h, s), 0.0, 1.0)
    gear2 = t[k] + s * h
    planet_rel = _hermite(planet[rows, k], planet[rows, k + 1], f_pl[rows, k],
                          f_pl[rows, k + 1], h, s)
    r2s = _hermite(r2[rows, k], r2[rows, k + 1], dr2[rows, k], dr2[rows, k + 1], h, s)
    r3s = _hermite(r3[rows, k], r3[rows, k + 1], dr3[rows, k], dr3[rows, k + 1], h, s)
    ratio = np.where(in_dwell[None, :], 0.0, (a1 - r2s) / r2s * r3s / (a2 - r3s))
    carrier_abs = carrier0 - psi[None, :]
    arm = carrier_abs + planet_rel + (arm0 - carrier0)
    if backlash is not None:
        arm = arm + backlash_offset(ratio, col(backlash))
    tip = tip_position(L1, L2, carrier_abs, arm)
    rate = tip_rate(L1, L2, carrier_abs, arm, ratio)
    return PopulationMotion(psi, tip, arm, ratio, rate, closure, a1_flat, a2_flat, gear2,
                            in_dwell)
