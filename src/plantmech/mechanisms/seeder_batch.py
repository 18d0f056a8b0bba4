"""Population forward kinematics of the second-order seeder train: P designs that
share the interpolation angles of their pitch curves are simulated at once with
array operations only (no Python loop per design or per sample).

Same model and conventions as ``seeder_forward`` (no dwell here): pitch-curve radii
of gears 2 and 3 at common node angles, r1 = a1 - r2, r4 = a2 - r3, rolling in the
carrier frame. Periodic cubic-spline interpolation is linear in the node radii, so it
is applied to the whole population as one matrix product.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from plantmech.mechanisms.three_bar import tip_position, tip_rate

TWO_PI = 2.0 * np.pi


def periodic_spline_matrix(nodes: np.ndarray, at: np.ndarray, nu: int = 0) -> np.ndarray:
    """Matrix M (len(at) x len(nodes)) with M @ r = nu-th derivative of the periodic
    cubic spline through (nodes, r) at angles ``at`` (rad)."""
    n = len(nodes)
    eye = np.eye(n)
    x = np.r_[nodes, nodes[0] + TWO_PI]
    spl = CubicSpline(x, np.vstack([eye, eye[:1]]), bc_type="periodic")
    return spl(nodes[0] + np.mod(at - nodes[0], TWO_PI), nu)


@dataclass
class PopulationMotion:
    carrier_angle: np.ndarray  # (S,)
    tip: np.ndarray  # (P, S, 2) mm
    arm_angle: np.ndarray  # (P, S) rad
    total_ratio: np.ndarray  # (P, S)
    tip_rate: np.ndarray  # (P, S, 2) mm/rad
    closure_error: np.ndarray  # (P, 2) rad: stage 1, stage 2


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


def simulate_population(nodes, radii2, radii3, L1, L2, a1, a2, carrier0, arm0,
                        contact2_0=np.pi, contact3_0=0.0, samples: int = 3600,
                        dense: int = 4096) -> PopulationMotion:
    """Simulate P trains. radii2, radii3: (P, N) mm at ``nodes`` (N,) rad; the other
    arguments are scalars or (P,) arrays (mm, rad)."""
    r2n = np.atleast_2d(np.asarray(radii2, dtype=float))
    r3n = np.atleast_2d(np.asarray(radii3, dtype=float))
    P = r2n.shape[0]
    col = lambda v: np.broadcast_to(np.asarray(v, dtype=float), (P,))[:, None]  # noqa: E731
    L1, L2, a1, a2 = col(L1), col(L2), col(a1), col(a2)
    carrier0, arm0 = col(carrier0), col(arm0)
    t = np.linspace(0.0, TWO_PI, dense + 1)
    nodes = np.asarray(nodes, dtype=float)
    r2 = r2n @ periodic_spline_matrix(nodes, contact2_0 + t).T  # (P, D+1)
    r3 = r3n @ periodic_spline_matrix(nodes, contact3_0 + t).T
    dr2 = r2n @ periodic_spline_matrix(nodes, contact2_0 + t, 1).T
    dr3 = r3n @ periodic_spline_matrix(nodes, contact3_0 + t, 1).T
    f_sun = r2 / (a1 - r2)  # d psi / d psi_2
    f_pl = r3 / (a2 - r3)  # d psi_4 / d psi_2
    sun = CubicSpline(t, f_sun, axis=1).antiderivative()(t)
    planet = CubicSpline(t, f_pl, axis=1).antiderivative()(t)
    closure = np.c_[np.abs(sun[:, -1] - TWO_PI), np.abs(planet[:, -1] - TWO_PI)]
    # Invert psi(psi_2) at uniform psi for every design with one flat searchsorted.
    psi = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    scale = (TWO_PI / sun[:, -1])[:, None]  # map each design's turn onto [0, 2 pi]
    sun_n = sun * scale
    offs = (np.arange(P) * 10.0)[:, None]
    flat = (sun_n + offs).ravel()
    k = np.searchsorted(flat, (psi[None, :] + offs).ravel(), side="right") - 1
    k = k.reshape(P, samples) - (np.arange(P) * (dense + 1))[:, None]
    k = np.clip(k, 0, dense - 1)
    rows = np.arange(P)[:, None]
    h = t[1] - t[0]
    y0, y1 = sun_n[rows, k], sun_n[rows, k + 1]
    d0, d1 = f_sun[rows, k] * scale, f_sun[rows, k + 1] * scale
    s = (psi[None, :] - y0) / np.maximum(y1 - y0, 1e-300)
    for _ in range(3):  # Newton on the Hermite cubic of psi(psi_2) within the interval
        val = _hermite(y0, y1, d0, d1, h, s) - psi[None, :]
        s = np.clip(s - val / _hermite_slope(y0, y1, d0, d1, h, s), 0.0, 1.0)
    planet_rel = _hermite(planet[rows, k], planet[rows, k + 1], f_pl[rows, k],
                          f_pl[rows, k + 1], h, s)
    r2s = _hermite(r2[rows, k], r2[rows, k + 1], dr2[rows, k], dr2[rows, k + 1], h, s)
    r3s = _hermite(r3[rows, k], r3[rows, k + 1], dr3[rows, k], dr3[rows, k + 1], h, s)
    ratio = (a1 - r2s) / r2s * r3s / (a2 - r3s)
    carrier_abs = carrier0 - psi[None, :]
    arm = carrier_abs + planet_rel + (arm0 - carrier0)
    tip = tip_position(L1, L2, carrier_abs, arm)
    rate = tip_rate(L1, L2, carrier_abs, arm, ratio)
    return PopulationMotion(psi, tip, arm, ratio, rate, closure)
