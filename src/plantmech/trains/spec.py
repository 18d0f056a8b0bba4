"""A ``PlanetaryDesign`` (design file, ``mechanism = "planetary"``) as a ``Train``.

Units change here: the file's mm and degrees become mm and radians. Errors are raised as
``TrainSpecError`` naming the design-file field (``train.pairs.<k>...``).
"""

from __future__ import annotations

import numpy as np

from plantmech.trains.curves import (
    TWO_PI,
    Curve,
    CurveError,
    eccentric_circle,
    ellipse,
    fourier,
    interpolated,
)
from plantmech.trains.model import BuiltTrain, PairSpec, Train, build
from plantmech.trains.pairs import PairError


class TrainSpecError(ValueError):
    """A train in a design file that cannot be built (message names the field)."""


def curve_from_spec(spec, grid: int, name: str) -> Curve:
    """The pitch curve of a design file's ``driver`` table on ``grid`` samples per turn."""
    if spec.family == "ellipse":
        return ellipse(spec.semi_major_mm, spec.eccentricity, grid, name)
    if spec.family == "eccentric":
        return eccentric_circle(spec.radius_mm, spec.offset_mm, grid, name)
    if spec.family == "fourier":
        return fourier(spec.mean_radius_mm, spec.cos_mm or [0.0], spec.sin_mm or [0.0], grid,
                       name)
    return interpolated(np.radians(spec.angles()), spec.radii_mm, grid, spec.interpolation,
                        spec.lobes, name, open_turn=getattr(spec, "open", False))


def _law_senses(design) -> list[int]:
    """Per pair, +1 where its driver turns counter-clockwise relative to the carrier
    (the contact then runs backwards over its body angles), else -1: the sun's sense
    (held carrier: the carrier's direction; else (k - 1) s), flipped by every external
    pair before it."""
    s = -1 if design.carrier.direction == "clockwise" else 1
    k = design.train.sun_speed_ratio
    sense = s if design.carrier.held else (1 if (k - 1) * s > 0 else -1)
    out = []
    for p in design.train.pairs:
        out.append(sense)
        if p.kind == "external":
            sense = -sense
    return out


def law_curve(pair, grid: int, name: str, turning: int = -1) -> tuple[Curve, float]:
    """(the driver's pitch curve, the centre distance a mm) of a design file's pair given by
    its transmission law (``design_law``): the ratio g(t) on the grid and, at centre
    distance a, r_d = a g / (1 + g) (external; the follower's radius a / (1 + g)), a g /
    (g - 1) (internal: the ring drives, g > 1), a g / (1 - g) (a ring follower, g < 1);
    a from centre_distance_mm, or from law.module_mm and teeth (the driver's pitch
    perimeter pi m z). The law's t is the driver's turn from the start: ``turning`` +1
    (the driver turns counter-clockwise relative to the carrier, so the contact runs over
    its body angles -t) mirrors the table. TrainSpecError naming the field and the driver
    angle."""
    from plantmech.design_law import ExpressionError, LawError, sample_law

    law = pair.law
    n1, n2 = pair.turns_pair()
    try:
        g, dg = sample_law(law, grid, n1, n2, f"{name}.law")
    except (LawError, ExpressionError) as exc:
        raise TrainSpecError(str(exc)) from None
    theta = TWO_PI * np.arange(grid) / grid
    if pair.kind == "external":
        r, dr = g / (1 + g), dg / (1 + g) ** 2
    else:
        internal = pair.kind == "internal"
        bad = g <= 1 if internal else g >= 1
        if bad.any():
            i = int(np.argmax(bad))
            raise TrainSpecError(
                f"{name}.law: no centre distance can close this pair: "
                + ("a ring driving a planet inside it turns it faster (ratio above 1)"
                   if internal else "a ring follower turns slower than its driver (ratio "
                   "below 1)") + f"; at driver angle {np.degrees(theta[i]):.3f} deg the "
                f"law's ratio is {g[i]:.6g}")
        r, dr = (g / (g - 1), -dg / (g - 1) ** 2) if internal else \
            (g / (1 - g), dg / (1 - g) ** 2)
    if pair.centre_distance_mm is not None:
        a = float(pair.centre_distance_mm)
    else:  # the driver's pitch perimeter at a = 1 mm, scaled to pi m z
        per = float(np.mean(np.hypot(r, dr))) * TWO_PI
        a = np.pi * law.module_mm * pair.teeth / per
    if turning > 0:  # body angle theta = -t
        back = (-np.arange(grid)) % grid
        r, dr = r[back], -dr[back]
    return Curve((a * r)[None, :], (a * dr)[None, :], f"{name}.law"), a


def require_curves(design) -> None:
    """TrainSpecError naming the field when a planetary file gives a [trajectory] instead of
    the sun's pitch curve or the arm's start (an input of `plantmech inverse`)."""
    first = design.train.pairs[0]
    if first.driver is None and first.follower is None and first.law is None:
        raise TrainSpecError("train.pairs.0.driver': no pitch curve: this file gives a "
                             "[trajectory]; run 'plantmech inverse' on it, which writes the "
                             "train's pitch curves (design.toml)")
    if design.arm.initial_angle_deg is None or design.arm.length_mm is None:
        raise TrainSpecError("arm': its length or start angle is missing: run 'plantmech "
                             "inverse' on this [trajectory] file, which computes them "
                             "(design.toml)")


def train_from_design(design) -> Train:
    """The ``Train`` (P = 1) of a planetary design."""
    require_curves(design)
    t = design.train
    grid = t.grid
    pairs = []
    for k, p in enumerate(t.pairs):
        field = f"train.pairs.{k}"
        curves = {}
        phase = 0.0
        for role in ("driver", "follower"):
            spec = getattr(p, role)
            if spec is None:
                continue
            try:
                curves[role] = curve_from_spec(spec, grid, f"{field}.{role}")
            except CurveError as exc:
                raise TrainSpecError(str(exc)) from None
            phase = np.radians(spec.phase_deg)
        centre = p.centre_distance_mm
        if p.law is not None:
            curves["driver"], centre = law_curve(p, grid, field, _law_senses(design)[k])
            phase = np.radians(p.law.phase_deg)
        dwell = None if p.dwell is None else (np.radians(p.dwell.start_deg),
                                               np.radians(p.dwell.sector_deg))
        pairs.append(PairSpec(kind=p.kind, driver=curves.get("driver"), phase=phase,
                              follower=curves.get("follower"),
                              centre_distance=centre,
                              direction=np.radians(p.direction_deg),
                              follower_turns=p.follower_turns, name=field, dwell=dwell))
    c = design.carrier
    return Train(pairs, carrier0=np.radians(c.initial_angle_deg),
                 carrier_sense=-1 if c.direction == "clockwise" else 1,
                 sun_speed_ratio=t.sun_speed_ratio, arm_length=design.arm.length_mm,
                 arm_angle=np.radians(design.arm.initial_angle_deg), arms=c.arms,
                 min_radius=t.min_pitch_radius_mm,
                 closure_tolerance=np.radians(t.closure_tolerance_deg), carrier_held=c.held)


def _curve_structure(spec):
    """What P curves of one family must share to be tabulated together (everything but
    their numbers): the family, the control angles, interpolation and lobes, the number
    of harmonics."""
    if spec is None:
        return None
    if spec.family == "radii":
        return ("radii", tuple(spec.angles()), len(spec.radii_mm), spec.interpolation,
                spec.lobes, spec.open)
    if spec.family == "fourier":
        return ("fourier", len(spec.cos_mm), len(spec.sin_mm))
    return (spec.family,)


def structure_key(design) -> tuple:
    """The structure P planetary designs must share to be one population (``Train``):
    pair kinds, which pairs give a driver or a follower table and of which family,
    follower turns, whether a centre distance or a dwell is given, the sun speed ratio,
    the grid, the carrier's sense and arms, and the rules (limits, cutting). Designs
    differing only in numbers (radii, eccentricities, phases, centre distances, dwell
    angles, arm, carrier start) share it."""
    t = design.train
    pairs = tuple((p.kind, _curve_structure(p.driver), _curve_structure(p.follower),
                   p.follower_turns, p.centre_distance_mm is None, p.dwell is None,
                   p.law is None)
                  for p in t.pairs)
    return (pairs, t.sun_speed_ratio, t.grid, t.min_pitch_radius_mm, t.closure_tolerance_deg,
            design.carrier.direction, design.carrier.arms, design.carrier.speed_deg_s,
            design.carrier.held,
            design.limits.model_dump_json(), design.manufacturing.model_dump_json())


def _curves_from_specs(specs: list, grid: int, name: str) -> Curve:
    """The pitch curves (P, grid) of P ``driver``/``follower`` tables of one structure
    (``_curve_structure``), tabulated at once."""
    first = specs[0]
    if first.family == "ellipse":
        return ellipse(np.array([s.semi_major_mm for s in specs]),
                       np.array([s.eccentricity for s in specs]), grid, name)
    if first.family == "eccentric":
        return eccentric_circle(np.array([s.radius_mm for s in specs]),
                                np.array([s.offset_mm for s in specs]), grid, name)
    if first.family == "fourier":
        return fourier(np.array([s.mean_radius_mm for s in specs]),
                       np.array([s.cos_mm or [0.0] for s in specs]),
                       np.array([s.sin_mm or [0.0] for s in specs]), grid, name)
    return interpolated(np.radians(first.angles()), np.array([s.radii_mm for s in specs]),
                        grid, first.interpolation, first.lobes, name,
                        open_turn=getattr(first, "open", False))


def train_from_designs(designs: list, grouped: bool = False) -> Train:
    """One ``Train`` of P planetary designs sharing their ``structure_key``: every number
    of the files becomes a (P,) array (the curves (P, grid)); P = 1 is
    ``train_from_design``. Raises ValueError when the structures differ, TrainSpecError
    (naming the field) when a curve cannot be tabulated. ``grouped``: the caller has
    grouped the designs by ``structure_key`` already (the key, a JSON dump of the rules per
    design, is not computed a second time)."""
    first = designs[0]
    require_curves(first)
    if not grouped:
        key = structure_key(first)
        for i, d in enumerate(designs[1:], 1):
            if structure_key(d) != key:
                raise ValueError(f"design {i} does not share design 0's train structure "
                                 "(pair kinds, curve families, turns, grid, carrier, rules)")
    t = first.train
    pairs = []
    for k, p in enumerate(t.pairs):
        field = f"train.pairs.{k}"
        curves = {}
        phase = np.zeros(len(designs))
        for role in ("driver", "follower"):
            if getattr(p, role) is None:
                continue
            specs = [getattr(d.train.pairs[k], role) for d in designs]
            try:
                curves[role] = _curves_from_specs(specs, t.grid, f"{field}.{role}")
            except CurveError as exc:
                raise TrainSpecError(str(exc)) from None
            phase = np.radians([s.phase_deg for s in specs])
        given = [d.train.pairs[k].centre_distance_mm for d in designs]
        if p.law is not None:
            made = [law_curve(d.train.pairs[k], t.grid, field, _law_senses(d)[k])
                    for d in designs]
            curves["driver"] = Curve(np.concatenate([c.r for c, _ in made]),
                                     np.concatenate([c.dr for c, _ in made]),
                                     f"{field}.law")
            given = [a for _, a in made]
            phase = np.radians([d.train.pairs[k].law.phase_deg for d in designs])
        dwell = None if p.dwell is None else (
            np.radians([d.train.pairs[k].dwell.start_deg for d in designs]),
            np.radians([d.train.pairs[k].dwell.sector_deg for d in designs]))
        pairs.append(PairSpec(kind=p.kind, driver=curves.get("driver"), phase=phase,
                              follower=curves.get("follower"),
                              centre_distance=None if given[0] is None else np.array(given),
                              direction=np.radians([d.train.pairs[k].direction_deg
                                                    for d in designs]),
                              follower_turns=p.follower_turns, name=field, dwell=dwell))
    c = first.carrier
    return Train(pairs, carrier0=np.radians([d.carrier.initial_angle_deg for d in designs]),
                 carrier_sense=-1 if c.direction == "clockwise" else 1,
                 sun_speed_ratio=t.sun_speed_ratio,
                 arm_length=np.array([d.arm.length_mm for d in designs]),
                 arm_angle=np.radians([d.arm.initial_angle_deg for d in designs]), arms=c.arms,
                 min_radius=t.min_pitch_radius_mm,
                 closure_tolerance=np.radians(t.closure_tolerance_deg), carrier_held=c.held)


#: how far (rad) an open curve's break may lie from its contact where the dwell starts
BREAK_TOLERANCE = 1e-6


def check_breaks(built: BuiltTrain) -> None:
    """TrainSpecError naming the field (``train.pairs.<k>.<role>.open``) unless every open
    curve (``trains.curves``: a break at body angle 0) that a pair's law rolls on is at its
    break at the contact when the first pair's toothless dwell starts: the dwell then holds
    it there (its shaft does not turn) and it rolls away from the break when meshing
    resumes, so the break is never rolled across while the teeth mesh (seed 000's
    inverse-designed gears 2 and 3 step at the lock point). A derived mate of an open curve
    breaks at the same contact (``trains.pairs``)."""
    from plantmech.trains.model import contact_angles

    train = built.train
    open_laws = [k for k, law in enumerate(built.laws) if law.driver.open]
    if not open_laws:
        return
    gap = train.pairs[0].dwell
    if gap is None:
        k = open_laws[0]
        raise TrainSpecError(f"{train.pairs[k].name}.driver.open: a curve with a break needs "
                             "the train's toothless dwell (train.pairs.0.dwell) to hold it at "
                             "its break")
    start = np.broadcast_to(np.asarray(gap[0], dtype=float), (built.designs,))
    # (P, P): every design at every design's start; each design's own is the diagonal
    angles = [tuple(np.diagonal(t)[:, None] for t in pair)
              for pair in contact_angles(built, start)]
    for k in open_laws:
        spec = train.pairs[k]
        given = spec.follower is not None
        theta = angles[k][1] if given else angles[k][0]
        off = np.abs(np.angle(np.exp(1j * theta[:, 0])))
        if np.any(off > BREAK_TOLERANCE):
            d = int(np.argmax(off))
            role = "follower" if given else ("driver" if spec.driver is not None else None)
            where = f"{spec.name}.{role}.open" if role else (
                f"{train.pairs[k - 1].name}: the follower's mate (open, an idler)")
            raise TrainSpecError(
                f"{where}: the curve's break (body angle 0) is not at the contact where the "
                f"dwell starts (carrier angle {np.degrees(start[d]):.6g} deg): the contact is "
                f"at its body angle {np.degrees(np.mod(theta[d, 0], TWO_PI)):.6f} deg, so the "
                "break would be rolled across while the teeth mesh; move the curve's phase "
                "(or its angles) so the break meets the contact at the dwell's start"
                + (f" (design {d})" if built.designs > 1 else ""))


def build_from_designs(designs: list, grouped: bool = False) -> BuiltTrain:
    """The built train of P planetary designs sharing their structure (``train_from_designs``,
    ``grouped`` as there); TrainSpecError names the pair (and the design) whose curves
    cannot roll or close."""
    train = train_from_designs(designs, grouped)
    try:
        built = build(train, len(designs))
    except (PairError, CurveError) as exc:
        raise TrainSpecError(str(exc)) from None
    check_breaks(built)
    return built


def build_from_design(design) -> BuiltTrain:
    """The built train (laws, gear curves) of a planetary design; TrainSpecError names the
    pair whose pitch curves cannot roll or close."""
    train = train_from_design(design)
    try:
        built = build(train)
    except (PairError, CurveError) as exc:
        raise TrainSpecError(str(exc)) from None
    check_breaks(built)
    return built
