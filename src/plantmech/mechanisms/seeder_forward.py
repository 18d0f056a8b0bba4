"""Forward kinematics of the second-order non-circular planetary train from its
pitch curves (seed 000 §4.3, Eq. 10-16, integrated exactly).

Inputs are the radius functions of gears 2 and 3 in their (common) body frame;
the sun and planet follow from the centre distances (r1 = a1 - r2, r4 = a2 - r3).
Rolling in the carrier frame: d psi_sun = (r2 / r1) d psi_2 and
d psi_4 = (r3 / r4) d psi_2, with psi_2 the clockwise turn of gears 2-3 and
psi_4 the counter-clockwise turn of the planet, both relative to the carrier.
A toothless dwell holds psi_2 while the carrier turns theta1.
Conventions as in ``seeder_inverse``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from plantmech.geometry.periodic import RadiusCurve
from plantmech.mechanisms.three_bar import tip_position, tip_rate

TWO_PI = 2.0 * np.pi


@dataclass
class SeederTrain:
    """A complete second-order train. Lengths mm, angles rad."""

    L1: float  # carrier length O -> planet axis
    L2: float  # arm length planet axis -> tip
    a1: float
    a2: float
    gear2: RadiusCurve  # r2(body angle) at the contact with the sun
    gear3: RadiusCurve  # r3(body angle) at the contact with the planet
    gear2_contact0: float  # body angle of gear 2 at the sun contact at psi = 0
    gear3_contact0: float  # body angle of gear 3 at the planet contact at psi = 0
    carrier0: float  # absolute carrier angle phi_10 at psi = 0
    arm0: float  # absolute arm angle at psi = 0
    dwell_start: float | None = None  # carrier angle where the dwell begins
    dwell_theta1: float = 0.0  # carrier angle spanned by the toothless sector


@dataclass
class ForwardResult:
    carrier_angle: np.ndarray
    gear2_angle: np.ndarray
    planet_rel: np.ndarray
    tip: np.ndarray
    arm_angle: np.ndarray
    total_ratio: np.ndarray  # d psi_4 / d psi
    closure_error: dict
    tip_rate: np.ndarray  # d tip / d psi (mm/rad), analytic (Eq. 16)

    def velocity(self, carrier_speed_deg_s: float = 360.0) -> np.ndarray:
        """Static tip velocity (m/s) for a clockwise carrier speed (deg/s)."""
        return self.tip_rate * np.radians(carrier_speed_deg_s) / 1000.0

    def speed(self, carrier_speed_deg_s: float = 360.0, travel_m_s: float = 0.0):
        """Tip speed (m/s); with the machine travelling at ``travel_m_s`` along -x of the
        mechanism frame's horizontal this is the dynamic speed of Eq. 17."""
        v = self.velocity(carrier_speed_deg_s)
        return np.hypot(v[:, 0] - travel_m_s, v[:, 1])


def simulate(train: SeederTrain, samples: int = 3600, dense: int = 16384) -> ForwardResult:
    """Tip path at ``samples`` uniform carrier angles over one turn.

    Angles of gears 2-3 and of the planet are exact integrals of the
    instantaneous ratios (cubic-spline antiderivative on ``dense`` nodes, then
    Newton refinement of the carrier -> gear-2 inversion).
    """
    t = np.linspace(0.0, TWO_PI, dense + 1)
    r2 = train.gear2(train.gear2_contact0 + t)
    r3 = train.gear3(train.gear3_contact0 + t)
    sun_f = CubicSpline(t, r2 / (train.a1 - r2)).antiderivative()
    planet_f = CubicSpline(t, r3 / (train.a2 - r3)).antiderivative()
    sun = sun_f(t)
    theta1 = train.dwell_theta1 if train.dwell_start is not None else 0.0
    closure = {"stage1": float(abs(sun[-1] + theta1 - TWO_PI)),
               "stage2": float(abs(planet_f(TWO_PI) - TWO_PI))}
    psi = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    if theta1 > 0:
        start = float(train.dwell_start)
        if start < 0 or start + theta1 > TWO_PI:
            raise ValueError("the dwell must lie inside one carrier turn from the start")
        in_dwell = (psi >= start) & (psi < start + theta1)
        target = np.where(psi >= start + theta1, psi - theta1, psi)
        lock = float(np.interp(start, sun, t))
    else:
        in_dwell = np.zeros(samples, dtype=bool)
        target = psi
        lock = 0.0
    gear2 = np.interp(target, sun, t)
    for _ in range(4):
        r = train.gear2(train.gear2_contact0 + gear2)
        gear2 = gear2 - (sun_f(gear2) - target) * (train.a1 - r) / r
    gear2 = np.where(in_dwell, lock, gear2)
    planet_rel = planet_f(gear2)
    r2s = train.gear2(train.gear2_contact0 + gear2)
    r3s = train.gear3(train.gear3_contact0 + gear2)
    ratio = np.where(in_dwell, 0.0, (train.a1 - r2s) / r2s * r3s / (train.a2 - r3s))
    carrier_abs = train.carrier0 - psi
    arm = carrier_abs + planet_rel + (train.arm0 - train.carrier0)
    tip = tip_position(train.L1, train.L2, carrier_abs, arm)
    rate = tip_rate(train.L1, train.L2, carrier_abs, arm, ratio)
    return ForwardResult(psi, gear2, planet_rel, tip, arm, ratio, closure, rate)


def solve_centre_distance(curve: RadiusCurve, turn: float = TWO_PI, dense: int = 8192) -> float:
    """Centre distance a (mm) at which the mate of ``curve`` (external pair, r_mate =
    a - r) turns ``turn`` rad while ``curve`` turns once (Eq. 8 closure).

    The mate's turn  int r/(a - r) dtheta  falls monotonically with a, so the root is
    unique; it is bracketed above max r.
    """
    from scipy.optimize import brentq

    t = np.linspace(0.0, TWO_PI, dense, endpoint=False)
    r = curve(curve.theta0 + t)
    rmax = float(r.max())

    def excess(a):
        return float(np.mean(r / (a - r)) * TWO_PI - turn)

    lo, hi = rmax * (1 + 1e-9), rmax * 2.0 + 1.0
    while excess(hi) > 0:
        hi *= 2.0
    return float(brentq(excess, lo, hi, xtol=1e-12, rtol=1e-14))
