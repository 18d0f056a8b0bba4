"""The general non-circular planetary train and its forward kinematics, population-first.

A train is a carrier turning about O, a first gear (the sun) on O, fixed or driven, and a
chain of gear pairs carried by the carrier; the last follower (the planet) carries the
arm. Every array has the designs first: (P, J, S) = designs x arms x carrier samples; a
single design is P = 1.

Frames and angles (radians inside, docs/architecture.md "Train model"):

- absolute frame: origin O, x right, y up, angles counter-clockwise from +x;
- carrier angle psi: the carrier's turn from the start, counter-clockwise when
  ``carrier_sense`` s = +1, clockwise (both papers) when s = -1; the carrier line of arm
  j lies at C_j(psi) = C0 + s (psi + 2 pi j / J), so arm j at psi is arm 0 at
  psi + 2 pi j / J when the sun is fixed (the arms at a phase offset);
- carrier frame: x along the carrier line; shaft 0 (the sun) at 0, shaft k + 1 at
  c_k + a_k exp(i delta_k) (``direction``, the line of centres of pair k);
- gear body angle alpha: the gear's frame relative to the carrier frame (CCW). A pair's
  contact lies at driver body angle theta_d = eps_d - alpha_d and follower body angle
  theta_f = sense F(theta_d) = eps_f - alpha_f (``trains.pairs``);
- the sun turns omega_sun = k omega_carrier absolutely (``sun_speed_ratio`` k, 0 =
  fixed), so relative to the carrier alpha_0 = alpha_0(0) + (k - 1) s psi;
- an idler's next pair is driven by the same gear (``driver`` None); a compound shaft's
  by another gear fixed to it at ``phase`` (its frame = the shaft's frame turned by
  phase); the sun's ``phase`` is its absolute orientation at the start;
- a pair may instead give its follower's pitch curve (``follower``, seed 000: gear 2 given,
  the sun derived): the law is then rolled on the follower, the driver is its mate (the sun,
  or a new gear on the previous follower's shaft), and ``phase`` is the follower's body
  angle at the contact at the start (it sets the derived driver's orientation).

The planet's absolute angle is C + alpha_planet; the arm (length L, mm) leaves the
planet's axis at the arm angle beta = planet angle + (beta0 - planet angle of arm 0 at
psi = 0), beta0 = ``arm_angle`` (rad, absolute at the start). Tip = centre + L e^{i beta};
its rate d tip / d psi and the attitude rate d beta / d psi come from the exact
instantaneous ratios (no finite differences).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from plantmech.trains.curves import TWO_PI, Curve, _column
from plantmech.trains.pairs import PairError, PairLaw, pair_law


@dataclass
class PairSpec:
    """One pair of the chain. ``driver`` None: the previous pair's follower drives (an
    idler); else the driver's pitch curve (the sun for the first pair, a gear on the
    previous follower's shaft for the others) with its ``phase`` (rad, scalar or (P,)).
    ``centre_distance`` (mm) None: solved for closure. ``direction`` (rad): line of
    centres driver -> follower in the carrier frame. ``follower_turns``: q, the
    follower's turns per driver turn. ``follower`` (instead of ``driver``): the
    follower's pitch curve is given and the driver derived; ``phase`` is then the
    follower's body angle (rad) at the contact at the start."""

    kind: str = "external"
    driver: Curve | None = None
    phase: float | np.ndarray = 0.0
    follower: Curve | None = None
    centre_distance: float | np.ndarray | None = None
    direction: float | np.ndarray = 0.0
    follower_turns: float = 1.0
    name: str = "pair"


@dataclass
class Train:
    """P trains sharing their structure (pair kinds, idlers, turns); every number may be
    per design. ``carrier0`` (rad): absolute angle of arm 0's carrier line at the start;
    ``carrier_sense`` +1 CCW / -1 CW; ``sun_speed_ratio`` k; ``arm_length`` L (mm);
    ``arm_angle`` beta0 (rad)."""

    pairs: list[PairSpec]
    carrier0: float | np.ndarray = 0.0
    carrier_sense: int = -1
    sun_speed_ratio: float = 0.0
    arm_length: float | np.ndarray = 100.0
    arm_angle: float | np.ndarray = 0.0
    arms: int = 1
    min_radius: float = 0.0
    closure_tolerance: float = np.radians(0.01)


@dataclass
class BuiltTrain:
    """The pairs' laws and the gear curves of P trains (``build``)."""

    train: Train
    laws: list[PairLaw]
    drivers: list[Curve]  # driver curve of each pair, in its own frame
    known_followers: list[Curve | None]  # follower curves computed so far (None: not yet)
    shafts: np.ndarray  # (P, K + 1) complex shaft positions in the carrier frame (mm)
    designs: int

    @property
    def centre_distances(self) -> np.ndarray:
        return np.stack([law.a for law in self.laws], axis=1)  # (P, K)

    @property
    def followers(self) -> list[Curve]:
        """Every pair's follower curve; a mate no later pair needs is derived here, on first
        use (the motion does not need it: populations skip its inversion)."""
        for k, law in enumerate(self.laws):
            if self.known_followers[k] is None:
                self.known_followers[k] = law.mate(f"{self.train.pairs[k].name} follower")
        return self.known_followers


@dataclass
class TrainMotion:
    """Motion of P designs x J arms at S carrier angles (complex positions, mm; angles
    rad, absolute, CCW)."""

    carrier_angle: np.ndarray  # (S,) psi
    carrier: np.ndarray  # (P|1, J, S) absolute carrier-line angle
    gear_angles: list[np.ndarray]  # per shaft (P, J, S): alpha relative to the carrier
    gear_rates: list[np.ndarray]  # d alpha / d psi
    driver_angles: list[np.ndarray]  # per pair (P, J, S): alpha of its driver gear
    contact_radii: list[tuple[np.ndarray, np.ndarray]]  # per pair (r_driver, r_follower)
    centre: np.ndarray  # (P, J, S) planet axis
    tip: np.ndarray  # (P, J, S)
    arm_angle: np.ndarray  # (P, J, S) beta (attitude), unwrapped
    arm_rate: np.ndarray  # d beta / d psi
    tip_rate: np.ndarray  # d tip / d psi (mm/rad)
    built: BuiltTrain = field(repr=False, default=None)

    def velocity(self, carrier_speed_deg_s: float) -> np.ndarray:
        """Tip velocity (complex, m/s) at the carrier speed (deg/s, in the carrier's
        sense of turning)."""
        return self.tip_rate * np.radians(carrier_speed_deg_s) / 1000.0


#: the kind of a pair seen from its follower (the law rolled on a given follower)
SWAPPED = {"external": "external", "internal": "internal_ring_follower",
           "internal_ring_follower": "internal"}


def _per_design(curve: Curve, P: int) -> Curve:
    if curve.designs == P:
        return curve
    n = curve.r.shape[1]
    return Curve(np.broadcast_to(curve.r, (P, n)).copy(),
                 np.broadcast_to(curve.dr, (P, n)).copy(), curve.name)


def build(train: Train, designs: int | None = None) -> BuiltTrain:
    """Every pair's law (closure, centre distance) and every gear's pitch curve. A pair
    with a given follower has its law rolled on the follower (``given_follower``)."""
    if not train.pairs:
        raise ValueError("a train needs at least one gear pair")
    for k, spec in enumerate(train.pairs):
        if spec.driver is not None and spec.follower is not None:
            raise ValueError(f"{spec.name}: give the driver's or the follower's pitch curve, "
                             "not both (the other follows from rolling)")
        if k == 0 and spec.driver is None and spec.follower is None:
            raise ValueError(f"{spec.name}: the first pair's driver is the sun; give its "
                             "pitch curve (or the follower's)")
    for spec in train.pairs:
        q = spec.follower_turns
        if spec.kind == "internal" and not q > 1:
            raise PairError(f"{spec.name}: an internal pair whose driver is the ring turns "
                            f"the follower faster than the ring: follower_turns > 1 (got {q:g})")
        if spec.kind == "internal_ring_follower" and not q < 1:
            raise PairError(f"{spec.name}: a ring follower turns slower than its driver: "
                            f"follower_turns < 1 (got {q:g})")
    P = designs or max(c.designs for p in train.pairs for c in (p.driver, p.follower)
                       if c is not None)
    laws, drivers, followers = [], [], []
    shafts = [np.zeros(P, dtype=complex)]
    previous: Curve | None = None
    for k, spec in enumerate(train.pairs):
        if spec.follower is not None:
            given = _per_design(spec.follower, P)
            law = pair_law(SWAPPED[spec.kind], given, 1.0 / spec.follower_turns,
                           spec.centre_distance, tolerance=train.closure_tolerance,
                           min_radius=train.min_radius,
                           name=f"{spec.name} (rolled on its given follower, which is the "
                           "'driver' of this message)")
            driver, follower = law.mate(f"{spec.name} driver"), given
        else:
            driver = previous if spec.driver is None else _per_design(spec.driver, P)
            law = pair_law(spec.kind, driver, spec.follower_turns, spec.centre_distance,
                           tolerance=train.closure_tolerance, min_radius=train.min_radius,
                           name=spec.name)
            idler_next = k + 1 < len(train.pairs) and (
                train.pairs[k + 1].driver is None and train.pairs[k + 1].follower is None)
            follower = law.mate(f"{spec.name} follower") if idler_next else None
        laws.append(law)
        drivers.append(driver)
        followers.append(follower)
        delta = np.broadcast_to(np.asarray(spec.direction, dtype=float), (P,))
        shafts.append(shafts[-1] + law.a * np.exp(1j * delta))
        previous = follower
    return BuiltTrain(train, laws, drivers, followers, np.stack(shafts, axis=1), P)


def _derived_driver_angle(spec: PairSpec, law: PairLaw, P: int) -> np.ndarray:
    """Body angle alpha (P, 1, 1) of a derived driver (the mate of a given follower) at
    the start of arm 0: the follower touches it at body angle ``phase``."""
    delta = _column(spec.direction, P)[:, :, None]
    contact = np.broadcast_to(_column(spec.phase, P), (P, 1))
    F, _ = law.F(contact)
    kind = _KIND_OFFSETS[spec.kind]
    return (delta + kind[0] - law.sense * F[:, :, None]).reshape(P, 1, 1)


#: contact direction offsets from delta (driver, follower) of each physical kind
_KIND_OFFSETS = {"external": (0.0, np.pi), "internal": (0.0, 0.0),
                 "internal_ring_follower": (np.pi, np.pi)}


def simulate(built: BuiltTrain, samples: int = 3600) -> TrainMotion:
    """Forward kinematics of P built trains over one carrier turn (``samples`` psi)."""
    tr = built.train
    P, J = built.designs, tr.arms
    s = float(tr.carrier_sense)
    psi = TWO_PI * np.arange(samples) / samples
    offset = TWO_PI * np.arange(J) / J
    turn = (psi[None, :] + offset[:, None])[None]  # (1, J, S)
    C0 = _column(tr.carrier0, P)[:, :, None]  # (P|1, 1, 1)
    carrier = C0 + s * turn
    k = float(tr.sun_speed_ratio)
    first = tr.pairs[0]
    if first.follower is not None:  # the sun is derived: its start from the contact
        alpha_start = _derived_driver_angle(first, built.laws[0], P)
    else:  # the sun's absolute orientation at the start
        alpha_start = _column(first.phase, P)[:, :, None] - C0
    # sun relative to arm j's carrier line: alpha_0 = alpha_0(0) + (k - 1) s psi - s offset_j
    alpha = np.broadcast_to(alpha_start + (k - 1) * s * psi[None, None, :]
                            - s * offset[None, :, None], (P, J, samples))
    rate = np.full((P, J, samples), (k - 1) * s)
    angles, rates, contacts, driver_angles = [alpha], [rate], [], []
    for i, (spec, law) in enumerate(zip(tr.pairs, built.laws, strict=True)):
        if i > 0 and spec.driver is not None:  # compound: a second gear on the shaft
            alpha = alpha + _column(spec.phase, P)[:, :, None]
        elif i > 0 and spec.follower is not None:  # a derived gear on the shaft
            alpha = alpha + (_derived_driver_angle(spec, law, P) - alpha[:, :1, :1])
        driver_angles.append(alpha)
        delta = _column(spec.direction, P)[:, :, None]
        eps_d, eps_f = _KIND_OFFSETS[spec.kind]
        theta_d = (delta + eps_d - alpha).reshape(P, -1)
        if spec.follower is None:
            F, g = law.F(theta_d)
            r_d = law.driver(theta_d)[0]
            r_f = law.follower_radius(r_d)
            theta_f = law.sense * F
            rate = law.sense * g.reshape(P, J, samples) * rate
        else:  # the law rolls on the follower: theta_d = sense F(theta_f)
            theta_f = law.invert(law.sense * theta_d)
            F, g = law.F(theta_f)
            r_f = law.driver(theta_f)[0]
            r_d = law.follower_radius(r_f)
            rate = law.sense * rate / g.reshape(P, J, samples)
        contacts.append((r_d.reshape(P, J, samples), r_f.reshape(P, J, samples)))
        alpha = delta + eps_f - theta_f.reshape(P, J, samples)
        angles.append(alpha)
        rates.append(rate)
    centre = built.shafts[:, -1, None, None] * np.exp(1j * carrier)
    planet = carrier + alpha
    beta0 = _column(tr.arm_angle, P)[:, :, None]
    beta = planet + (beta0 - planet[:, :1, :1])
    L = _column(tr.arm_length, P)[:, :, None]
    tip = centre + L * np.exp(1j * beta)
    beta_rate = s + rate
    tip_rate = 1j * s * centre + 1j * L * beta_rate * np.exp(1j * beta)
    return TrainMotion(psi, np.broadcast_to(carrier, (P, J, samples)), angles, rates,
                       driver_angles, contacts, centre, tip, beta, beta_rate, tip_rate, built)


def forward(train: Train, samples: int = 3600) -> TrainMotion:
    """``simulate(build(train))``: P designs' motion from their train description."""
    return simulate(build(train), samples)


__all__ = ["PairSpec", "Train", "BuiltTrain", "TrainMotion", "build", "simulate", "forward"]
