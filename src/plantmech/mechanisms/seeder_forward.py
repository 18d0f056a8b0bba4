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

from plantmech.gears.closure import ClosureFix, close_pair, solve_centre_distance  # noqa: F401
from plantmech.geometry.periodic import PitchCurveError, RadiusCurve
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
    total_ratio: np.ndarray  # d psi_4 / d psi (planet per carrier; 0 in the dwell)
    closure_error: dict
    tip_rate: np.ndarray  # d tip / d psi (mm/rad), analytic (Eq. 16)
    stage1_rate: np.ndarray | None = None  # d psi_2 / d psi = r1 / r2 (0 in the dwell)
    stage2_rate: np.ndarray | None = None  # d psi_4 / d psi_2 = r3 / r4
    in_dwell: np.ndarray | None = None

    def time(self, carrier_speed_deg_s: float = 360.0) -> np.ndarray:
        """Time (s) at each sample for the carrier speed (deg/s)."""
        return self.carrier_angle / np.radians(carrier_speed_deg_s)

    def velocity(self, carrier_speed_deg_s: float = 360.0) -> np.ndarray:
        """Static tip velocity (m/s) for a clockwise carrier speed (deg/s)."""
        return self.tip_rate * np.radians(carrier_speed_deg_s) / 1000.0

    def speed(self, carrier_speed_deg_s: float = 360.0, travel_m_s: float = 0.0):
        """Tip speed (m/s); with the machine travelling at ``travel_m_s`` along -x of the
        mechanism frame's horizontal this is the dynamic speed of Eq. 17."""
        v = self.velocity(carrier_speed_deg_s)
        return np.hypot(v[:, 0] - travel_m_s, v[:, 1])

    def dynamic_tip(self, carrier_speed_deg_s: float = 360.0, travel_m_s: float = 0.0):
        """Tip path (mm) over the ground for the machine travelling at ``travel_m_s``
        (Eq. 17's frame: x_ground = x - v_c t); origin at the carrier axis at t = 0."""
        shift = travel_m_s * 1000.0 * self.time(carrier_speed_deg_s)
        return np.c_[self.tip[:, 0] - shift, self.tip[:, 1]]


def rolling_integral(curve: RadiusCurve, contact0: float, a: float, dense: int):
    """F(t) = integral_0^t r / (a - r) dt' (rad) for the gear turning t from ``contact0``
    (mate's turn while the gear turns t): a cubic-spline antiderivative on ``dense``
    nodes. A non-periodic curve (break at its ``theta0``: the lock point of an
    intermittent gear, where the radius jumps) is integrated in two pieces that meet at
    the break exactly."""
    if curve.periodic:
        t = np.linspace(0.0, TWO_PI, dense + 1)
        r = curve(contact0 + t)
        return CubicSpline(t, r / (a - r)).antiderivative()
    spl = curve.spline
    tb = float(np.mod(curve.theta0 - contact0, TWO_PI))  # gear turn at which the break passes
    xc = curve.theta0 + np.mod(contact0 - curve.theta0, TWO_PI)  # spline abscissa at t = 0
    pieces = []
    for t0, t1, x0 in ((0.0, tb, xc), (tb, TWO_PI, curve.theta0)):
        if t1 - t0 < 1e-12:
            continue
        tt = np.linspace(t0, t1, max(8, int(dense * (t1 - t0) / TWO_PI)) + 1)
        r = spl(x0 + (tt - t0))
        pieces.append((t0, t1, CubicSpline(tt, r / (a - r)).antiderivative()))
    if len(pieces) == 1:
        return pieces[0][2]
    (_, tb_, fa), (_, _, fb) = pieces
    base = float(fa(tb_))

    def F(x):
        x = np.asarray(x, dtype=float)
        return np.where(x <= tb_, fa(np.minimum(x, tb_)), base + fb(np.maximum(x, tb_)))
    return F


def simulate(train: SeederTrain, samples: int = 3600, dense: int = 16384) -> ForwardResult:
    """Tip path at ``samples`` uniform carrier angles over one turn.

    Angles of gears 2-3 and of the planet are exact integrals of the
    instantaneous ratios (cubic-spline antiderivative on ``dense`` nodes, then
    Newton refinement of the carrier -> gear-2 inversion).
    """
    t = np.linspace(0.0, TWO_PI, dense + 1)
    sun_f = rolling_integral(train.gear2, train.gear2_contact0, train.a1, dense)
    planet_f = rolling_integral(train.gear3, train.gear3_contact0, train.a2, dense)
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
        # meshing carrier angle: held at the dwell start while the sector passes
        target = np.where(psi >= start + theta1, psi - theta1, np.where(in_dwell, start, psi))
    else:
        in_dwell = np.zeros(samples, dtype=bool)
        target = psi
    gear2 = np.interp(target, sun, t)
    for _ in range(4):
        r = train.gear2(train.gear2_contact0 + gear2)
        gear2 = gear2 - (sun_f(gear2) - target) * (train.a1 - r) / r
    planet_rel = planet_f(gear2)
    r2s = train.gear2(train.gear2_contact0 + gear2)
    r3s = train.gear3(train.gear3_contact0 + gear2)
    ratio = np.where(in_dwell, 0.0, (train.a1 - r2s) / r2s * r3s / (train.a2 - r3s))
    carrier_abs = train.carrier0 - psi
    arm = carrier_abs + planet_rel + (train.arm0 - train.carrier0)
    tip = tip_position(train.L1, train.L2, carrier_abs, arm)
    rate = tip_rate(train.L1, train.L2, carrier_abs, arm, ratio)
    stage1 = np.where(in_dwell, 0.0, (train.a1 - r2s) / r2s)
    stage2 = r3s / (train.a2 - r3s)
    return ForwardResult(psi, gear2, planet_rel, tip, arm, ratio, closure, rate,
                         stage1, stage2, in_dwell)



@dataclass
class GearPoints:
    """Interpolation points of gear 2 or 3: body angles (rad, increasing, within one
    turn) and pitch radii (mm); ``contact0`` is the body angle at the contact point
    (with the sun for gear 2, with the planet for gear 3) at carrier angle 0."""

    angles: np.ndarray
    radii: np.ndarray
    contact0: float = 0.0


def _check_positive(curve: RadiusCurve, a: float, name: str, mate: str, min_radius: float):
    t = curve.theta0 + np.linspace(0.0, TWO_PI, 7200, endpoint=False)
    r = curve(t)
    for label, rr in ((name, r), (mate, a - r)):
        k = int(np.argmin(rr))
        if rr[k] < min_radius:
            raise PitchCurveError(
                f"{label}: pitch radius {rr[k]:.3f} mm at {name} body angle "
                f"{np.degrees(np.mod(t[k], TWO_PI)):.2f} deg is below the minimum "
                f"{min_radius:g} mm (centre distance {a:.3f} mm); "
                "the interpolant overshoots or the radii are too large")


def assemble_train(L1: float, L2: float, a1: float, a2: float, gear2: GearPoints,
                   gear3: GearPoints, carrier0: float, arm0: float,
                   dwell_start: float | None = None, dwell_sector: float = 0.0,
                   kind: str = "hermite", closure: str = "check",
                   tolerance: float = np.radians(0.01), min_radius: float = 1.0,
                   ) -> tuple[SeederTrain, list[ClosureFix]]:
    """Build a train from interpolation points, closing both pairs by ``closure``
    (see ``gears.closure``). Raises PitchCurveError / ClosureError / ValueError with
    the gear, angle and numbers involved."""
    if dwell_start is not None and not (0.0 < dwell_sector < TWO_PI):
        raise ValueError("the toothless sector must span between 0 and 360 deg of carrier turn")
    turn1 = TWO_PI - (dwell_sector if dwell_start is not None else 0.0)
    g2, a1, fix1 = close_pair("sun - gear 2", gear2.angles, gear2.radii, a1, turn1, closure,
                              kind, tolerance, name="gear 2")
    g3, a2, fix2 = close_pair("gear 3 - planet", gear3.angles, gear3.radii, a2, TWO_PI,
                              closure, kind, tolerance, name="gear 3")
    _check_positive(g2, a1, "gear 2", "sun (gear 1)", min_radius)
    _check_positive(g3, a2, "gear 3", "planet (gear 4)", min_radius)
    if not (abs(a1 - a2) <= L1 <= a1 + a2):
        raise ValueError(f"the carrier cannot hold the shafts: L1 = {L1:.3f} mm but the "
                         f"centre distances a1 = {a1:.3f} and a2 = {a2:.3f} mm need "
                         f"{abs(a1 - a2):.3f} <= L1 <= {a1 + a2:.3f} mm")
    train = SeederTrain(L1=L1, L2=L2, a1=a1, a2=a2, gear2=g2, gear3=g3,
                        gear2_contact0=gear2.contact0, gear3_contact0=gear3.contact0,
                        carrier0=carrier0, arm0=arm0,
                        dwell_start=dwell_start, dwell_theta1=dwell_sector)
    return train, [fix1, fix2]


def shaft_offset(train: SeederTrain) -> float:
    """Angle (rad) at O between the carrier line O -> planet axis and O -> gear-2/3 shaft
    (0 when a1 + a2 = L1, the paper's collinear carrier)."""
    c = (train.a1**2 + train.L1**2 - train.a2**2) / (2 * train.a1 * train.L1)
    return float(np.arccos(np.clip(c, -1.0, 1.0)))


def sun_rolling_start(train: SeederTrain, dense: int = 16384) -> float:
    """Gear 2's body angle (rad) at the sun contact where the sun's rolling arc begins.

    With a toothless dwell (seed 000's sector cd, theta_1), gear 2 is held while the
    carrier turns theta_1 from ``dwell_start``: its body angle at the sun contact then is
    contact0 + psi_2(dwell_start), where the rolling of the sun (integral of r2 / r1,
    ``rolling_integral``) reaches dwell_start. The sun's rolling arc starts and ends
    there, and its toothless (locking) arc lies between its ends. Without a dwell: the
    curve's ``theta0``. Returned within [theta0, theta0 + 2 pi)."""
    theta0 = float(train.gear2.theta0)
    if train.dwell_start is None or train.dwell_theta1 <= 0:
        return theta0
    f = rolling_integral(train.gear2, train.gear2_contact0, train.a1, dense)
    t = np.linspace(0.0, TWO_PI, dense + 1)
    target = float(train.dwell_start)
    g = float(np.interp(target, f(t), t))
    for _ in range(4):  # Newton on F(g) = dwell_start; F' = r2 / (a1 - r2)
        r = float(train.gear2(train.gear2_contact0 + g))
        g -= (float(f(g)) - target) * (train.a1 - r) / r
    start = theta0 + float(np.mod(train.gear2_contact0 + g - theta0, TWO_PI))
    if not train.gear2.periodic and min(start - theta0, theta0 + TWO_PI - start) < 1e-4:
        # the inverse design's gear 2 breaks at the lock point (its radius steps there):
        # the root found is that break up to round-off, which must not land a hair before
        # it (the first sample would then take the radius from the break's other side)
        return theta0
    return start
