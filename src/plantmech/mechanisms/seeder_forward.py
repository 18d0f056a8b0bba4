"""Forward kinematics of the second-order non-circular planetary train from its
pitch curves (seed 000 §4.3, Eq. 10-16, integrated exactly).

Inputs are the radius functions of gears 2 and 3 in their (common) body frame;
the sun and planet follow from the centre distances (r1 = a1 - r2, r4 = a2 - r3).
Rolling in the carrier frame: d psi_sun = (r2 / r1) d psi_2 and
d psi_4 = (r3 / r4) d psi_2, with psi_2 the clockwise turn of gears 2-3 and
psi_4 the counter-clockwise turn of the planet, both relative to the carrier.
A toothless dwell holds psi_2 while the carrier turns theta1.
Conventions as in ``seeder_inverse``.

One design is a population of one: ``simulate`` hands the train's pitch curves (as
piecewise cubic Hermite over one turn, ``hermite_form``) to the population model
(``seeder_batch.simulate_curves`` and its numba kernel ``seeder_kernel.simulate_rows``),
which integrates, inverts and places the tip; this module builds and checks trains and
keeps the per-sample arrays of one design (``ForwardResult``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

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


def hermite_form(curve: RadiusCurve) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pitch curve over one turn of its body angle from ``theta0`` as the population
    kernel takes it: (knots (N + 1,) rad from theta0 to theta0 + 2 pi, radii (N + 1,) mm,
    slopes (N + 1,) mm/rad), the last two the left limits at the end knot. Exact for every
    ``RadiusCurve`` (piecewise cubics: periodic spline, periodic Hermite, an open spline
    with its break at theta0, extrapolated to the end of the turn)."""
    spl = curve.spline
    x = np.asarray(spl.x, dtype=float)
    end = curve.theta0 + TWO_PI
    x = np.r_[curve.theta0, x[(x > curve.theta0 + 1e-12) & (x < end - 1e-12)], end]
    return x, np.asarray(spl(x), dtype=float), np.asarray(spl(x, 1), dtype=float)


def simulate(train: SeederTrain, samples: int = 3600, dense: int = 16384) -> ForwardResult:
    """Tip path at ``samples`` uniform carrier angles over one turn: the population
    forward model (``seeder_batch.simulate_curves``, one fused kernel) for P = 1 with
    every per-sample array kept.

    Angles of gears 2-3 and of the planet are exact integrals of the instantaneous
    ratios (the running integral of the cubic spline through ``dense`` samples per turn,
    then Newton on the carrier -> gear-2 inversion). A curve with a break (the inverse
    design's gears with a dwell: their radii jump at the lock point, where the toothless
    sector starts) is integrated from the break: the kernel's turn starts at the lock
    (contact angles moved there, carrier samples taken in meshing order from the dwell
    start) and the planet's turn is referred back to psi = 0.
    """
    from plantmech.mechanisms.seeder_batch import meshing_angle, simulate_curves

    theta1 = train.dwell_theta1 if train.dwell_start is not None else 0.0
    psi = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    if theta1 > 0:
        start = float(train.dwell_start)
        if start < 0 or start + theta1 > TWO_PI:
            raise ValueError("the dwell must lie inside one carrier turn from the start")
    target, in_dwell = meshing_angle(psi, train.dwell_start, theta1)
    form2, form3 = ([v[None] if k else v for k, v in enumerate(hermite_form(g))]
                    for g in (train.gear2, train.gear3))
    c2, c3 = train.gear2_contact0, train.gear3_contact0
    breaks = [float(np.mod(g.theta0 - c, TWO_PI)) for g, c in
              ((train.gear2, c2), (train.gear3, c3)) if not g.periodic]
    tb = 0.0
    if breaks:
        if theta1 <= 0:
            raise ValueError("a pitch curve with a break (an open curve) needs the toothless "
                             "dwell that starts at it")
        tb = breaks[0]
        if any(min(abs(b - tb), TWO_PI - abs(b - tb)) > 1e-9 for b in breaks):
            raise ValueError("gears 2 and 3 break at different turns of their shaft "
                             f"({np.degrees(breaks[0]):.6f} and {np.degrees(breaks[1]):.6f} "
                             "deg from the contact at psi = 0)")
        if min(tb, TWO_PI - tb) < 1e-12:
            tb = 0.0
    common = (train.L1, train.L2, train.a1, train.a2, train.carrier0, train.arm0)
    if tb == 0.0:
        m = simulate_curves(form2, form3, *common, c2, c3, psi, dense, train.dwell_start,
                            theta1, target=target, in_dwell=in_dwell, rescale=False)
        gear2, arm, tip = m.gear2_angle[0], m.arm_angle[0], m.tip[0]
    else:
        # the turn from the break (the lock, reached at the dwell start): meshing angles
        # from there, and two extra samples at psi = 0 for the planet's turn from the break
        # to the contact at psi = 0 (meshing angle span - dwell start) and over the turn
        span = TWO_PI - theta1
        start = float(train.dwell_start)
        after = psi >= start
        rot = np.r_[np.where(after, target - start, target - start + span), span - start, span]
        order = np.argsort(rot, kind="stable")
        psi_all = np.r_[psi, 0.0, 0.0]
        dwell_all = np.r_[in_dwell, False, False]
        m = simulate_curves(form2, form3, *common, c2 + tb, c3 + tb, psi_all[order], dense,
                            train.dwell_start, theta1, target=rot[order],
                            in_dwell=dwell_all[order], rescale=False)
        back = np.empty_like(order)
        back[order] = np.arange(order.size)
        turn = m.gear2_angle[0][back]
        arm_k = m.arm_angle[0][back]
        to_contact = arm_k[samples] - train.arm0  # planet turn from the break to psi = 0
        total = arm_k[samples + 1] - train.arm0  # planet turn over the whole turn
        gear2 = turn[:samples] + np.where(after, tb, tb - TWO_PI)
        arm = arm_k[:samples] - to_contact + np.where(after, total, 0.0)
        tip = tip_position(train.L1, train.L2, train.carrier0 - psi, arm)
    planet_rel = arm - (train.carrier0 - psi) - (train.arm0 - train.carrier0)
    closure = {"stage1": float(m.closure_error[0, 0]), "stage2": float(m.closure_error[0, 1])}
    # the stage ratios from the pitch curves at the solved angles (the kernel's ratio
    # interpolates the dense samples: the same to O(h^4), but the curves are at hand)
    r2s = train.gear2(train.gear2_contact0 + gear2)
    r3s = train.gear3(train.gear3_contact0 + gear2)
    stage1 = np.where(in_dwell, 0.0, (train.a1 - r2s) / r2s)
    stage2 = r3s / (train.a2 - r3s)
    ratio = stage1 * stage2
    rate = tip_rate(train.L1, train.L2, train.carrier0 - psi, arm, ratio)
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
    contact0 + psi_2(dwell_start), where the rolling of the sun (integral of r2 / r1, the
    forward model's inversion at the meshing angle dwell_start, ``simulate_curves``)
    reaches dwell_start. The sun's rolling arc starts and ends there, and its toothless
    (locking) arc lies between its ends. Without a dwell: the curve's ``theta0``; for the
    inverse design's gear 2 with a break (its radius steps at the lock point, where the
    dwell starts: ``simulate`` integrates from it) the break, ``theta0``. Returned within
    [theta0, theta0 + 2 pi)."""
    from plantmech.mechanisms.seeder_batch import simulate_curves

    theta0 = float(train.gear2.theta0)
    if train.dwell_start is None or train.dwell_theta1 <= 0 or not train.gear2.periodic:
        return theta0
    target = np.array([float(train.dwell_start)])
    forms = [[v[None] if k else v for k, v in enumerate(hermite_form(g))]
             for g in (train.gear2, train.gear3)]
    m = simulate_curves(*forms, train.L1, train.L2, train.a1, train.a2, train.carrier0,
                        train.arm0, train.gear2_contact0, train.gear3_contact0, target, dense,
                        train.dwell_start, train.dwell_theta1, target=target,
                        in_dwell=np.zeros(1, dtype=bool), rescale=False)
    g = float(m.gear2_angle[0, 0])
    return theta0 + float(np.mod(train.gear2_contact0 + g - theta0, TWO_PI))
