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

A pair may carry a toothless dwell (``PairSpec.dwell``, seed 000's sector over cd, Eq. 5):
from carrier angle psi_s for a sector theta_1 of carrier turn its follower (and everything
after it) does not turn relative to the carrier while the driver's toothless arc passes;
after it the pair rolls on theta_1 behind the carrier. Supported where it is the seeder's:
the first pair, a fixed sun (it turns exactly theta_1 relative to the carrier through the
dwell) and a given follower (gear 2; the sun is derived: its rolling arc is the mate of one
follower turn, 360 - theta_1 deg, and its toothless arc the rest). ``mesh`` maps a driver's
body angle to its follower's through the law (and the toothless arc): ``simulate`` and the
tooth-contact loads (``contact.planetary``) call it.

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
from plantmech.trains.pairs import _KIND, PairError, PairLaw, pair_law


@dataclass
class PairSpec:
    """One pair of the chain. ``driver`` None: the previous pair's follower drives (an
    idler); else the driver's pitch curve (the sun for the first pair, a gear on the
    previous follower's shaft for the others) with its ``phase`` (rad, scalar or (P,)).
    ``centre_distance`` (mm) None: solved for closure. ``direction`` (rad): line of
    centres driver -> follower in the carrier frame. ``follower_turns``: q, the
    follower's turns per driver turn. ``follower`` (instead of ``driver``): the
    follower's pitch curve is given and the driver derived; ``phase`` is then the
    follower's body angle (rad) at the contact at the start. ``dwell``: (psi_s, theta_1)
    (rad, scalars or (P,)): the carrier angle where the toothless dwell starts and the
    carrier turn it spans (seed 000's theta_1; module docstring)."""

    kind: str = "external"
    driver: Curve | None = None
    phase: float | np.ndarray = 0.0
    follower: Curve | None = None
    centre_distance: float | np.ndarray | None = None
    direction: float | np.ndarray = 0.0
    follower_turns: float = 1.0
    name: str = "pair"
    dwell: tuple | None = None  # (psi_s, theta_1) rad, scalars or (P,): the toothless dwell


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
    #: the carrier is the frame (a pair, or any chain, on fixed centres): psi is then the
    #: sun's (the first driver's) turn, in the sense ``carrier_sense``; one arm
    carrier_held: bool = False

    @property
    def carrier_rate(self) -> float:
        """d C / d psi: the carrier's absolute turn per unit psi (0 when held)."""
        return 0.0 if self.carrier_held else float(self.carrier_sense)

    @property
    def sun_rate(self) -> float:
        """d alpha_0 / d psi: the sun's turn relative to the carrier per unit psi ((k - 1) s;
        s when the carrier is held and the sun drives)."""
        s = float(self.carrier_sense)
        return s if self.carrier_held else (float(self.sun_speed_ratio) - 1) * s


@dataclass
class Toothless:
    """A pair's toothless dwell in its driver's terms: the driver's body angle ``lock``
    (rad, (P, 1, 1), relative to arm 0's carrier line) where the follower locks, the
    driver's turn ``width`` (rad, (P, 1, 1)) while its toothless arc passes (theta_1 for a
    fixed sun) and ``sense`` (+1 / -1): the driver's direction of turn relative to the
    carrier. The dwell is a region of the driver's body, so every arm meets it."""

    lock: np.ndarray
    width: np.ndarray
    sense: float

    def meshing(self, alpha: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(alpha_m, meshes) at driver body angles ``alpha`` (rad, (P, ...)): the angle the
        pair has rolled through (the toothless arcs passed squeezed out: alpha_m is held at
        the lock over the arc and ``width`` behind alpha after it, in every turn; before
        the first lock alpha_m = alpha) and whether the teeth mesh there (False on the
        toothless arc, seed 000's in_dwell)."""
        lock = self.lock.reshape((-1,) + (1,) * (np.ndim(alpha) - 1))
        width = self.width.reshape(lock.shape)
        t = self.sense * (alpha - lock)  # the driver's travel from the lock
        turns = np.floor(t / TWO_PI)
        v = t - TWO_PI * turns  # [0, 2 pi): the toothless arc is [0, width)
        meshes = v >= width
        rolled = turns * (TWO_PI - width) + np.where(meshes, v - width, 0.0)
        return lock + self.sense * rolled, meshes


@dataclass
class BuiltTrain:
    """The pairs' laws and the gear curves of P trains (``build``). A pair's driver
    curve is its body as it turns: a derived sun with a toothless dwell is its rolling arc
    (the mate of one follower turn) and, over its toothless arc, the circular arc at the
    lock radius (``toothless[k]`` says where)."""

    train: Train
    laws: list[PairLaw]
    known_drivers: list[Curve | None]  # driver curves computed so far (None: not yet)
    known_followers: list[Curve | None]  # follower curves computed so far (None: not yet)
    shafts: np.ndarray  # (P, K + 1) complex shaft positions in the carrier frame (mm)
    designs: int
    toothless: list[Toothless | None] = field(default_factory=list)  # per pair
    #: per pair, how to derive a driver not yet known (the mate of a given follower, or a
    #: derived sun with its toothless arc), None where the driver is given
    derive_driver: list = field(default_factory=list, repr=False)

    @property
    def centre_distances(self) -> np.ndarray:
        return np.stack([law.a for law in self.laws], axis=1)  # (P, K)

    @property
    def drivers(self) -> list[Curve]:
        """Every pair's driver curve in its own frame; a derived driver (the mate of a
        given follower: seed 000's sun, with its toothless arc) is derived here, on first
        use: the motion and the objectives read the law only, so a population skips the
        full-grid inversion (``PairLaw.invert``) the drawn gear needs."""
        for k, make in enumerate(self.derive_driver):
            if self.known_drivers[k] is None and make is not None:
                self.known_drivers[k] = make()
        return self.known_drivers

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
    #: per pair (P, J, S) bool: where its teeth mesh (False on a toothless dwell, where its
    #: follower is held and the contact radii are the lock's), None without a dwell
    meshes: list = field(default_factory=list)

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
    ends = () if not curve.open else (np.broadcast_to(curve.r_end, (P,)).copy(),
                                      np.broadcast_to(curve.dr_end, (P,)).copy())
    return Curve(np.broadcast_to(curve.r, (P, n)).copy(),
                 np.broadcast_to(curve.dr, (P, n)).copy(), curve.name, *ends)


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
    dwells = [_dwell_of(train, k, spec, P) for k, spec in enumerate(train.pairs)]
    laws, drivers, followers, toothless, derive = [], [], [], [], []
    shafts = [np.zeros(P, dtype=complex)]
    previous: Curve | None = None
    for k, spec in enumerate(train.pairs):
        gap = None
        if spec.follower is not None:
            given = _per_design(spec.follower, P)
            turns = 1.0 / spec.follower_turns
            if dwells[k] is not None:  # the sun rolls 360 - theta_1 deg per follower turn
                turns = (1.0 - dwells[k][1] / TWO_PI) / spec.follower_turns
            law = pair_law(SWAPPED[spec.kind], given, turns,
                           spec.centre_distance, tolerance=train.closure_tolerance,
                           min_radius=train.min_radius,
                           name=f"{spec.name} (rolled on its given follower, which is the "
                           "'driver' of this message"
                           + (", its driver rolling 360 deg less the dwell's sector)"
                              if dwells[k] is not None else ")"),
                           periodic_mate=dwells[k] is None)
            if dwells[k] is None:
                make = _mate_maker(law, f"{spec.name} driver")
            else:
                start, sector = dwells[k]
                lock = _derived_driver_angle(spec, law, P) - float(train.carrier_sense) * \
                    start[:, None, None]
                gap = Toothless(lock, sector[:, None, None], -float(train.carrier_sense))
                make = _toothless_maker(law, spec, gap, P)
            driver = None  # derived on first use (BuiltTrain.drivers)
            follower = given
        else:
            make = None
            driver = previous if spec.driver is None else _per_design(spec.driver, P)
            law = pair_law(spec.kind, driver, spec.follower_turns, spec.centre_distance,
                           tolerance=train.closure_tolerance, min_radius=train.min_radius,
                           name=spec.name)
            idler_next = k + 1 < len(train.pairs) and (
                train.pairs[k + 1].driver is None and train.pairs[k + 1].follower is None)
            follower = law.mate(f"{spec.name} follower") if idler_next else None
        laws.append(law)
        drivers.append(driver)
        derive.append(make)
        followers.append(follower)
        toothless.append(gap)
        delta = np.broadcast_to(np.asarray(spec.direction, dtype=float), (P,))
        shafts.append(shafts[-1] + law.a * np.exp(1j * delta))
        previous = follower
    return BuiltTrain(train, laws, drivers, followers, np.stack(shafts, axis=1), P, toothless,
                      derive)


def _mate_maker(law: PairLaw, name: str):
    return lambda: law.mate(name)


def _toothless_maker(law: PairLaw, spec: PairSpec, gap: Toothless, P: int):
    return lambda: _toothless_driver(law, spec, gap, P)


def _dwell_of(train: Train, k: int, spec: PairSpec, P: int):
    """(psi_s, theta_1) (P,) rad of pair k's toothless dwell, or None; PairError naming
    the pair where the dwell is not the seeder's (module docstring) or does not fit in one
    carrier turn."""
    if spec.dwell is None:
        return None
    where = f"{spec.name}.dwell"
    if train.carrier_held:
        raise PairError(f"{where}: a toothless dwell is the carrier's sector; this train's "
                        "carrier is held (a pair on fixed centres)")
    if k > 0:
        raise PairError(f"{where}: a toothless dwell is supported on the first pair (the "
                        "sun's) only: a later driver does not turn uniformly relative to the "
                        "carrier, so its toothless arc would not be the carrier's sector")
    if float(train.sun_speed_ratio) != 0.0:
        raise PairError(f"{where}: a toothless dwell needs a fixed sun (sun_speed_ratio = 0; "
                        f"got {float(train.sun_speed_ratio):g}): a turning sun would bring its "
                        "toothless arc round at another carrier angle every turn")
    if spec.follower is None:
        raise PairError(f"{where}: give the follower's pitch curve (the pair's 'follower' "
                        "table, seed 000's gear 2) instead of the sun's: the sun is then "
                        "derived, its rolling arc the mate of one follower turn and its "
                        "toothless arc the rest")
    start, sector = (np.broadcast_to(np.asarray(v, dtype=float), (P,)).astype(float)
                     for v in spec.dwell)
    bad = ~((sector > 0) & (sector < TWO_PI) & (start >= 0) & (start + sector <= TWO_PI)
            & np.isfinite(start) & np.isfinite(sector))
    if bad.any():
        d = int(np.argmax(bad))
        raise PairError(f"{where}: the dwell from carrier angle {np.degrees(start[d]):.6g} "
                        f"deg over a sector of {np.degrees(sector[d]):.6g} deg does not lie "
                        "inside one carrier turn (0 <= start, 0 < sector, start + sector <= "
                        "360 deg)" + (f" (design {d})" if P > 1 else ""))
    return start, sector


def _toothless_driver(law: PairLaw, spec: PairSpec, gap: Toothless, P: int) -> Curve:
    """The derived driver (the sun) of a pair with a toothless dwell, on the given
    follower's grid of body angles (its frame: the law's, theta_d = sense F(theta_f)):
    from the lock, the toothless arc (the driver turns ``gap.width`` while the follower
    is held), drawn as the circular arc at the lock radius, then the rolling arc, the mate
    of one follower turn (r = kappa r_f + c a at theta_f = F^-1(sense theta_m))."""
    n = law.g.shape[1]
    theta = TWO_PI * np.arange(n) / n
    delta = _column(spec.direction, P)
    eps_d = _KIND_OFFSETS[spec.kind][0]
    theta_lock = delta + eps_d - gap.lock[:, :, 0]  # (P, 1) body angle at the lock
    travel = np.mod(-gap.sense * (theta[None, :] - theta_lock), TWO_PI)  # past the lock
    rolling = travel >= gap.width[:, :, 0]
    theta_m = theta_lock - gap.sense * np.where(rolling, travel - gap.width[:, :, 0], 0.0)
    theta_f = law.invert(np.broadcast_to(law.sense * theta_m, (P, n)))
    r_f, dr_f = law.driver(theta_f)
    g = r_f / law.follower_radius(r_f)
    _, kappa, _, _, _ = _KIND[law.kind]
    return Curve(law.follower_radius(r_f), np.where(rolling, kappa * dr_f / (law.sense * g),
                                                    0.0), f"{spec.name} driver")


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


@dataclass
class PairMesh:
    """A pair's follower at its driver's body angles (``mesh``): body angle alpha_f and its
    rate d alpha_f / d psi (rad, rad/rad; None when no driver rate was given), the pitch
    radii at the contact (mm; on a toothless arc those where the follower locked), and
    where the teeth mesh (None without a toothless dwell)."""

    follower_angle: np.ndarray
    follower_rate: np.ndarray | None
    driver_radius: np.ndarray
    follower_radius: np.ndarray
    meshes: np.ndarray | None = None


def mesh(law: PairLaw, spec: PairSpec, driver_angle: np.ndarray, driver_rate=None,
         toothless: Toothless | None = None) -> PairMesh:
    """The follower of pair ``spec`` (its ``law``) at driver body angles alpha_d
    (``driver_angle``, rad relative to the carrier line, shape (P|1, ...)): the contact at
    driver body angle theta_d = delta + eps_d - alpha_d lies at follower body angle
    theta_f = sense F(theta_d) (a given follower: theta_d = sense F(theta_f), inverted), so
    alpha_f = delta + eps_f - theta_f, and d alpha_f / d psi = sense g d alpha_d / d psi
    (a given follower: sense / g) from ``driver_rate`` (d alpha_d / d psi, same shape).
    ``toothless``: the pair's dwell; the law then reads the driver's meshing angle
    (``Toothless.meshing``) and the follower's rate is 0 on the toothless arc. The one
    pair mapping of the model: ``simulate`` and ``contact.planetary`` call it."""
    P = law.a.shape[0]
    alpha = np.asarray(driver_angle, dtype=float)
    shape = (max(P, alpha.shape[0]),) + alpha.shape[1:]
    meshes = None
    if toothless is not None:
        alpha, meshes = toothless.meshing(alpha)
        if driver_rate is not None:
            driver_rate = np.where(meshes, driver_rate, 0.0)
    delta = _column(spec.direction, P).reshape((-1,) + (1,) * (alpha.ndim - 1))
    eps_d, eps_f = _KIND_OFFSETS[spec.kind]
    theta_d = (delta + eps_d - alpha).reshape(P, -1)
    rate = None
    if spec.follower is None:
        F, g = law.F(theta_d)
        r_d = law.driver(theta_d)[0]
        r_f = law.follower_radius(r_d)
        theta_f = law.sense * F
        if driver_rate is not None:
            rate = law.sense * g.reshape(shape) * driver_rate
    else:  # the law rolls on the follower: theta_d = sense F(theta_f)
        theta_f = law.invert(law.sense * theta_d)
        F, g = law.F(theta_f)
        r_f = law.driver(theta_f)[0]
        r_d = law.follower_radius(r_f)
        if driver_rate is not None:
            rate = law.sense * driver_rate / g.reshape(shape)
    return PairMesh(delta + eps_f - theta_f.reshape(shape), rate, r_d.reshape(shape),
                    r_f.reshape(shape), meshes)


def simulate(built: BuiltTrain, samples: int = 3600) -> TrainMotion:
    """Forward kinematics of P built trains over one carrier turn (``samples`` psi)."""
    tr = built.train
    P, J = built.designs, tr.arms
    s = tr.carrier_rate  # 0 when the carrier is held (psi is then the sun's turn)
    psi = TWO_PI * np.arange(samples) / samples
    offset = TWO_PI * np.arange(J) / J
    turn = (psi[None, :] + offset[:, None])[None]  # (1, J, S)
    C0 = _column(tr.carrier0, P)[:, :, None]  # (P|1, 1, 1)
    carrier = C0 + s * turn
    # sun relative to arm j's carrier line: alpha_0 = alpha_0(0) + (k - 1) s psi - s offset_j
    alpha = np.broadcast_to(_sun_start(built) + tr.sun_rate * psi[None, None, :]
                            - s * offset[None, :, None], (P, J, samples))
    rate = np.full((P, J, samples), tr.sun_rate)
    angles, rates, contacts, driver_angles, meshes = [alpha], [rate], [], [], []
    for driver_alpha, m in _pair_chain(built, alpha, rate):
        driver_angles.append(driver_alpha)
        contacts.append((m.driver_radius, m.follower_radius))
        meshes.append(m.meshes)
        alpha, rate = m.follower_angle, m.follower_rate
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
                       driver_angles, contacts, centre, tip, beta, beta_rate, tip_rate, built,
                       meshes)


def simulate_tips(built: BuiltTrain, samples: int = 3600) -> TrainMotion | None:
    """``simulate``'s tip motion (carrier, planet centre, tip, its rate, the arm angle and
    its rate; no per-gear tables: ``gear_angles``, ``contact_radii`` ... empty) of a
    population in one fused pass per design (``trains.fused.chain_tips``), for what reads
    the tips only (``objectives.planetary.population_evaluation``); None where the pass
    does not apply (an open curve's law, pairs on different grids, fewer than
    ``curves.KERNEL_POINTS`` grid points): ``simulate`` then. The same tips to 1e-9 mm
    (tests/test_trains_fused.py)."""
    from plantmech.trains.curves import use_kernels

    tr, P, J = built.train, built.designs, built.train.arms
    laws = built.laws
    N = laws[0].g.shape[1]
    if not use_kernels(P * N) or any(law.g_end is not None or law.g.shape[1] != N
                                     for law in laws):
        return None
    from plantmech.trains.fused import chain_tips

    K = len(laws)
    stack = [tuple(np.ascontiguousarray(getattr(law, t), dtype=float) for law in laws)
             for t in ("Fp", "g", "dg")]
    q_e = np.ascontiguousarray(np.stack([law.q_e for law in laws]))
    delta = np.stack([np.broadcast_to(_column(sp.direction, P)[:, 0], (P,)) for sp in tr.pairs])
    given = np.array([sp.follower is not None for sp in tr.pairs])
    derived = np.array([i > 0 and sp.follower is not None for i, sp in enumerate(tr.pairs)])
    shift = np.zeros((K, P))
    for i, (sp, law) in enumerate(zip(tr.pairs, laws, strict=True)):
        if i > 0 and sp.follower is not None:
            shift[i] = _derived_driver_angle(sp, law, P)[:, 0, 0]
        elif i > 0 and sp.driver is not None:
            shift[i] = np.broadcast_to(_column(sp.phase, P)[:, 0], (P,))
    offsets = np.array([_KIND_OFFSETS[sp.kind] for sp in tr.pairs])
    sense = np.array([float(law.sense) for law in laws])
    gap = built.toothless[0] if built.toothless else None
    lock = np.zeros(P) if gap is None else np.broadcast_to(gap.lock.reshape(-1), (P,))
    width = np.zeros(P) if gap is None else np.broadcast_to(gap.width.reshape(-1), (P,))
    s = tr.carrier_rate

    def col(v):
        return np.ascontiguousarray(np.broadcast_to(_column(v, P)[:, 0], (P,)), dtype=float)

    tip, tip_rate, beta, beta_rate, centre = chain_tips(
        *stack, q_e, np.ascontiguousarray(delta, dtype=float), given,
        np.ascontiguousarray(offsets[:, 0]), np.ascontiguousarray(offsets[:, 1]), sense, shift,
        derived, np.ascontiguousarray(lock, dtype=float), np.ascontiguousarray(width,
                                                                             dtype=float),
        -float(tr.carrier_sense) if gap is None else float(gap.sense), gap is not None,
        col(_sun_start(built)[:, 0, 0]), tr.sun_rate, col(tr.carrier0),
        s, J, samples, np.ascontiguousarray(built.shafts[:, -1]), col(tr.arm_length),
        col(tr.arm_angle), float(tr.sun_speed_ratio) == 0.0 and J > 1 and samples % J == 0)
    psi = TWO_PI * np.arange(samples) / samples
    offset = TWO_PI * np.arange(J) / J
    carrier = _column(tr.carrier0, P)[:, :, None] + s * (psi[None, :] + offset[:, None])[None]
    return TrainMotion(psi, np.broadcast_to(carrier, (P, J, samples)), [], [], [], [], centre,
                       tip, beta, beta_rate, tip_rate, built, [])


def _sun_start(built: BuiltTrain) -> np.ndarray:
    """The sun's body angle alpha_0(0) relative to the carrier line at psi = 0 (P|1, 1, 1)
    rad: from the first contact when the sun is derived, else its absolute orientation."""
    tr, P = built.train, built.designs
    first = tr.pairs[0]
    if first.follower is not None:
        return _derived_driver_angle(first, built.laws[0], P)
    return _column(first.phase, P)[:, :, None] - _column(tr.carrier0, P)[:, :, None]


def _pair_chain(built: BuiltTrain, alpha: np.ndarray, rate):
    """Each pair in turn from the sun's body angles ``alpha`` (P, J, M) rad and their rates
    (or None): yields (the pair's driver's alpha, its ``PairMesh``). A compound driver adds
    its phase on the shaft; a derived one is phased at its contact at the first sample
    (psi = 0)."""
    tr, P = built.train, built.designs
    for i, (spec, law) in enumerate(zip(tr.pairs, built.laws, strict=True)):
        if i > 0 and spec.driver is not None:  # compound: a second gear on the shaft
            alpha = alpha + _column(spec.phase, P)[:, :, None]
        elif i > 0 and spec.follower is not None:  # a derived gear on the shaft
            alpha = alpha + (_derived_driver_angle(spec, law, P) - alpha[:, :1, :1])
        m = mesh(law, spec, alpha, rate, built.toothless[i] if built.toothless else None)
        yield alpha, m
        alpha, rate = m.follower_angle, m.follower_rate


def contact_angles(built: BuiltTrain, psi) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per pair, (theta_d, theta_f) (P, M) rad: the body angles of its driver and follower
    at their contact, arm 0, at carrier angles ``psi`` (M,) rad (``simulate``'s chain at
    the angles asked, e.g. where a dwell starts: ``trains.spec`` checks there that an open
    curve's break is held, never rolled across)."""
    tr = built.train
    P = built.designs
    # psi = 0 first: the chain phases a derived gear at its first sample, as simulate's
    psi = np.r_[0.0, np.atleast_1d(np.asarray(psi, dtype=float))][None, None, :]
    alpha = np.broadcast_to(_sun_start(built) + tr.sun_rate * psi,
                            (P, 1, psi.shape[-1]))
    out = []
    for (driver_alpha, m), spec, gap in zip(
            _pair_chain(built, alpha, None), tr.pairs,
            built.toothless or [None] * len(tr.pairs), strict=True):
        rolled = driver_alpha if gap is None else gap.meshing(driver_alpha)[0]
        eps_d, eps_f = _KIND_OFFSETS[spec.kind]
        delta = _column(spec.direction, P)[:, :, None]
        out.append(((delta + eps_d - rolled)[:, 0, 1:],
                    (delta + eps_f - m.follower_angle)[:, 0, 1:]))
    return out


def forward(train: Train, samples: int = 3600) -> TrainMotion:
    """``simulate(build(train))``: P designs' motion from their train description."""
    return simulate(build(train), samples)


__all__ = ["PairSpec", "Train", "BuiltTrain", "TrainMotion", "Toothless", "PairMesh", "mesh",
           "build", "simulate", "simulate_tips", "forward", "contact_angles"]
