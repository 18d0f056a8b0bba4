"""A ``PlanetaryDesign`` (design file, ``mechanism = "planetary"``) as a ``Train``.

Units change here: the file's mm and degrees become mm and radians. Errors are raised as
``TrainSpecError`` naming the design-file field (``train.pairs.<k>...``).
"""

from __future__ import annotations

import numpy as np

from plantmech.trains.curves import (
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
                        spec.lobes, name)


def train_from_design(design) -> Train:
    """The ``Train`` (P = 1) of a planetary design."""
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
        pairs.append(PairSpec(kind=p.kind, driver=curves.get("driver"), phase=phase,
                              follower=curves.get("follower"),
                              centre_distance=p.centre_distance_mm,
                              direction=np.radians(p.direction_deg),
                              follower_turns=p.follower_turns, name=field))
    c = design.carrier
    return Train(pairs, carrier0=np.radians(c.initial_angle_deg),
                 carrier_sense=-1 if c.direction == "clockwise" else 1,
                 sun_speed_ratio=t.sun_speed_ratio, arm_length=design.arm.length_mm,
                 arm_angle=np.radians(design.arm.initial_angle_deg), arms=c.arms,
                 min_radius=t.min_pitch_radius_mm,
                 closure_tolerance=np.radians(t.closure_tolerance_deg))


def build_from_design(design) -> BuiltTrain:
    """The built train (laws, gear curves) of a planetary design; TrainSpecError names the
    pair whose pitch curves cannot roll or close."""
    train = train_from_design(design)
    try:
        return build(train)
    except (PairError, CurveError) as exc:
        raise TrainSpecError(str(exc)) from None
