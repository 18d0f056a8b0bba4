"""Design files (TOML) and their validation.

Every error names the file, the field (dotted path, with the point index) and what was
expected. Units at this boundary: mm, degrees, degrees per second, m/s.

Types are strict: a number field takes an integer or a float (never ``true`` or ``"254"``),
an index or count takes an integer (never ``3.0``), a switch takes ``true``/``false``. Sizes
and counts are bounded by what a planting mechanism can be (:data:`MAX_SIZE_MM`,
:data:`MAX_POINTS`, :data:`MAX_SAMPLES`), files by :data:`MAX_FILE_BYTES` and
:data:`MAX_NESTING`, so every run stays bounded.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    Strict,
    StrictBool,
    ValidationError,
    field_validator,
    model_validator,
)

from plantmech.inputs import parse_toml, read_input_text

SECTION_LETTERS = ("a", "b", "c", "d", "e", "f")

#: largest length or coordinate (mm): no planting mechanism is 10 m across.
MAX_SIZE_MM = 10_000.0
#: most type-value points / interpolation radii in one curve.
MAX_POINTS = 1000
#: most samples per carrier turn (0.018 deg steps; a transplanter run at this takes ~20 s).
MAX_SAMPLES = 20_000
#: largest design file (bytes).
MAX_FILE_BYTES = 1_000_000
#: deepest nesting of tables/arrays in a design file.
MAX_NESTING = 8
#: smallest distance between consecutive type-value points (mm).
MIN_POINT_SPACING_MM = 0.1
#: largest speed a field machine or a tip may have (m/s).
MAX_SPEED_M_S = 100.0
#: largest carrier speed (deg/s): 100 turns per second.
MAX_CARRIER_SPEED_DEG_S = 36_000.0


class DesignError(ValueError):
    """A design file could not be read or is invalid (message names file and field)."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


# Strict scalar types (no bool->number, string->number or float->int coercion).
FiniteFloat = Annotated[float, Strict(), Field(allow_inf_nan=False)]
PositiveMM = Annotated[float, Strict(), Field(gt=0, le=MAX_SIZE_MM, allow_inf_nan=False)]
NonNegativeMM = Annotated[float, Strict(), Field(ge=0, le=MAX_SIZE_MM, allow_inf_nan=False)]
Coordinate = Annotated[float, Strict(),
                       Field(ge=-MAX_SIZE_MM, le=MAX_SIZE_MM, allow_inf_nan=False)]
AngleDeg = Annotated[float, Strict(), Field(ge=-720.0, le=720.0, allow_inf_nan=False)]
PositiveAngleDeg = Annotated[float, Strict(), Field(gt=0, le=360.0, allow_inf_nan=False)]
CarrierAngleDeg = Annotated[float, Strict(), Field(ge=0, lt=360, allow_inf_nan=False)]
SpeedMS = Annotated[float, Strict(), Field(gt=0, le=MAX_SPEED_M_S, allow_inf_nan=False)]
Index = Annotated[int, Strict(), Field(ge=0, lt=MAX_POINTS)]
Samples = Annotated[int, Strict(), Field(ge=90, le=MAX_SAMPLES)]
Text = Annotated[str, Strict(), Field(max_length=10_000)]
Letter = Literal["a", "b", "c", "d", "e", "f"]
Interp = Literal["hermite", "spline"]


def _check_polar_points(radii: list, angles: list | None, field: str, unit: str) -> None:
    """Angles of a closed polar curve's control points: as many as radii, strictly
    increasing, spanning less than one turn (otherwise the curve would cross itself)."""
    if len(radii) < 4:
        raise ValueError(f"need at least 4 radii, got {len(radii)}")
    if angles is None:
        return
    if len(angles) != len(radii):
        raise ValueError(f"{field} has {len(angles)} values but radii_mm has {len(radii)}")
    for k in range(1, len(angles)):
        if angles[k] <= angles[k - 1]:
            raise ValueError(
                f"{field} must increase: point {k} at {angles[k]:g} deg follows "
                f"{angles[k - 1]:g} deg (out-of-order angles make the polar pitch curve "
                "cross itself)")
    if angles[-1] - angles[0] >= 360.0:
        raise ValueError(f"{field} span {angles[-1] - angles[0]:g} deg; a closed pitch curve "
                         f"takes each {unit} once (span < 360 deg), more would make it cross "
                         "itself")


def _check_interval(pair, field: str) -> None:
    if pair[0] > pair[1]:
        raise ValueError(f"{field} = [{pair[0]:g}, {pair[1]:g}]: the lower limit is above "
                         "the upper one")


def _uniform(values: list | None, n: int) -> list[float]:
    return values if values is not None else [360.0 * k / n for k in range(n)]


def _section_index(letter: str, meaning: str) -> Any:
    return Field(description=f"{meaning}: index of the type-value point q_i (0-based, q0 = "
                 f"the first point) at section point {letter} of the \"8\" trajectory "
                 "(seed 000 Fig. 2)")


class Sections(_Strict):
    """Type-value point indices (0-based, q0 = 0) of the section boundaries of the
    "8" trajectory: picking ab, transport bcd, seeding de, return efca (seed 000 §2).
    Distinct, and met in the order a, b, c, d, e, f going round the points (cyclically)."""

    a: Index = _section_index("a", "start of picking")
    b: Index = _section_index("b", "end of picking, start of transport")
    c: Index = _section_index("c", "transport: start of the toothless dwell cd")
    d: Index = _section_index("d", "end of transport, start of seeding")
    e: Index = _section_index("e", "seeding point (lowest point, sowing), start of return")
    f: Index = _section_index("f", "return: end of the big ring")

    @model_validator(mode="after")
    def _distinct(self):
        seen: dict[int, str] = {}
        for letter in SECTION_LETTERS:
            idx = getattr(self, letter)
            if idx in seen:
                raise ValueError(f"sections.{letter} = {idx} is the same point as "
                                 f"sections.{seen[idx]}: the six section points must be "
                                 "distinct")
            seen[idx] = letter
        return self


def _point_label(i: int, p) -> str:
    return f"q{i} ({p[0]:g}, {p[1]:g})"


class Trajectory(_Strict):
    """The planned tip trajectory of the seeder (seed 000 Table 2): type-value points
    joined by a periodic cubic, with its section points."""

    points: list[tuple[Coordinate, Coordinate]] = Field(
        description="type-value points q_i = (x, y) in mm, origin at the carrier (sun) axis, "
        "x right, y up, in the order the tip passes them (seed 000 Table 2); 6 to "
        f"{MAX_POINTS} points, consecutive ones at least {MIN_POINT_SPACING_MM} mm apart, "
        "none at the carrier axis, not all on one line", max_length=MAX_POINTS)
    sections: Sections = Field(description="section points a-f as type-value point indices")
    samples: Samples = Field(3600, description="samples of the motion per carrier turn "
                             "(3600 = 0.1 deg)")
    error_estimate_limit_mm: PositiveMM = Field(
        1.0, description="`plantmech inverse`: largest accepted error estimate (mm), the "
        "distance of the pitch radii and of the tip at equal carrier angle between the design "
        "and the same design made from every other type-value point "
        "(objectives.inverse_estimate); above it the verdict is not met and names where to "
        "add points")

    @field_validator("points")
    @classmethod
    def _enough_points(cls, v):
        if len(v) < 6:
            raise ValueError(f"need at least 6 type-value points, got {len(v)}")
        p = np.asarray(v, dtype=float)
        size = float(np.ptp(p, axis=0).max())
        gap = np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)
        k = int(np.argmin(gap))
        if gap[k] < MIN_POINT_SPACING_MM:
            j = (k + 1) % len(p)
            what = "coincide" if gap[k] == 0 else f"are {gap[k]:.3g} mm apart"
            raise ValueError(f"points {_point_label(k, p[k])} and {_point_label(j, p[j])} "
                             f"{what}; consecutive type-value points must be at least "
                             f"{MIN_POINT_SPACING_MM} mm apart")
        d = np.linalg.norm(p[:, None, :] - p[None, :, :], axis=2)
        d[np.tril_indices(len(p))] = np.inf
        i, j = np.unravel_index(int(np.argmin(d)), d.shape)
        if d[i, j] < MIN_POINT_SPACING_MM:
            what = "coincide" if d[i, j] == 0 else f"are only {d[i, j]:.3g} mm apart"
            raise ValueError(f"points {_point_label(i, p[i])} and {_point_label(j, p[j])} "
                             f"{what} (less than {MIN_POINT_SPACING_MM} mm): the tip cannot "
                             "pass the same place twice as two type-value points")
        sv = np.linalg.svd(p - p.mean(axis=0), compute_uv=False)
        if sv[-1] <= 1e-3 * sv[0] or size == 0:
            raise ValueError("all type-value points lie on one line: a closed trajectory "
                             "needs points spread in two directions")
        r = np.hypot(p[:, 0], p[:, 1])
        k = int(np.argmin(r))
        if r[k] < 1e-6:
            raise ValueError(f"point {_point_label(k, p[k])} is at the rotation centre; the "
                             "tip cannot pass through the carrier axis")
        return v

    @model_validator(mode="after")
    def _sections_in_range(self):
        n = len(self.points)
        for letter in SECTION_LETTERS:
            idx = getattr(self.sections, letter)
            if idx >= n:
                raise ValueError(
                    f"sections.{letter} = {idx} but there are only {n} points (q0..q{n - 1})")
        a = self.sections.a
        offsets = [(getattr(self.sections, x) - a) % n for x in SECTION_LETTERS]
        for k in range(1, 6):
            if offsets[k] <= offsets[k - 1]:
                got = ", ".join(f"{x} = {getattr(self.sections, x)}" for x in SECTION_LETTERS)
                raise ValueError(
                    f"sections out of order ({got}): going round the points from a, "
                    f"{SECTION_LETTERS[k]} must come after {SECTION_LETTERS[k - 1]} "
                    "(picking ab, transport bcd, seeding de, return efca)")
        if self.samples < 4 * n:
            raise ValueError(f"samples = {self.samples} is fewer than 4 per type-value point "
                             f"({n} points)")
        return self


class Range(_Strict):
    """An open interval; either end may be left out."""

    min: Coordinate | None = Field(None, description="lower limit (same unit as the field); "
                                    "none if left out")
    max: Coordinate | None = Field(None, description="upper limit (same unit as the field); "
                                    "none if left out")

    @model_validator(mode="after")
    def _ordered(self):
        if self.min is not None and self.max is not None and self.min >= self.max:
            raise ValueError(f"min = {self.min:g} is not below max = {self.max:g}")
        return self


def _limit(default: Range, text: str) -> Any:
    return Field(default, description=text + " (seed 000 Table 1)")


class PlanningLimits(_Strict):
    """Table 1 of seed 000 (mm, degrees): limits on the planned trajectory's shape."""

    small_ring_height_mm: Range = _limit(Range(min=130), "height of the small ring (mm)")
    small_ring_width_mm: Range = _limit(Range(min=180, max=220), "width of the small ring (mm)")
    large_ring_height_mm: Range = _limit(Range(min=400), "height of the large ring (mm)")
    large_ring_width_mm: Range = _limit(Range(min=250), "width of the large ring (mm)")
    cd_central_angle_deg: Range = _limit(Range(min=40), "central angle of section cd about "
                                         "the carrier axis (deg)")
    sowing_height_difference_mm: Range = _limit(Range(min=60, max=100),
                                                "height from the seeding point e to d (mm)")
    centre_to_trench_bottom_mm: Range = _limit(Range(min=260), "depth of the trench bottom "
                                               "below the carrier axis (mm)")


class Dwell(_Strict):
    """Toothless sector of the sun gear (seed 000 Eq. 5): the arm is held in the
    carrier between two section points."""

    enabled: StrictBool = Field(True, description="true: the sun has a toothless sector "
                                "(gears 2-3 stop, the arm turns with the carrier)")
    start: Letter = Field("c", description="section point where the dwell starts")
    end: Letter = Field("d", description="section point where the dwell ends (another "
                        "point than start)")
    anchor: Letter = Field("e", description="section point whose attitude is kept exactly")
    edge_radius_mm: PositiveMM | None = Field(None, description="R2 of Eq. 5: sun radius at "
                                              "the sector's edges (mm); default: from the "
                                              "stage-1 ratio")

    @model_validator(mode="after")
    def _extent(self):
        if self.enabled and self.start == self.end:
            raise ValueError(f"dwell start = end = {self.start!r}: a dwell needs two "
                             "different section points (it would have zero length)")
        return self


class GearTrain(_Strict):
    """How the inverse design splits the ratio over the two stages (seed 000 §3)."""

    a1_mm: PositiveMM | None = Field(None, description="a1: centre distance sun - gear 2 "
                                     "(mm); default L1/2")
    a2_mm: PositiveMM | None = Field(None, description="a2: centre distance gear 3 - planet "
                                     "(mm); default L1/2")
    split_exponent: float = Field(0.5, gt=0, lt=1, allow_inf_nan=False, strict=True,
                                  description="stage-1 ratio = C * (total ratio)^exponent "
                                  "(paper: 0.5)")
    min_pitch_radius_mm: PositiveMM = Field(5.0, description="smallest pitch radius any "
                                            "gear may have (mm)")
    dwell: Dwell | None = Field(None, description="toothless dwell of the sun (Eq. 5); "
                                "default: none")


class Attitude(_Strict):
    """Section 4.1 limits on the cane attitude (degrees)."""

    picking_swing_max_deg: PositiveAngleDeg = Field(30.0, description="objective 1: largest "
                                                    "swing of the arm over picking ab (deg)")
    seeding_swing_max_deg: PositiveAngleDeg = Field(20.0, description="objective 2: largest "
                                                    "swing of the arm over seeding de (deg)")
    sowing_angle_max_deg: PositiveAngleDeg = Field(30.0, description="objective 3: largest "
                                                   "angle of the cane to the ground at e (deg)")


class GearPointsSpec(_Strict):
    """Interpolation points of one intermediate gear (seed 000 Table 4)."""

    radii_mm: list[PositiveMM] = Field(description="r_i: pitch radii at the interpolation "
                                       f"angles (mm), 4 to {MAX_POINTS}",
                                       max_length=MAX_POINTS)
    angles_deg: list[AngleDeg] | None = Field(
        None, description="body angles of the radii (deg), increasing, spanning less than "
        "360 deg; default: uniform 0, 360/N, ...")
    contact_angle_deg: AngleDeg = Field(
        0.0, description="body angle at the contact point (gear 2: with the sun; "
        "gear 3: with the planet) at carrier angle 0 (deg)")

    @model_validator(mode="after")
    def _angles(self):
        _check_polar_points(self.radii_mm, self.angles_deg, "angles_deg", "body angle")
        return self

    def angles(self) -> list[float]:
        return _uniform(self.angles_deg, len(self.radii_mm))


class TrainDwell(_Strict):
    """Toothless sector of the sun gear (seed 000 Eq. 5) in carrier angles."""

    start_deg: CarrierAngleDeg = Field(description="carrier angle (deg, clockwise from the "
                                       "start) where gears 2-3 stop")
    sector_deg: Annotated[float, Strict(), Field(gt=0, lt=360, allow_inf_nan=False)] = Field(
        description="theta_1: carrier turn during the stop (deg)")

    @model_validator(mode="after")
    def _inside(self):
        if self.start_deg + self.sector_deg > 360.0:
            raise ValueError(f"the dwell ({self.start_deg:g} + {self.sector_deg:g} deg) runs "
                             "past the end of the carrier turn; shift the start angle "
                             "(the cycle starts at carrier angle 0)")
        return self


def _section_angle(letter: str) -> Any:
    return Field(description=f"carrier angle of section point {letter} (deg, clockwise from "
                 "the start)")


class SectionAngles(_Strict):
    """Carrier angles (deg, clockwise from the start) of the section points a-f."""

    a: CarrierAngleDeg = _section_angle("a")
    b: CarrierAngleDeg = _section_angle("b")
    c: CarrierAngleDeg = _section_angle("c")
    d: CarrierAngleDeg = _section_angle("d")
    e: CarrierAngleDeg = _section_angle("e")
    f: CarrierAngleDeg = _section_angle("f")

    @model_validator(mode="after")
    def _distinct(self):
        vals = [getattr(self, x) for x in SECTION_LETTERS]
        for i in range(6):
            for j in range(i + 1, 6):
                if vals[i] == vals[j]:
                    raise ValueError(f"{SECTION_LETTERS[i]} and {SECTION_LETTERS[j]} are "
                                     f"both at {vals[i]:g} deg: section points are distinct")
        offsets = [(v - vals[0]) % 360.0 for v in vals]
        for k in range(1, 6):
            if offsets[k] <= offsets[k - 1]:
                got = ", ".join(f"{x} = {v:g}" for x, v in zip(SECTION_LETTERS, vals,
                                                                strict=True))
                raise ValueError(
                    f"sections out of order ({got}): going round the carrier turn from a, "
                    f"{SECTION_LETTERS[k]} must come after {SECTION_LETTERS[k - 1]} "
                    "(picking ab, transport bcd, seeding de, return efca)")
        return self


class Train(_Strict):
    """A second-order train given directly by its pitch curves (seed 000 §4.3, Table 4)."""

    L1_mm: PositiveMM = Field(description="L1: carrier length, sun axis to planet axis (mm)")
    L2_mm: PositiveMM = Field(description="L2: arm length, planet axis to tip (mm)")
    a1_mm: PositiveMM = Field(description="a1: centre distance sun - gear 2 (mm)")
    a2_mm: PositiveMM = Field(description="a2: centre distance gear 3 - planet (mm)")
    gear2: GearPointsSpec = Field(description="gear 2 (meshes with the sun)")
    gear3: GearPointsSpec = Field(description="gear 3 (on gear 2's shaft, meshes with the "
                                  "planet)")
    interpolation: Interp = Field("hermite", description="curve through the radii: periodic "
                                  "cubic Hermite (paper) or periodic spline")
    closure: Literal["check", "centre_distance", "radial_offset", "scale"] = Field(
        "check", description="how an unclosed pair is restored (check = refuse)")
    closure_tolerance_deg: Annotated[float, Strict(), Field(gt=0, le=10.0,
                                                            allow_inf_nan=False)] = Field(
        0.01, description="largest closure error accepted as closed (deg)")
    initial_carrier_angle_deg: AngleDeg = Field(
        description="phi_10: absolute carrier angle at the start (deg, CCW from +x)")
    initial_arm_angle_deg: AngleDeg = Field(
        description="absolute angle of planet axis -> tip at the start (deg, CCW from +x)")
    dwell: TrainDwell | None = Field(None, description="toothless sector of the sun; "
                                     "default: none")
    sections_deg: SectionAngles | None = Field(
        None, description="carrier angles of a-f; default: located on the trajectory's "
        "section points")
    samples: Samples = Field(3600, description="samples per carrier turn")
    min_pitch_radius_mm: PositiveMM = Field(5.0, description="smallest pitch radius any gear "
                                            "may have (mm)")

    @model_validator(mode="after")
    def _radii_fit(self):
        for gear, a, name in ((self.gear2, self.a1_mm, "a1_mm"),
                              (self.gear3, self.a2_mm, "a2_mm")):
            k = int(np.argmax(gear.radii_mm))
            if gear.radii_mm[k] >= a:
                which = "gear2" if gear is self.gear2 else "gear3"
                raise ValueError(f"{which}.radii_mm[{k}] = {gear.radii_mm[k]:g} mm is not "
                                 f"below the centre distance {name} = {a:g} mm: its mate "
                                 "would need a radius <= 0")
        return self


class Operation(_Strict):
    """How the seeder is driven."""

    carrier_speed_deg_s: Annotated[float, Strict(), Field(
        gt=0, le=MAX_CARRIER_SPEED_DEG_S, allow_inf_nan=False)] = Field(
        360.0, description="omega: clockwise carrier speed (deg/s)")
    travel_speed_m_s: Annotated[float, Strict(), Field(
        ge=-MAX_SPEED_M_S, le=MAX_SPEED_M_S, allow_inf_nan=False)] | None = Field(
        None, description="v_c: machine travel speed (m/s); default: zero-speed seeding "
        "(Eq. 18)")


class SpeedLimits(_Strict):
    """Section 4.1 objectives 4-5 (m/s)."""

    seeding_max_m_s: SpeedMS = Field(1.5, description="objective 4: peak static tip speed "
                                     "over seeding de (m/s)")
    return_min_m_s: SpeedMS = Field(1.1, description="objective 5: minimum tip speed over "
                                    "return ef, static and dynamic (m/s)")


class GearChecks(_Strict):
    """Tooth-generation settings used by the seeder's gear checks."""

    tool_pressure_angle_deg: float = Field(20.0, ge=5, le=35, allow_inf_nan=False, strict=True,
                                           description="alpha: pressure angle of the "
                                           "generating rack (deg)")
    max_working_pressure_angle_deg: float = Field(45.0, gt=0, lt=90, allow_inf_nan=False,
                                                  strict=True,
                                                  description="largest working pressure "
                                                  "angle of a non-circular pair (deg)")


class Manufacturing(_Strict):
    """What the workshop can cut (docs/manufacturing.md; Litvin & Fuentes ch. 9). The tool's
    pressure angle and the working-pressure-angle limit are those of [gear_checks] (seeder) or
    [limits] (transplanters, (xiv)); the transplanter's smallest module is its (xi)."""

    pressure_angle_deg: float | None = Field(
        None, ge=14.5, le=30, allow_inf_nan=False, strict=True,
        description="tool pressure angle alpha, deg (standard 20, also 25; default: the "
                    "seeder's gear_checks.tool_pressure_angle_deg, 20 for the transplanters)")
    addendum: float = Field(1.0, gt=0, le=2, allow_inf_nan=False, strict=True,
                            description="tooth addendum ha, x module (standard 1.0; stub 0.8)")
    dedendum: float = Field(1.25, gt=0, le=3, allow_inf_nan=False, strict=True,
                            description="tooth dedendum hf, x module (above the addendum)")
    min_cutter_teeth: int = Field(12, ge=6, le=100, strict=True,
                                  description="smallest shaper cutter (teeth) "
                                  "for concave spans and internal gears")
    min_internal_difference: float = Field(
        8.0, gt=0, le=50, allow_inf_nan=False, strict=True,
        description="smallest equivalent tooth-number difference of an internal mesh (ring - "
                    "planet, or a concave span - its shaper cutter)")
    min_top_land: float = Field(0.25, gt=0, le=1, allow_inf_nan=False, strict=True,
                                description="thinnest tooth tip, x module (pointed below)")
    hub_modules: float = Field(1.5, ge=0, le=10, allow_inf_nan=False, strict=True,
                               description="material between the tooth roots and the bore, "
                                           "x module")
    min_bore_mm: float = Field(3.0, ge=0, le=200, allow_inf_nan=False, strict=True,
                               description="smallest bore diameter (mm)")
    min_module_mm: float = Field(1.0, gt=0, le=50, allow_inf_nan=False, strict=True,
                                 description="smallest module the gears may have (strength), mm "
                                             "(seeder; the transplanters use limits.min_module_mm)")
    modules_mm: list[Annotated[float, Strict(), Field(gt=0, le=50, allow_inf_nan=False)]] | None = (
        Field(None, min_length=1, max_length=100,
              description="the modules the workshop has cutters for, mm; default: ISO 54 "
                          "series I and II (gears/modules.py); a gear cut at another module is "
                          "a finding"))
    special_module: StrictBool = Field(False, description="true: the workshop has a special "
                                       "cutter, a module outside the list is accepted")
    material: Literal["steel", "cast_iron", "pom", "pa66"] = Field(
        "steel", description="gear material for the strength table of `plantmech verify` "
        "(contact/strength.py: C45 steel, grey cast iron GJL-250 by ISO 6336; POM, PA66 by "
        "VDI 2736)")
    shaft_overhang_mm: float | None = Field(
        None, gt=0, le=1000, allow_inf_nan=False, strict=True,
        description="bending arm of the tooth force on the shaft in a gear's bore, mm: from "
                    "the nearest bearing (or the shaft's shoulder) to the middle of the gear's "
                    "face (`plantmech verify`'s shaft check, contact/strength.py); default: "
                    "one face width, an assumption the verdict states")

    @model_validator(mode="after")
    def _root_clearance(self):
        if not self.dedendum > self.addendum:
            raise ValueError(f"dedendum {self.dedendum:g} must exceed addendum "
                             f"{self.addendum:g} (root clearance)")
        return self


class SeederDesign(_Strict):
    """Sugarcane seeder with a second-order non-circular planetary train (seed 000)."""

    mechanism: Literal["sugarcane_seeder"] = Field(description="which mechanism the file "
                                                   "describes")
    name: Text = Field("unnamed design", description="name shown in reports")
    description: Text = Field("", description="free text")
    trajectory: Trajectory | None = Field(None, description="planned trajectory (inverse "
                                          "design)")
    train: Train | None = Field(None, description="gear train by its pitch curves (forward "
                                "simulation)")
    planning_limits: PlanningLimits = Field(PlanningLimits(), description="Table 1 limits")
    gear_train: GearTrain = Field(GearTrain(), description="inverse-design settings")
    attitude: Attitude = Field(Attitude(), description="objectives 1-3")
    operation: Operation = Field(Operation(), description="drive and travel speed")
    speed: SpeedLimits = Field(SpeedLimits(), description="objectives 4-5")
    gear_checks: GearChecks = Field(GearChecks(), description="gear-check settings")
    manufacturing: Manufacturing = Field(Manufacturing(), description="what the workshop "
                                         "can cut (docs/manufacturability.md)")

    @model_validator(mode="after")
    def _something_to_do(self):
        if self.trajectory is None and self.train is None:
            raise ValueError("give a [trajectory] (inverse design) or a [train] "
                             "(pitch curves), or both")
        if self.train is not None and self.train.sections_deg is None and self.trajectory is None:
            raise ValueError("train.sections_deg is needed when there is no [trajectory] "
                             "whose section points could locate them")
        return self


def _model_in(annotation):
    """The pydantic model a field's annotation holds (through Optional, list, dict), or
    None."""
    import typing

    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in typing.get_args(annotation):
        found = _model_in(arg)
        if found is not None:
            return found
    return None


def _fields_at(model, loc) -> list[str]:
    """The field names a table at ``loc`` (a pydantic error's location, without its last
    part) accepts in ``model``; [] where the walk cannot follow (a tagged union)."""
    cls = model
    for part in loc:
        if isinstance(part, int):
            continue
        fields = {f.alias or name: f for name, f in cls.model_fields.items()}
        if part not in fields:
            return []
        cls = _model_in(fields[part].annotation)
        if cls is None:
            return []
    return [f.alias or name for name, f in cls.model_fields.items()]


def _format_error(path, err: ValidationError, model=None) -> str:
    """The error naming each bad field; with ``model`` (the validated class), an unknown
    field gets the closest known names of its table ("did you mean")."""
    from plantmech.typos import did_you_mean

    lines = [f"{path}: invalid design file"]
    for e in err.errors():
        loc = ".".join(str(p) for p in e["loc"]) or "(top level)"
        msg = e["msg"].removeprefix("Value error, ")
        if e["type"] == "missing":
            msg = "required field is missing"
        elif e["type"] == "extra_forbidden":
            msg = "unknown field (check the spelling)"
            if model is not None and e["loc"]:
                hint = did_you_mean(str(e["loc"][-1]), _fields_at(model, e["loc"][:-1]))
                msg = f"unknown field{hint}" if hint else msg
        got = e.get("input")
        tail = ""
        if e["type"] not in ("missing",) and not isinstance(got, dict | list):
            text = repr(got)
            tail = f" (got {text[:60] + '...' if len(text) > 60 else text})"
        lines.append(f"  field '{loc}': {msg}{tail}")
    return "\n".join(lines)


# --- seed 001: rice transplanting mechanisms ----------------------------------------


class InternalGearSpec(_Strict):
    """Lobed non-circular internal gear (seed 001): control radii over one lobe."""

    lobes: Annotated[int, Strict()] = Field(4, ge=2, le=12, description="n: lobes = mean "
                                            "ratio planet : internal gear")
    radii_mm: list[PositiveMM] = Field(description="r_i: pitch radii over one lobe (mm), "
                                       f"4 to {MAX_POINTS}", max_length=MAX_POINTS)
    phases_deg: list[AngleDeg] | None = Field(
        None, description="theta_i: lobe phase of each r_i (deg, 360 per lobe, in the order "
        "the mesh point meets them); default uniform")
    interpolation: Interp = Field("hermite", description="curve through the radii: periodic "
                                  "cubic Hermite or periodic spline")
    initial_phase_deg: AngleDeg = Field(0.0, description="sigma: lobe phase of arm 1's "
                                        "mesh point at the start (deg)")
    teeth: Annotated[int, Strict()] | None = Field(None, ge=3, le=2000,
                                                   description="tooth count (for the "
                                                   "module); a multiple of lobes")
    centre_distance_mm: PositiveMM | None = Field(None, description="a: centre distance "
                                                  "(mm); default: solved so the planet "
                                                  "turns once per lobe")
    min_planet_radius_mm: PositiveMM = Field(2.0, description="smallest planet pitch radius "
                                             "(mm)")
    rim_mm: NonNegativeMM = Field(5.0, description="gearbox wall outside the internal gear's "
                                  "root (mm)")

    @model_validator(mode="after")
    def _check(self):
        _check_polar_points(self.radii_mm, self.phases_deg, "phases_deg", "lobe phase")
        if self.teeth is not None and self.teeth % self.lobes:
            raise ValueError(f"teeth = {self.teeth} is not a multiple of lobes = {self.lobes}: "
                             "every lobe must carry whole teeth")
        return self

    def phases(self) -> list[float]:
        return _uniform(self.phases_deg, len(self.radii_mm))


class SunGearSpec(_Strict):
    """Fixed sun of a K-H-V train: control radii at absolute angles (deg, CCW from +x)."""

    radii_mm: list[PositiveMM] = Field(description="pitch radii of the sun (mm), 4 to "
                                       f"{MAX_POINTS}", max_length=MAX_POINTS)
    angles_deg: list[AngleDeg] | None = Field(None, description="absolute angles of the radii "
                                              "(deg, CCW from +x), increasing, spanning less "
                                              "than 360; default uniform")
    interpolation: Interp = Field("hermite", description="curve through the radii")
    teeth: Annotated[int, Strict()] | None = Field(None, ge=3, le=2000,
                                                   description="tooth count (for the module)")
    rim_mm: NonNegativeMM = Field(5.0, description="gearbox wall outside the sun (mm)")

    @model_validator(mode="after")
    def _check(self):
        _check_polar_points(self.radii_mm, self.angles_deg, "angles_deg", "angle")
        return self

    def angles(self) -> list[float]:
        return _uniform(self.angles_deg, len(self.radii_mm))


class Drive(_Strict):
    """How the transplanter is driven."""

    carrier_speed_deg_s: Annotated[float, Strict(), Field(
        gt=0, le=MAX_CARRIER_SPEED_DEG_S, allow_inf_nan=False)] = Field(
        360.0, description="omega_2: carrier speed, clockwise (deg/s)")
    speed_ratio: float | None = Field(None, gt=0, le=10, allow_inf_nan=False, strict=True,
                                      description="omega_1/omega_2: internal gear to carrier "
                                      "speed; default (n - 1)/n")


class Carrier(_Strict):
    """The rotary box carrying the arms."""

    initial_angle_deg: AngleDeg = Field(description="phi_H0: carrier angle at the start (deg, "
                                        "CCW from +x)")
    arms: Annotated[int, Strict()] = Field(3, ge=1, le=6, description="number of planting "
                                           "arms, evenly spaced")


class Arm(_Strict):
    """A planting arm fixed on a planet (seed 001 Fig. 3)."""

    S_mm: PositiveMM = Field(description="S: planet axis to needle tip B (mm)")
    H1_mm: PositiveMM = Field(description="H1: planet axis to break point A (mm)")
    beta_deg: AngleDeg = Field(description="beta: arm installation angle on the planet (deg)")
    needle_length_mm: PositiveMM = Field(60.0, description="part of the fork allowed through "
                                         "the seedling door (mm)")
    outline: dict[Annotated[str, Field(max_length=64)],
                  Annotated[list[tuple[Coordinate, Coordinate]],
                            Field(max_length=MAX_POINTS)]] | None = Field(
        None, description="{layer: polygon} in the arm frame (mm); default documented",
        max_length=16)

    @model_validator(mode="after")
    def _check(self):
        if self.H1_mm > self.S_mm:
            raise ValueError(f"H1_mm = {self.H1_mm:g} exceeds S_mm = {self.S_mm:g}: the break "
                             "point must lie between the planet axis and the tip")
        if self.needle_length_mm > self.S_mm:
            raise ValueError(f"needle_length_mm = {self.needle_length_mm:g} exceeds S_mm = "
                             f"{self.S_mm:g}: the needle is part of the arm")
        for layer, poly in (self.outline or {}).items():
            _check_outline(poly, f"outline.{layer}")
        return self


def _check_outline(poly: list, field: str) -> None:
    """A drawn outline: at least 3 points enclosing an area (not all on one line), its
    edges crossing nowhere (a GEOS-valid polygon)."""
    if len(poly) < 3:
        raise ValueError(f"{field} has {len(poly)} points; a polygon needs 3")
    p = np.asarray(poly, dtype=float)
    sv = np.linalg.svd(p - p.mean(axis=0), compute_uv=False)
    if sv[0] == 0 or sv[-1] <= 1e-9 * sv[0]:
        raise ValueError(f"{field} encloses no area (its {len(poly)} points lie on one line "
                         "or coincide); give a polygon")
    import shapely

    shape = shapely.Polygon(p)
    if not shape.is_valid:
        reason = shapely.is_valid_reason(shape)
        raise ValueError(f"{field} is not a simple polygon ({reason}): its edges may not "
                         "cross; list the points once around the outline")
    if shape.area <= 1e-6 * float(np.ptp(p, axis=0).max()) ** 2:
        raise ValueError(f"{field} encloses no area; give a polygon")


class SeedlingBox(_Strict):
    """The seedling box and its door (seed 001: Yx, Yy, Ya)."""

    x_mm: Coordinate = Field(description="Yx: door point x (mm, carrier axis at 0)")
    y_mm: Coordinate = Field(description="Yy: door point y (mm)")
    inclination_deg: AngleDeg = Field(description="Ya: floor direction (deg, CCW from +x)")
    mat_thickness_mm: Annotated[float, Strict(), Field(gt=0, le=1000, allow_inf_nan=False)] = (
        Field(20.0, description="seedling mat thickness (mm)"))
    sample_mm: Annotated[float, Strict(), Field(ge=0.5, le=1000, allow_inf_nan=False)] = Field(
        8.0, description="size of one seedling block the needle takes (mm)")
    length_mm: Annotated[float, Strict(), Field(gt=0, le=5000, allow_inf_nan=False)] = Field(
        300.0, description="length of the box floor drawn (mm)")
    door_length_mm: Annotated[float, Strict(), Field(ge=0, le=1000, allow_inf_nan=False)] = (
        Field(15.0, description="length of the door opening (mm)"))
    floor_thickness_mm: Annotated[float, Strict(), Field(gt=0, le=1000,
                                                         allow_inf_nan=False)] = Field(
        5.0, description="thickness of the box floor (mm)")

    @model_validator(mode="after")
    def _sizes(self):
        if self.sample_mm > self.length_mm:
            raise ValueError(f"sample_mm = {self.sample_mm:g} exceeds length_mm = "
                             f"{self.length_mm:g}")
        if self.door_length_mm > self.length_mm:
            raise ValueError(f"door_length_mm = {self.door_length_mm:g} exceeds length_mm = "
                             f"{self.length_mm:g}")
        return self


class FieldSpec(_Strict):
    """The field: planting depth and plant spacing (seed 001)."""

    planting_depth_mm: Annotated[float, Strict(), Field(gt=0, le=1000,
                                                        allow_inf_nan=False)] = Field(
        25.0, description="ground above the lowest tip point (mm)")
    plant_spacing_mm: Annotated[float, Strict(), Field(gt=0, le=2000,
                                                       allow_inf_nan=False)] = Field(
        120.0, description="distance between plants along the row (mm)")
    spacing_range_mm: tuple[Annotated[float, Strict(), Field(gt=0, le=2000,
                                                             allow_inf_nan=False)],
                            Annotated[float, Strict(), Field(gt=0, le=2000,
                                                             allow_inf_nan=False)]] = Field(
        (60.0, 180.0), description="[shortest, longest] plant spacing checked (mm)")
    check_height_mm: Annotated[float, Strict(), Field(gt=0, le=2000,
                                                      allow_inf_nan=False)] = Field(
        100.0, description="height over which the forward inclination is measured (mm)")

    @model_validator(mode="after")
    def _ranges(self):
        _check_interval(self.spacing_range_mm, "spacing_range_mm")
        return self


AnglePair = tuple[AngleDeg, AngleDeg]


class TransplanterLimitsSpec(_Strict):
    """Objectives (iii)-(xv) of seed 001 (degrees, mm)."""

    picking_angle_deg: AnglePair = Field((320.0, 350.0), description="(iii) [min, max] needle "
                                         "angle when picking (deg)")
    pushing_angle_deg: AnglePair = Field((270.0, 310.0), description="(iv) [min, max] needle "
                                         "angle when pushing the seedling (deg)")
    angle_difference_deg: AnglePair = Field((45.0, 65.0), description="(v) [min, max] "
                                            "difference picking - pushing angle (deg)")
    rectangularity_mm: PositiveMM = Field(0.5, description="(vi) largest deviation of the "
                                          "picking path from the door's rectangle (mm)")
    min_trajectory_height_mm: PositiveMM = Field(200.0, description="(vii) smallest height of "
                                                 "the tip trajectory (mm)")
    min_forward_inclination_deg: PositiveAngleDeg = Field(70.0, description="(viii) smallest "
                                                          "forward inclination (deg)")
    max_hole_width_mm: PositiveMM = Field(30.0, description="(ix) widest hole in the ground "
                                          "(mm)")
    min_gearbox_clearance_mm: Coordinate = Field(20.0, description="(x) smallest clearance "
                                                 "between the arm and the gearbox (mm)")
    min_module_mm: Annotated[float, Strict(), Field(gt=0, le=100, allow_inf_nan=False)] = (
        Field(2.5, description="(xi) smallest gear module (mm)"))
    min_needle_angle_deg: AngleDeg = Field(10.0, description="(xii) smallest needle angle to "
                                           "the box floor (deg)")
    min_equivalent_teeth: Annotated[float, Strict(), Field(gt=0, le=1000,
                                                           allow_inf_nan=False)] = Field(
        8.0, description="(xiii) smallest equivalent spur-gear tooth count 2|rho|/m of the "
        "pitch curves")
    min_internal_teeth_difference: Annotated[float, Strict(), Field(
        gt=0, le=1000, allow_inf_nan=False)] = Field(
        8.0, description="(xv) smallest tooth-count difference internal - planet")
    max_working_pressure_angle_deg: Annotated[float, Strict(), Field(
        gt=0, lt=90, allow_inf_nan=False)] = Field(45.0, description="(xiv) largest working "
                                                   "pressure angle (deg)")

    @model_validator(mode="after")
    def _ranges(self):
        for name in ("picking_angle_deg", "pushing_angle_deg", "angle_difference_deg"):
            _check_interval(getattr(self, name), name)
        return self


class _TransplanterBase(_Strict):
    name: Text = Field("unnamed design", description="name shown in reports")
    description: Text = Field("", description="free text")
    samples: Samples = Field(3600, description="samples per carrier turn")
    drive: Drive = Field(Drive(), description="carrier speed and speed ratio")
    carrier: Carrier = Field(description="the rotary box")
    arm: Arm = Field(description="the planting arm")
    seedling_box: SeedlingBox = Field(description="the seedling box")
    field: FieldSpec = Field(FieldSpec(), description="the field")
    limits: TransplanterLimitsSpec = Field(TransplanterLimitsSpec(),
                                           description="objectives (iii)-(xv)")
    manufacturing: Manufacturing = Field(Manufacturing(), description="what the workshop "
                                         "can cut (docs/manufacturability.md)")


class TransplanterDesign(_TransplanterBase):
    """Differential internal-engagement train (seed 001)."""

    mechanism: Literal["rice_transplanter"] = Field(description="which mechanism the file "
                                                    "describes")
    internal_gear: InternalGearSpec = Field(description="the lobed internal gear")

    @model_validator(mode="after")
    def _ratio(self):
        n = self.internal_gear.lobes
        k = self.drive.speed_ratio
        if k is not None:
            m = n * (1 - k)
            if abs(m - round(m)) > 1e-9 or round(m) == 0:
                raise ValueError(
                    f"drive.speed_ratio = {k:g} with {n} lobes moves the mesh point {m:.6g} "
                    "lobes per carrier turn; the arms repeat every carrier turn only for a "
                    f"whole non-zero number (swinging arm: speed_ratio = {(n - 1) / n:.6g})")
        return self


class KHVDesign(_TransplanterBase):
    """Single-DOF K-H-V non-circular planetary train (seed 001 Fig. 1)."""

    mechanism: Literal["rice_transplanter_khv"] = Field(description="which mechanism the "
                                                        "file describes")
    sun_gear: SunGearSpec = Field(description="the fixed non-circular sun")


MECHANISMS = {"sugarcane_seeder": SeederDesign, "rice_transplanter": TransplanterDesign,
              "rice_transplanter_khv": KHVDesign}

# the general train (mechanism = "planetary") registers itself in MECHANISMS
import plantmech.design_planetary  # noqa: E402, F401


def _read_design_file(path: Path) -> str:
    """Text of a design file: a regular file (opened non-blocking, so a FIFO or device
    never hangs), at most MAX_FILE_BYTES, UTF-8 (``plantmech.inputs``); a missing one is
    named with the nearest design file beside it ("did you mean")."""
    if not os.path.lexists(path):
        from plantmech.typos import did_you_mean

        try:
            near = [p.name for p in path.parent.iterdir() if p.suffix == ".toml"]
        except OSError:
            near = []
        raise DesignError(f"{path}: no such design file{did_you_mean(path.name, near)}")
    return read_input_text(path, "design file", MAX_FILE_BYTES, DesignError)


def _dict_depth(obj, level: int = 0) -> int:
    if level > MAX_NESTING:
        return level
    if isinstance(obj, dict):
        return max([_dict_depth(v, level + 1) for v in obj.values()], default=level + 1)
    if isinstance(obj, list):
        return max([_dict_depth(v, level + 1) for v in obj], default=level + 1)
    return level


def _parse_toml(text: str, source: str) -> dict:
    return parse_toml(text, source, MAX_NESTING, DesignError, "a design file needs at most 3")


def load_design(source: str | Path | dict, name: str | None = None):
    """Read and validate a design; raise DesignError naming the source and field.

    ``source``: a path (``Path``, or a ``str`` without a newline or ``=``), TOML text (a
    ``str`` with a newline or ``=``), or an already-parsed ``dict``. ``name`` labels the
    source in messages (default: the path, ``<string>`` or ``<dict>``).
    """
    if isinstance(source, dict):
        label = name or "<dict>"
        raw = source
        if _dict_depth(raw) > MAX_NESTING:
            raise DesignError(f"{label}: nested deeper than {MAX_NESTING} levels")
    elif isinstance(source, str) and ("\n" in source or "=" in source):
        label = name or "<string>"
        if len(source.encode("utf-8")) > MAX_FILE_BYTES:
            raise DesignError(f"{label}: larger than {MAX_FILE_BYTES} bytes")
        raw = _parse_toml(source, label)
    elif isinstance(source, str | os.PathLike):
        path = Path(source)
        label = name or str(path)
        if str(source) == "":
            raise DesignError("the design file name is empty")
        raw = _parse_toml(_read_design_file(path), label)
    else:
        raise DesignError(f"a design is a path, TOML text or a dict, not {type(source).__name__}")
    return _validate(raw, label)


def _validate(raw: dict, path) -> Any:
    mech = raw.get("mechanism")
    known = ", ".join(f'"{m}"' for m in MECHANISMS)
    if mech is None:
        raise DesignError(f"{path}: field 'mechanism' is missing (expected one of {known})")
    if not isinstance(mech, str):
        raise DesignError(f"{path}: field 'mechanism': expected a string, one of {known} "
                          f"(got {type(mech).__name__})")
    if mech not in MECHANISMS:
        raise DesignError(f"{path}: field 'mechanism': unknown mechanism {mech[:60]!r} "
                          f"(expected one of {known})")
    if mech == "sugarcane_seeder" and "trajectory" not in raw and "train" not in raw:
        raise DesignError(f"{path}: field 'trajectory' is missing: give a [trajectory] "
                          "(inverse design) or a [train] (pitch curves), or both")
    try:
        return MECHANISMS[mech].model_validate(raw)
    except ValidationError as exc:
        raise DesignError(_format_error(path, exc, MECHANISMS[mech])) from None
    except RecursionError:
        raise DesignError(f"{path}: nested too deeply") from None
