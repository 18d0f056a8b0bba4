"""Design files of the general non-circular planetary train (``mechanism = "planetary"``).

A carrier, a sun (fixed or driven), a chain of ``[[train.pairs]]`` (external or internal,
idlers and compound shafts), pitch curves from the supported families, and one or more
arms at a phase offset (``trains.model``). Imported by ``design.py``, which registers the
mechanism; strict types and field-named errors as everywhere in ``design.py``.
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Field, Strict, StrictBool, field_validator, model_validator

from plantmech.design import (
    MAX_CARRIER_SPEED_DEG_S,
    MAX_POINTS,
    MECHANISMS,
    AngleDeg,
    CarrierAngleDeg,
    Interp,
    Manufacturing,
    PositiveMM,
    Range,
    Samples,
    Text,
    TrainDwell,
    Trajectory,
    _check_polar_points,
    _Strict,
    _uniform,
)

#: most pairs in one chain.
MAX_PAIRS = 8
#: most Fourier harmonics of a pitch curve.
MAX_HARMONICS = 32

Eccentricity = Annotated[float, Strict(), Field(ge=0, le=0.8, allow_inf_nan=False)]
Harmonic = Annotated[float, Strict(), Field(ge=-1000, le=1000, allow_inf_nan=False)]


class EllipseCurve(_Strict):
    """An ellipse turning about one of its foci: r = A (1 - e^2) / (1 - e cos theta), theta
    measured from the far end of the major axis (r(0) = A (1 + e))."""

    family: Literal["ellipse"] = Field(description="pitch-curve family")
    semi_major_mm: PositiveMM = Field(description="A: semi-major axis (mm)")
    eccentricity: Eccentricity = Field(description="e: eccentricity (0 = circle turning "
                                       "about its centre; at most 0.8)")
    phase_deg: AngleDeg = Field(0.0, description="a driver: the sun's absolute angle of "
                                "the far end of the major axis at the start (deg, CCW from "
                                "+x), a compound gear's angle to the frame of the gear it is "
                                "fixed to; a given follower: its body angle at the contact "
                                "at the start (deg)")


class EccentricCurve(_Strict):
    """A circle turning about a point off its centre: r = E cos theta + sqrt(R^2 - E^2
    sin^2 theta), theta from the side farthest from the axis."""

    family: Literal["eccentric"] = Field(description="pitch-curve family")
    radius_mm: PositiveMM = Field(description="R: circle radius (mm)")
    offset_mm: Annotated[float, Strict(), Field(ge=0, allow_inf_nan=False)] = Field(
        description="E: distance of the turning axis from the centre (mm, below R)")
    phase_deg: AngleDeg = Field(0.0, description="as for an ellipse: orientation of the "
                                "farthest point (deg)")

    @model_validator(mode="after")
    def _inside(self):
        if self.offset_mm >= self.radius_mm:
            raise ValueError(f"offset_mm = {self.offset_mm:g} is not below radius_mm = "
                             f"{self.radius_mm:g}: the axis must lie inside the circle")
        return self


class FourierCurve(_Strict):
    """r = r0 + sum_k (c_k cos k theta + s_k sin k theta), k = 1, 2, ..."""

    family: Literal["fourier"] = Field(description="pitch-curve family")
    mean_radius_mm: PositiveMM = Field(description="r0: mean radius (mm)")
    cos_mm: list[Harmonic] = Field([], description="c_1, c_2, ...: cosine coefficients (mm)",
                                   max_length=MAX_HARMONICS)
    sin_mm: list[Harmonic] = Field([], description="s_1, s_2, ...: sine coefficients (mm)",
                                   max_length=MAX_HARMONICS)
    phase_deg: AngleDeg = Field(0.0, description="as for an ellipse: orientation of "
                                "theta = 0 (deg)")

    @model_validator(mode="after")
    def _positive(self):
        th = np.linspace(0.0, 2 * np.pi, 2048, endpoint=False)
        r = np.full_like(th, self.mean_radius_mm)
        for k, c in enumerate(self.cos_mm, 1):
            r += c * np.cos(k * th)
        for k, s in enumerate(self.sin_mm, 1):
            r += s * np.sin(k * th)
        j = int(np.argmin(r))
        if r[j] <= 0:
            raise ValueError(f"the series falls to {r[j]:.4g} mm at {np.degrees(th[j]):.1f} "
                             "deg: a pitch radius must stay positive")
        return self


#: most control radii of an open pitch curve (``RadiiCurve.open``): seed 000's
#: inverse-designed gears with a dwell carry their inverse design's knots (3600 samples
#: per carrier turn less the dwell's); tabulated by SciPy's spline, no dense matrix.
MAX_OPEN_POINTS = 4096


class RadiiCurve(_Strict):
    """Control radii joined by a periodic cubic Hermite (seed 000 §4.3) or spline,
    optionally over identical lobes; or, ``open``, one open turn with a break at body
    angle 0 (``trains.curves``)."""

    family: Literal["radii"] = Field(description="pitch-curve family")
    radii_mm: list[PositiveMM] = Field(description=f"r_i: control radii (mm), 4 to "
                                       f"{MAX_POINTS} ({MAX_OPEN_POINTS} for an open curve)",
                                       max_length=MAX_OPEN_POINTS)
    angles_deg: list[AngleDeg] | None = Field(
        None, description="angles of the radii within one lobe (deg, 360 per lobe), "
        "increasing, spanning less than 360; default uniform. An open curve: from 0 to 360 "
        "(both ends), default uniform", max_length=MAX_OPEN_POINTS)
    interpolation: Interp = Field("hermite", description="periodic cubic Hermite (C1) or "
                                  "periodic cubic spline (C2); an open curve: cubic Hermite "
                                  "(one-sided end slopes) or not-a-knot cubic spline")
    lobes: Annotated[int, Strict()] = Field(1, ge=1, le=12, description="n: identical "
                                            "lobes round the gear")
    open: StrictBool = Field(False, description="true: the curve breaks at body angle 0 "
                             "(its radius's two limits there differ; seed 000's "
                             "inverse-designed gears with a toothless dwell): the first radius "
                             "is the right limit at 0 deg, the last the left limit at 360 "
                             "deg. Only where the train's dwell holds the curve at its break "
                             "(the contact there when the dwell starts, so it is never rolled "
                             "across), one lobe, follower_turns = 1")
    phase_deg: AngleDeg = Field(0.0, description="as for an ellipse: orientation of angle 0 "
                                "(deg)")

    @model_validator(mode="after")
    def _angles(self):
        if not self.open:
            if len(self.radii_mm) > MAX_POINTS:
                raise ValueError(f"radii_mm: at most {MAX_POINTS} items for a periodic curve "
                                 f"(got {len(self.radii_mm)}; {MAX_OPEN_POINTS} for an open "
                                 "one)")
            _check_polar_points(self.radii_mm, self.angles_deg, "angles_deg", "angle")
            return self
        if self.lobes != 1:
            raise ValueError(f"open: an open curve (a break at body angle 0) has one lobe, "
                             f"got lobes = {self.lobes}")
        if len(self.radii_mm) < 4:
            raise ValueError(f"need at least 4 radii, got {len(self.radii_mm)}")
        angles = self.angles()
        if len(angles) != len(self.radii_mm):
            raise ValueError(f"angles_deg has {len(angles)} values but radii_mm has "
                             f"{len(self.radii_mm)}")
        if angles[0] != 0.0 or angles[-1] != 360.0:
            raise ValueError(f"angles_deg of an open curve run from 0 deg (its break, the "
                             f"right limit) to 360 deg (the left limit); got {angles[0]:g} to "
                             f"{angles[-1]:g}")
        for k in range(1, len(angles)):
            if angles[k] <= angles[k - 1]:
                raise ValueError(f"angles_deg must increase: point {k} at {angles[k]:g} deg "
                                 f"follows {angles[k - 1]:g} deg")
        return self

    def angles(self) -> list[float]:
        if self.open and self.angles_deg is None:
            n = len(self.radii_mm)
            return [360.0 * k / (n - 1) for k in range(n)]
        return _uniform(self.angles_deg, len(self.radii_mm))


PitchCurve = Annotated[EllipseCurve | EccentricCurve | FourierCurve | RadiiCurve,
                       Field(discriminator="family")]


class TransmissionLaw(_Strict):
    """A pair given by its transmission law (``design_law``): the follower's angle phi as
    a function of the driver's t, or the ratio d phi / dt, as an expression of t (rad) in
    a restricted grammar or as a table over one lobe (360 / n2 deg of driver angle, n2 the
    follower's turns); the driver's pitch curve follows at the pair's centre distance."""

    follower_angle: Text | None = Field(
        None, description="phi(t): the follower's angle (rad) as an expression of the "
        "driver's turn t from the start (rad, in its sense of turning): numbers, t, pi, "
        "e, the constants below, + - * / **, sin "
        "cos tan asin acos atan atan2 sinh cosh tanh exp log sqrt abs hypot; over a lobe "
        "(t from 0 to 360 / n2 deg) it must turn 360 / n1 deg")
    ratio: Text | None = Field(
        None, description="instead: g(t) = d phi / dt, the follower's speed over the "
        "driver's, as an expression of t (rad); its mean over a driver turn must be n2 / n1")
    driver_deg: list[AngleDeg] | None = Field(
        None, description="a table instead: driver angles (deg, increasing) over one lobe, "
        "first to last spanning 360 / n2 deg", max_length=MAX_OPEN_POINTS)
    follower_deg: list[Annotated[float, Strict(), Field(ge=-1e5, le=1e5,
                                                        allow_inf_nan=False)]] | None = Field(
        None, description="with driver_deg: the follower's angle there (deg), joined by a "
        "periodic cubic spline of its periodic part", max_length=MAX_OPEN_POINTS)
    ratio_table: list[Annotated[float, Strict(), Field(gt=0, le=1e3,
                                                       allow_inf_nan=False)]] | None = Field(
        None, description="with driver_deg, instead of follower_deg: the ratio there "
        "(periodic cubic spline; first = last)", max_length=MAX_OPEN_POINTS)
    constants: dict[Text, Annotated[float, Strict(), Field(allow_inf_nan=False)]] | None = (
        Field(None, description="named numbers the expressions may use, e.g. { k = 2.08 }",
              max_length=32))
    segment_deg: list[AngleDeg] | None = Field(
        None, description="[t0, t1]: an open segment: the law is wanted for driver angles t0 "
        "to t1 only (deg, t1 - t0 below 360); the pair is closed by a return arc over the "
        "rest of the turn (a cubic of the ratio joining the segment's ends)", min_length=2,
        max_length=2)
    module_mm: Annotated[float, Strict(), Field(gt=0, le=100, allow_inf_nan=False)] | None = (
        Field(None, description="with the pair's teeth, instead of centre_distance_mm: the "
              "size from the tooth count (the driver's pitch perimeter is pi m z)"))
    phase_deg: AngleDeg = Field(0.0, description="as for a driver curve: the sun's absolute "
                                "angle of its body angle t = 0 at the start (deg)")

    @model_validator(mode="after")
    def _one_form(self):
        from plantmech.design_law import ExpressionError, compile_expression

        forms = [n for n in ("follower_angle", "ratio", "follower_deg", "ratio_table")
                 if getattr(self, n) is not None]
        if len(forms) != 1:
            raise ValueError("give one of follower_angle, ratio (expressions) or "
                             "driver_deg with follower_deg or ratio_table (a table); got "
                             + (", ".join(forms) or "none"))
        for n in ("follower_angle", "ratio"):
            text = getattr(self, n)
            if text is not None:
                try:
                    compile_expression(text, self.constants)
                except ExpressionError as exc:
                    raise ValueError(f"{n}: {exc}") from None
        table = self.follower_deg if self.follower_deg is not None else self.ratio_table
        if table is not None:
            if self.driver_deg is None or len(self.driver_deg) != len(table):
                raise ValueError("a tabulated law needs driver_deg with as many values as "
                                 + ("follower_deg" if self.follower_deg is not None
                                    else "ratio_table"))
            if len(table) < 4:
                raise ValueError(f"a tabulated law needs at least 4 rows, got {len(table)}")
            for k in range(1, len(self.driver_deg)):
                if self.driver_deg[k] <= self.driver_deg[k - 1]:
                    raise ValueError(f"driver_deg must increase: row {k} at "
                                     f"{self.driver_deg[k]:g} deg follows "
                                     f"{self.driver_deg[k - 1]:g} deg")
            if self.segment_deg is not None:
                raise ValueError("segment_deg takes an expression (follower_angle or ratio)")
        elif self.driver_deg is not None:
            raise ValueError("driver_deg goes with follower_deg or ratio_table")
        if self.segment_deg is not None:
            t0, t1 = self.segment_deg
            if not 0 < t1 - t0 < 360:
                raise ValueError(f"segment_deg = [{t0:g}, {t1:g}]: the segment's end follows "
                                 "its start by less than a turn (0 < t1 - t0 < 360)")
        return self


class PairDwell(TrainDwell):
    """A toothless dwell of the pair (seed 000's sector over cd, Eq. 5), in carrier angles:
    while the carrier turns ``sector_deg`` from ``start_deg`` the follower (and every gear
    after it) does not turn relative to the carrier; the driver's toothless arc passes
    the follower, which then rolls on ``sector_deg`` behind the carrier. The first pair
    only, with a fixed sun and the follower's pitch curve given (seed 000's gear 2): the sun
    is derived, its rolling arc the mate of one follower turn (360 - sector_deg deg of its
    body) and its toothless arc the rest (examples/planetary/sugarcane_table4.toml)."""

    start_deg: CarrierAngleDeg = Field(description="psi_s: carrier angle (deg, from the "
                                       "start, in the carrier's sense) where the follower "
                                       "stops")


class GearPair(_Strict):
    """One pair of the chain: a driver and the follower it rolls (the follower's pitch
    curve follows from rolling; it drives the next pair unless that pair gives a driver)."""

    kind: Literal["external", "internal", "internal_ring_follower"] = Field(
        "external", description="external; internal (the driver is a ring, the follower "
        "rolls inside it, seed 001); internal_ring_follower (the follower is a ring)")
    driver: PitchCurve | None = Field(
        None, description="the driver's pitch curve: required for the first pair (the "
        "sun); for later pairs a second gear fixed to the previous follower's shaft "
        "(compound); left out: the previous follower drives (an idler)")
    follower: PitchCurve | None = Field(
        None, description="instead of the driver: the follower's pitch curve (seed 000: "
        "gear 2 given, the sun derived); the driver is then its mate (the sun, or a new "
        "gear on the previous follower's shaft) and the follower's phase_deg is its body "
        "angle at the contact at the start (deg)")
    law: TransmissionLaw | None = Field(
        None, description="instead of the driver: the pair's transmission law (the "
        "follower's angle or the ratio as a function of the driver's angle); the driver's "
        "pitch curve follows at centre_distance_mm (or from law.module_mm and teeth)")
    centre_distance_mm: PositiveMM | None = Field(
        None, description="a: centre distance (mm); default: solved so the pair closes "
        "(a law: required unless law.module_mm and teeth size it)")
    turns: list[Annotated[int, Strict(), Field(ge=1, le=12)]] | None = Field(
        None, description="[n1, n2]: the driver makes n1 turns while the follower makes n2 "
        "(lobed gears: [1, 2], [2, 3]); sets follower_turns = n2 / n1. The driver's teeth "
        "must then be a multiple of n2 (the follower carries z n1 / n2)", min_length=2,
        max_length=2)
    direction_deg: AngleDeg = Field(0.0, description="delta: direction of the line of "
                                    "centres driver -> follower, from the carrier line "
                                    "(deg, CCW)")
    follower_turns: Annotated[float, Strict(), Field(gt=0, le=12, allow_inf_nan=False)] = (
        Field(1.0, description="q: follower turns per driver turn relative to the carrier "
              "(the pair closes when the rolled ratio's mean is q)"))
    dwell: PairDwell | None = Field(
        None, description="a toothless dwell of this pair (the first pair only, a fixed sun "
        "and a given follower; seed 000's sector)")
    teeth: Annotated[int, Strict()] | None = Field(
        None, ge=6, le=500, description="z: tooth count of the pair's driver (the sun, a "
        "compound gear, or the derived driver of a given follower) for `plantmech gears`: "
        "the module is its pitch perimeter / (pi z), so the curve closes on whole teeth; "
        "default: the largest standard module the pitch curves allow (gears.modules."
        "choose_teeth; or --module). An idler's "
        "pair (no driver table) takes the previous pair's module; a multiple of the "
        "driver's lobes. A pair with a dwell: the given follower's (the sun is then a "
        "partial gear, toothless over its toothless arc)")

    @model_validator(mode="before")
    @classmethod
    def _turns_set_follower_turns(cls, data):
        if isinstance(data, dict) and isinstance(data.get("turns"), list) \
                and len(data["turns"]) == 2 and all(
                    isinstance(v, int) and not isinstance(v, bool) and v > 0
                    for v in data["turns"]):
            n1, n2 = data["turns"]
            given = data.get("follower_turns")
            if given is not None and given != n2 / n1:
                raise ValueError(f"turns = [{n1}, {n2}] (follower_turns {n2 / n1:g}) and "
                                 f"follower_turns = {given!r} disagree: give one")
            data = {**data, "follower_turns": n2 / n1}
        return data

    @model_validator(mode="after")
    def _law_fits(self):
        if self.law is None:
            return self
        if self.driver is not None or self.follower is not None:
            raise ValueError("give driver, follower or law, not two (the others follow from "
                             "rolling)")
        if self.centre_distance_mm is None and (self.law.module_mm is None
                                                or self.teeth is None):
            raise ValueError("law: a transmission law fixes the gears' shape, not their "
                             "size: give centre_distance_mm, or law.module_mm with teeth")
        if self.centre_distance_mm is not None and self.law.module_mm is not None:
            raise ValueError("law.module_mm: the size is given twice (centre_distance_mm "
                             "too): give one")
        if self.dwell is not None:
            raise ValueError("dwell: a pair given by its law has no toothless dwell")
        return self

    def turns_pair(self) -> tuple[int, int]:
        """(n1, n2): the driver's and the follower's turns (from ``turns``, else the
        follower_turns as the nearest fraction with denominator up to 12)."""
        if self.turns is not None:
            return int(self.turns[0]), int(self.turns[1])
        from fractions import Fraction

        f = Fraction(self.follower_turns).limit_denominator(12)
        return f.denominator, f.numerator

    @model_validator(mode="after")
    def _teeth_fit(self):
        lobes = getattr(self.driver, "lobes", 1)
        if self.teeth is not None and self.teeth % lobes:
            raise ValueError(f"teeth = {self.teeth} is not a multiple of driver.lobes = "
                             f"{lobes}: every lobe must carry whole teeth")
        if self.teeth is not None and self.turns is not None and self.teeth % self.turns[1]:
            n1, n2 = self.turns
            raise ValueError(f"teeth = {self.teeth} does not divide by the follower's turns "
                             f"{n2} (turns = [{n1}, {n2}]): the follower would carry "
                             f"{self.teeth * n1 / n2:g} teeth; use a multiple of {n2}")
        return self

    @model_validator(mode="after")
    def _turns_fit_kind(self):
        q = self.follower_turns
        if self.kind == "internal" and not q > 1:
            raise ValueError(f"follower_turns = {q:g}: a planet rolling inside its ring "
                             "driver turns faster than the ring (follower_turns > 1)")
        if self.kind == "internal_ring_follower" and not q < 1:
            raise ValueError(f"follower_turns = {q:g}: a ring rolling round its driver turns "
                             "slower than the driver (follower_turns < 1)")
        return self


class PlanetaryTrain(_Strict):
    """The chain of gear pairs carried by the carrier (docs/architecture.md, "Train
    model")."""

    pairs: list[GearPair] = Field(description=f"the pairs, sun first, planet last (1 to "
                                  f"{MAX_PAIRS})", min_length=1, max_length=MAX_PAIRS)
    sun_speed_ratio: Annotated[float, Strict(), Field(ge=-10, le=10, allow_inf_nan=False)] = (
        Field(0.0, description="k: absolute sun speed / carrier speed (0 = fixed sun; "
              "seed 001: omega_1 / omega_2)"))
    grid: Annotated[int, Strict(), Field(ge=512, le=32768)] = Field(
        8192, description="samples per gear turn of the tabulated pitch curves and ratio "
        "laws (the interpolation error falls as grid^-4; 16384 matches seed 001's "
        "4096 per lobe)")
    min_pitch_radius_mm: PositiveMM = Field(2.0, description="smallest pitch radius any "
                                            "gear may have (mm)")
    closure_tolerance_deg: Annotated[float, Strict(), Field(gt=0, le=10.0,
                                                            allow_inf_nan=False)] = Field(
        0.01, description="largest closure error of a pair with a given centre distance "
        "(deg per driver turn)")

    @model_validator(mode="after")
    def _one_curve_per_pair(self):
        for k, p in enumerate(self.pairs):
            if p.driver is not None and p.follower is not None:
                raise ValueError(f"pairs.{k}: give driver or follower, not both (the other "
                                 "follows from rolling)")
            if p.dwell is not None and k:
                raise ValueError(f"pairs.{k}.dwell: a toothless dwell is supported on the "
                                 "first pair (the sun's) only: a later driver does not turn "
                                 "uniformly relative to the carrier")
            if p.dwell is not None and p.follower is None:
                raise ValueError(f"pairs.{k}.dwell: give the follower's pitch curve "
                                 f"(pairs.{k}.follower, seed 000's gear 2) instead of the "
                                 "sun's: the sun is then derived, its rolling arc the mate of "
                                 "one follower turn and its toothless arc the rest")
            if p.dwell is not None and self.sun_speed_ratio != 0:
                raise ValueError(f"pairs.{k}.dwell: a toothless dwell needs a fixed sun "
                                 f"(sun_speed_ratio = 0, got {self.sun_speed_ratio:g}): a "
                                 "turning sun brings its toothless arc round at another "
                                 "carrier angle every turn")
            for role in ("driver", "follower"):
                if not getattr(getattr(p, role), "open", False):
                    continue
                if self.pairs[0].dwell is None:
                    raise ValueError(f"pairs.{k}.{role}.open: a curve with a break needs the "
                                     "train's toothless dwell (pairs.0.dwell) to hold it at its "
                                     "break (rolled across, its ratio would jump while the "
                                     "teeth mesh); this train has no dwell")
                if p.follower_turns != 1:
                    raise ValueError(f"pairs.{k}.{role}.open: a curve with a break needs "
                                     f"follower_turns = 1 (got {p.follower_turns:g}): the break "
                                     "would meet its mate at another body angle every turn")
            if k and p.driver is None and p.follower is None and p.law is None \
                    and p.teeth is not None:
                raise ValueError(f"pairs.{k}.teeth: this pair's driver is the previous "
                                 "follower (an idler), whose teeth follow from the pair "
                                 "before; give teeth on the pair with the driver table")
        return self


class PlanetaryCarrier(_Strict):
    """The carrier: how it turns and how many arms it carries."""

    initial_angle_deg: AngleDeg = Field(0.0, description="C0: absolute angle of arm 1's "
                                        "carrier line (sun axis -> first shaft) at the start "
                                        "(deg, CCW from +x)")
    speed_deg_s: Annotated[float, Strict(), Field(
        gt=0, le=MAX_CARRIER_SPEED_DEG_S, allow_inf_nan=False)] = Field(
        360.0, description="omega: carrier speed (deg/s)")
    direction: Literal["clockwise", "counterclockwise"] = Field(
        "clockwise", description="sense of the carrier's turn")
    arms: Annotated[int, Strict()] = Field(1, ge=1, le=6, description="arms (each with its "
                                           "own chain), evenly spaced round the carrier")
    held: StrictBool = Field(False, description="true: the carrier is the frame (gears on "
                             "fixed centres: a gear pair, or any chain); the sun (the first "
                             "driver) then turns at speed_deg_s in `direction`, and the "
                             "samples are over one sun turn; one arm, a sun_speed_ratio of 0 "
                             "(unused), no toothless dwell")


class PlanetaryArm(_Strict):
    """The arm fixed on the planet (last follower)."""

    length_mm: PositiveMM | None = Field(None, description="L: planet axis to tip (mm); "
                                         "required unless `plantmech inverse` computes it "
                                         "from a [trajectory]")
    initial_angle_deg: AngleDeg | None = Field(
        None, description="beta_0: absolute angle of planet axis -> tip of arm 1 at the "
        "start (deg, CCW from +x); required unless `plantmech inverse` computes it from a "
        "[trajectory]")


PointIndex = Annotated[int, Strict(), Field(ge=0, lt=MAX_POINTS)]


class TrajectoryDwell(_Strict):
    """The toothless dwell of seed 000's second-order inverse design over a stretch of the
    planned path (examples/sugarcane_seeder_dwell.toml's [gear_train.dwell], its section
    letters given as type-value point indices, 0-based): the arm is held in the carrier
    from point ``start`` to point ``end`` (the sun's toothless sector, seed 000 Eq. 5) and
    the planned turn inside is redistributed so the attitude at ``anchor`` is kept."""

    start: PointIndex = Field(description="type-value point (0-based) where the dwell starts "
                              "(the seeder's section c)")
    end: PointIndex = Field(description="type-value point where it ends (section d; another "
                            "point than start)")
    anchor: PointIndex = Field(description="type-value point whose attitude is kept exactly "
                               "(section e)")
    edge_radius_mm: PositiveMM | None = Field(None, description="R2 of Eq. 5: the sun's radius "
                                              "at the sector's edges (mm); default: from the "
                                              "stage-1 ratio")

    @model_validator(mode="after")
    def _extent(self):
        if self.start == self.end:
            raise ValueError(f"start = end = {self.start}: a dwell needs two different "
                             "type-value points (it would have zero length)")
        return self


class PlanetaryTrajectory(Trajectory):
    """The planned tip trajectory of a first-order train for `plantmech inverse` (the
    seeder's [trajectory] points and samples; no sections). The file then gives a fixed
    sun (`train.sun_speed_ratio = 0`), ONE `[[train.pairs]]` with its `kind` and
    `follower_turns` but no pitch-curve table, and an `[arm]` without length or start angle:
    the trajectory's farthest and nearest radii fix the carrier arm (the pair's centre
    distance) and the arm (`arm`), the two-link chain the planet's angle along the carrier,
    hence the ratio law and the sun's pitch curve (`objectives.planetary_inverse`).
    `plantmech inverse`
    writes design.toml: this file with the sun as `family = "radii"` (periodic spline),
    the centre distance, the arm and the start angles filled in, which `plantmech forward`
    runs; the round trip (its tip through every type-value point within 0.01 mm) is a
    check of the verdict. A centre distance or arm length given in the file must equal the
    one the trajectory fixes."""

    sections: None = Field(None, description="not used by a planetary train (the seeder's "
                           "section points)")
    arm: Literal["long", "short"] = Field(
        "long", description="which link is the longer: the trajectory's farthest and "
        "nearest radii fix the carrier arm a and the arm L (seed 000 Eq. 1: the chain "
        "straightens and folds once per cycle); \"long\": L = (rho_max + rho_min) / 2, "
        "a = (rho_max - rho_min) / 2 (seed 000), \"short\": the two exchanged; a "
        "second-order train (two pairs) takes \"long\"")
    split_exponent: Annotated[float, Strict(), Field(gt=0, lt=1, allow_inf_nan=False)] = (
        Field(0.5, description="p: a second-order train (two pairs, seed 000) gives its "
              "first pair the ratio C (total ratio)^p (seed 000 Eq. 7-8)"))

    dwell: TrajectoryDwell | None = Field(
        None, description="a second-order train (two pairs, seed 000): the sun's toothless "
        "dwell between two type-value points; `plantmech inverse` then writes gear 2 and "
        "gear 3 as open curves breaking at the lock point and the first pair's "
        "[train.pairs.dwell]")

    @model_validator(mode="after")
    def _sections_in_range(self):  # replaces the seeder's: no sections here
        n = len(self.points)
        if self.dwell is not None:
            for key in ("start", "end", "anchor"):
                if getattr(self.dwell, key) >= n:
                    raise ValueError(f"dwell.{key} = {getattr(self.dwell, key)}: there are "
                                     f"{n} type-value points (0 to {n - 1})")
        if self.samples < 4 * n:
            raise ValueError(f"samples = {self.samples} is fewer than 4 per type-value point "
                             f"({n} points)")
        return self


class PlanetaryLimits(_Strict):
    """Limits on the generic objectives; a limit left out is reported, not checked."""

    path_width_mm: Range | None = Field(None, description="horizontal extent of the tip path "
                                        "(mm)")
    path_height_mm: Range | None = Field(None, description="vertical extent of the tip path "
                                         "(mm)")
    attitude_range_deg: Range | None = Field(None, description="swing of the arm over a "
                                             "turn, max - min of its angle (deg)")
    max_tip_speed_m_s: Range | None = Field(None, description="largest tip speed (m/s)")
    min_tip_speed_m_s: Range | None = Field(None, description="smallest tip speed (m/s)")
    loops: Range | None = Field(None, description="self-crossings of the tip path (count)")
    min_module_mm: Annotated[float, Strict(), Field(gt=0, le=100, allow_inf_nan=False)] = (
        Field(1.0, description="smallest gear module (mm), a pitch-curve manufacturability "
              "rule of `plantmech gears` (as the transplanters' (xi))"))
    min_internal_teeth_difference: Annotated[float, Strict(), Field(
        gt=0, le=1000, allow_inf_nan=False)] = Field(
        8.0, description="smallest equivalent tooth-count difference ring - planet of an "
        "internal pair (as the transplanters' (xv))")
    max_working_pressure_angle_deg: Annotated[float, Strict(), Field(
        gt=0, lt=90, allow_inf_nan=False)] = Field(45.0, description="largest working "
                                                   "pressure angle of a pair (deg, as the "
                                                   "transplanters' (xiv))")


#: most free variables of one optimization.
MAX_VARIABLES = 32


def resolve_path(root, path: str):
    """(parent, key) of a dotted field path of a design ("train.pairs.0.driver.eccentricity":
    attribute names and list indices); raises ValueError naming the first part that is not
    there."""
    parts = path.split(".")
    node = root
    for i, part in enumerate(parts[:-1]):
        node = _step(node, part, ".".join(parts[:i + 1]))
    last = parts[-1]
    _step(node, last, path)  # it must exist
    return node, last


def _step(node, part: str, where: str):
    if isinstance(node, list):
        if not part.isdigit() or int(part) >= len(node):
            raise ValueError(f"'{where}': no item {part} (the list has {len(node)})")
        return node[int(part)]
    if isinstance(node, dict):  # a table of named numbers (a law's constants)
        if part not in node:
            raise ValueError(f"'{where}': no such entry (the table has "
                             f"{', '.join(node) or 'none'})")
        return node[part]
    if node is None or part not in getattr(type(node), "model_fields", {}):
        raise ValueError(f"'{where}': no such field")
    return getattr(node, part)


def get_path(root, path: str):
    node, key = resolve_path(root, path)
    if isinstance(node, dict):
        return node[key]
    return node[int(key)] if isinstance(node, list) else getattr(node, key)


def set_path(root, path: str, value) -> None:
    """Write ``value`` at the dotted ``path`` of a design (a model or its model_dump())."""
    parts = path.split(".")
    node = root
    for part in parts[:-1]:
        node = node[int(part)] if isinstance(node, list) else (
            node[part] if isinstance(node, dict) else getattr(node, part))
    last = parts[-1]
    if isinstance(node, list):
        node[int(last)] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        setattr(node, last, value)


class PlanetaryOptimize(_Strict):
    """What `plantmech optimize --problem planetary` may change: the numeric fields named by
    their dotted path in the file, each within [lower, upper]; every [limits] check and the
    pitch-curve manufacturability rules are its constraints (docs/optimization.md)."""

    variables: dict[Text, list[Annotated[float, Field(allow_inf_nan=False)]]] = Field(
        description="free variables: \"dotted.path\" = [lower, upper], e.g. "
        "\"train.pairs.0.driver.eccentricity\" = [0.1, 0.4] (a numeric field of this file; "
        f"list items by index; 1 to {MAX_VARIABLES}); units those of the field",
        min_length=1, max_length=MAX_VARIABLES)
    samples: Annotated[int, Strict()] = Field(
        720, ge=90, le=20000, description="samples per carrier turn while optimizing (the "
        "best design is re-checked at the file's own `samples`)")

    @model_validator(mode="after")
    def _bounds(self):
        for path, b in self.variables.items():
            if len(b) != 2 or not b[0] < b[1]:
                raise ValueError(f"variables.\"{path}\": give [lower, upper] with lower < "
                                 f"upper, got {b}")
        return self


class PlanetaryDesign(_Strict):
    """A general non-circular planetary train (issue 16): any chain of pairs, forward
    simulated. A gear pair on fixed centres is such a train with its carrier held
    (``carrier.held = true``: the sun is the driver, the planet the follower; `plantmech
    init pair`, examples/planetary/elliptic_pair.toml), and any pair may be given by its
    transmission law instead of a pitch curve (``train.pairs[].law``: the follower's angle
    or the ratio as a function of the driver's turn, an expression or a table, periodic or
    an open segment; ``turns = [n1, n2]`` for lobed gears). A law is refused, naming the
    driver angle, where its ratio reaches zero or changes sign, where it does not repeat as
    the turns ask, or where no centre distance closes the pair; the driver's tooth count
    must be a multiple of n2, and two identical mates (two ellipses about their foci) are
    interchangeable only with an odd count: `plantmech gears` chooses one when ``teeth``
    is left out and says so when an even one is given."""

    mechanism: Literal["planetary"] = Field(description="which mechanism the file "
                                            "describes")
    name: Text = Field("unnamed design", description="name shown in reports")
    description: Text = Field("", description="free text")
    samples: Samples = Field(3600, description="samples per carrier turn")
    trajectory: PlanetaryTrajectory | None = Field(
        None, description="planned tip trajectory for `plantmech inverse` (the train's "
        "pitch curves are then computed; see the [trajectory] table below)")
    carrier: PlanetaryCarrier = Field(PlanetaryCarrier(), description="the carrier")
    train: PlanetaryTrain = Field(description="the gear pairs")
    arm: PlanetaryArm = Field(description="the arm on the planet")
    limits: PlanetaryLimits = Field(PlanetaryLimits(), description="limits on the "
                                    "objectives")
    manufacturing: Manufacturing = Field(Manufacturing(), description="what the workshop "
                                         "can cut (`plantmech gears`; docs/manufacturing.md)")
    optimize: PlanetaryOptimize | None = Field(
        None, description="free variables for `plantmech optimize --problem planetary`")

    @field_validator("train")
    @classmethod
    def _sun_curve_or_trajectory(cls, train, info):
        first = train.pairs[0]
        if first.driver is None and first.follower is None and first.law is None and \
                info.data.get("trajectory") is None:
            raise ValueError("pairs.0.driver is missing: the first pair's driver is the sun; "
                             "give its pitch curve (or the follower's), or a [trajectory] for "
                             "`plantmech inverse` to compute it")
        return train

    @model_validator(mode="after")
    def _held_carrier(self):
        if not self.carrier.held:
            return self
        if self.carrier.arms != 1:
            raise ValueError(f"carrier.arms = {self.carrier.arms}: a held carrier (gears on "
                             "fixed centres) carries one chain")
        if self.train.sun_speed_ratio != 0:
            raise ValueError("train.sun_speed_ratio: with the carrier held the sun is the "
                             "driver (carrier.speed_deg_s); leave the ratio out")
        for k, p in enumerate(self.train.pairs):
            if p.dwell is not None:
                raise ValueError(f"train.pairs.{k}.dwell: a toothless dwell is the carrier's "
                                 "sector; this carrier is held")
        if self.trajectory is not None:
            raise ValueError("trajectory: inverse design moves the carrier; this carrier is "
                             "held")
        return self

    @field_validator("arm")
    @classmethod
    def _arm_or_trajectory(cls, arm, info):
        if info.data.get("trajectory") is None:
            for name in ("length_mm", "initial_angle_deg"):
                if getattr(arm, name) is None:
                    raise ValueError(f"{name} is missing (or give a [trajectory] for "
                                     "`plantmech inverse` to compute it)")
        return arm

    @model_validator(mode="after")
    def _variables_are_numeric_fields(self):
        if self.optimize is None:
            return self
        from pydantic import ValidationError

        for path, (lo, hi) in self.optimize.variables.items():
            field = f"optimize.variables.\"{path}\""
            if path.split(".")[0] in ("optimize", "mechanism"):
                raise ValueError(f"{field}: the optimization's own settings and the "
                                 "mechanism are not design variables")
            try:
                value = get_path(self, path)
            except ValueError as exc:
                raise ValueError(f"{field}: {exc}") from None
            if isinstance(value, bool) or not isinstance(value, float | int):
                raise ValueError(f"{field}: the field holds {value!r}, not a number")
            data = self.model_dump(exclude={"optimize"})
            for bound in (lo, hi):
                set_path(data, path, float(bound))
                try:
                    PlanetaryDesign.model_validate(data)
                except ValidationError as exc:
                    e = exc.errors()[0]
                    loc = ".".join(str(x) for x in e["loc"])
                    raise ValueError(f"{field}: the bound {bound:g} makes the file invalid "
                                     f"({loc}: {e['msg']})") from None
        return self


MECHANISMS["planetary"] = PlanetaryDesign
