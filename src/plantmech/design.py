"""Design files (TOML) and their validation.

Every error names the file, the field (dotted path) and what was expected.
Units at this boundary: mm, degrees, degrees per second.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

SECTION_LETTERS = ("a", "b", "c", "d", "e", "f")


class DesignError(ValueError):
    """A design file could not be read or is invalid (message names file and field)."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]
PositiveMM = Annotated[float, Field(gt=0, allow_inf_nan=False)]


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


def _uniform(values: list | None, n: int) -> list[float]:
    return values if values is not None else [360.0 * k / n for k in range(n)]


class Sections(_Strict):
    """Type-value point indices (0-based, q0 = 0) of the section boundaries of the
    "8" trajectory: picking ab, transport bcd, seeding de, return efca (seed 000 §2)."""

    a: int = Field(ge=0)
    b: int = Field(ge=0)
    c: int = Field(ge=0)
    d: int = Field(ge=0)
    e: int = Field(ge=0)
    f: int = Field(ge=0)


class Trajectory(_Strict):
    points: list[tuple[FiniteFloat, FiniteFloat]] = Field(
        description="type-value points q_i (x, y) in mm, origin at the carrier axis")
    sections: Sections
    samples: int = Field(3600, ge=90, le=200_000, description="samples per carrier turn")

    @field_validator("points")
    @classmethod
    def _enough_points(cls, v):
        if len(v) < 6:
            raise ValueError(f"need at least 6 type-value points, got {len(v)}")
        return v

    @model_validator(mode="after")
    def _sections_in_range(self):
        n = len(self.points)
        for letter in SECTION_LETTERS:
            idx = getattr(self.sections, letter)
            if idx >= n:
                raise ValueError(
                    f"sections.{letter} = {idx} but there are only {n} points (q0..q{n - 1})")
        return self


class Range(_Strict):
    min: FiniteFloat | None = None
    max: FiniteFloat | None = None


class PlanningLimits(_Strict):
    """Table 1 of seed 000 (mm, degrees)."""

    small_ring_height_mm: Range = Range(min=130)
    small_ring_width_mm: Range = Range(min=180, max=220)
    large_ring_height_mm: Range = Range(min=400)
    large_ring_width_mm: Range = Range(min=250)
    cd_central_angle_deg: Range = Range(min=40)
    sowing_height_difference_mm: Range = Range(min=60, max=100)
    centre_to_trench_bottom_mm: Range = Range(min=260)


class Dwell(_Strict):
    """Toothless sector of the sun gear (seed 000 Eq. 5): the arm is held in the
    carrier between two section points."""

    enabled: bool = True
    start: Literal["a", "b", "c", "d", "e", "f"] = "c"
    end: Literal["a", "b", "c", "d", "e", "f"] = "d"
    anchor: Literal["a", "b", "c", "d", "e", "f"] = Field(
        "e", description="section point whose attitude is kept exactly")
    edge_radius_mm: PositiveMM | None = Field(None, description="R2 of Eq. 5")


class GearTrain(_Strict):
    a1_mm: PositiveMM | None = Field(None, description="sun-gear 2 centre distance (L1/2)")
    a2_mm: PositiveMM | None = Field(None, description="gear 3-planet centre distance (L1/2)")
    split_exponent: float = Field(0.5, gt=0, lt=1, allow_inf_nan=False)
    min_pitch_radius_mm: PositiveMM = 5.0
    dwell: Dwell | None = None


class Attitude(_Strict):
    """Section 4.1 limits on the cane attitude (degrees)."""

    picking_swing_max_deg: PositiveMM = 30.0
    seeding_swing_max_deg: PositiveMM = 20.0
    sowing_angle_max_deg: PositiveMM = 30.0


class GearPointsSpec(_Strict):
    """Interpolation points of one intermediate gear (seed 000 Table 4)."""

    radii_mm: list[PositiveMM] = Field(description="pitch radii at the interpolation angles")
    angles_deg: list[FiniteFloat] | None = Field(
        None, description="body angles, increasing, spanning less than 360 deg; "
        "default: uniform 0, 360/N, ...")
    contact_angle_deg: FiniteFloat = Field(
        0.0, description="body angle at the contact point (gear 2: with the sun; "
        "gear 3: with the planet) at carrier angle 0")

    @model_validator(mode="after")
    def _angles(self):
        _check_polar_points(self.radii_mm, self.angles_deg, "angles_deg", "body angle")
        return self

    def angles(self) -> list[float]:
        return _uniform(self.angles_deg, len(self.radii_mm))


class TrainDwell(_Strict):
    """Toothless sector of the sun gear (seed 000 Eq. 5) in carrier angles."""

    start_deg: float = Field(ge=0, lt=360, allow_inf_nan=False,
                             description="carrier angle (clockwise from the start) "
                             "where gears 2-3 stop")
    sector_deg: float = Field(gt=0, lt=360, allow_inf_nan=False,
                              description="theta_1: carrier turn during the stop")

    @model_validator(mode="after")
    def _inside(self):
        if self.start_deg + self.sector_deg > 360.0:
            raise ValueError(f"the dwell ({self.start_deg:g} + {self.sector_deg:g} deg) runs "
                             "past the end of the carrier turn; shift the start angle "
                             "(the cycle starts at carrier angle 0)")
        return self


class SectionAngles(_Strict):
    """Carrier angles (deg, clockwise from the start) of the section points a-f."""

    a: float = Field(ge=0, lt=360, allow_inf_nan=False)
    b: float = Field(ge=0, lt=360, allow_inf_nan=False)
    c: float = Field(ge=0, lt=360, allow_inf_nan=False)
    d: float = Field(ge=0, lt=360, allow_inf_nan=False)
    e: float = Field(ge=0, lt=360, allow_inf_nan=False)
    f: float = Field(ge=0, lt=360, allow_inf_nan=False)


class Train(_Strict):
    """A second-order train given directly by its pitch curves (seed 000 §4.3, Table 4)."""

    L1_mm: PositiveMM = Field(description="carrier length, sun axis to planet axis")
    L2_mm: PositiveMM = Field(description="arm length, planet axis to tip")
    a1_mm: PositiveMM = Field(description="centre distance sun - gear 2")
    a2_mm: PositiveMM = Field(description="centre distance gear 3 - planet")
    gear2: GearPointsSpec
    gear3: GearPointsSpec
    interpolation: Literal["hermite", "spline"] = "hermite"
    closure: Literal["check", "centre_distance", "radial_offset", "scale"] = Field(
        "check", description="how an unclosed pair is restored (check = refuse)")
    closure_tolerance_deg: PositiveMM = 0.01
    initial_carrier_angle_deg: FiniteFloat = Field(
        description="absolute carrier angle phi_10 at the start, CCW from +x")
    initial_arm_angle_deg: FiniteFloat = Field(
        description="absolute angle of planet axis -> tip at the start, CCW from +x")
    dwell: TrainDwell | None = None
    sections_deg: SectionAngles | None = Field(
        None, description="carrier angles of a-f; default: located on the trajectory's "
        "section points")
    samples: int = Field(3600, ge=90, le=200_000, description="samples per carrier turn")
    min_pitch_radius_mm: PositiveMM = 5.0


class Operation(_Strict):
    carrier_speed_deg_s: PositiveMM = Field(360.0, description="clockwise carrier speed")
    travel_speed_m_s: FiniteFloat | None = Field(
        None, description="machine travel speed v_c; default: zero-speed seeding (Eq. 18)")


class SpeedLimits(_Strict):
    """Section 4.1 objectives 4-5 (m/s)."""

    seeding_max_m_s: PositiveMM = 1.5
    return_min_m_s: PositiveMM = 1.1


class GearChecks(_Strict):
    tool_pressure_angle_deg: float = Field(20.0, gt=0, lt=45, allow_inf_nan=False)
    max_working_pressure_angle_deg: float = Field(45.0, gt=0, lt=90, allow_inf_nan=False)


class Manufacturing(_Strict):
    """What the workshop can cut (docs/manufacturing.md; Litvin & Fuentes ch. 9). The tool's
    pressure angle and the working-pressure-angle limit are those of [gear_checks] (seeder) or
    [limits] (transplanters, (xiv)); the transplanter's smallest module is its (xi)."""

    pressure_angle_deg: float | None = Field(
        None, ge=14.5, le=30, allow_inf_nan=False,
        description="tool pressure angle alpha, deg (standard 20, also 25; default: the "
                    "seeder's gear_checks.tool_pressure_angle_deg, 20 for the transplanters)")
    addendum: float = Field(1.0, gt=0, le=2, allow_inf_nan=False,
                            description="tooth addendum ha, x module (standard 1.0; stub 0.8)")
    dedendum: float = Field(1.25, gt=0, le=3, allow_inf_nan=False,
                            description="tooth dedendum hf, x module (above the addendum)")
    min_cutter_teeth: int = Field(12, ge=6, le=100, description="smallest shaper cutter (teeth) "
                                  "for concave spans and internal gears")
    min_internal_difference: float = Field(
        8.0, gt=0, le=50, allow_inf_nan=False,
        description="smallest equivalent tooth-number difference of an internal mesh (ring - "
                    "planet, or a concave span - its shaper cutter)")
    min_top_land: float = Field(0.25, gt=0, le=1, allow_inf_nan=False,
                                description="thinnest tooth tip, x module (pointed below)")
    hub_modules: float = Field(1.5, ge=0, le=10, allow_inf_nan=False,
                               description="material between the tooth roots and the bore, "
                                           "x module")
    min_bore_mm: float = Field(3.0, ge=0, le=200, allow_inf_nan=False,
                               description="smallest bore diameter (mm)")
    min_module_mm: float = Field(1.0, gt=0, le=50, allow_inf_nan=False,
                                 description="smallest module the gears may have (strength), mm "
                                             "(seeder; the transplanters use limits.min_module_mm)")

    @model_validator(mode="after")
    def _root_clearance(self):
        if not self.dedendum > self.addendum:
            raise ValueError(f"dedendum {self.dedendum:g} must exceed addendum "
                             f"{self.addendum:g} (root clearance)")
        return self


class SeederDesign(_Strict):
    mechanism: Literal["sugarcane_seeder"]
    name: str = "unnamed design"
    description: str = ""
    trajectory: Trajectory | None = None
    train: Train | None = None
    planning_limits: PlanningLimits = PlanningLimits()
    gear_train: GearTrain = GearTrain()
    attitude: Attitude = Attitude()
    operation: Operation = Operation()
    speed: SpeedLimits = SpeedLimits()
    gear_checks: GearChecks = GearChecks()
    manufacturing: Manufacturing = Manufacturing()

    @model_validator(mode="after")
    def _something_to_do(self):
        if self.trajectory is None and self.train is None:
            raise ValueError("give a [trajectory] (inverse design) or a [train] "
                             "(pitch curves), or both")
        if self.train is not None and self.train.sections_deg is None and self.trajectory is None:
            raise ValueError("train.sections_deg is needed when there is no [trajectory] "
                             "whose section points could locate them")
        return self


def _format_error(path: Path, err: ValidationError) -> str:
    lines = [f"{path}: invalid design file"]
    for e in err.errors():
        loc = ".".join(str(p) for p in e["loc"]) or "(top level)"
        msg = e["msg"].removeprefix("Value error, ")
        if e["type"] == "missing":
            msg = "required field is missing"
        elif e["type"] == "extra_forbidden":
            msg = "unknown field (check the spelling)"
        got = e.get("input")
        tail = "" if e["type"] in ("missing",) or isinstance(got, dict) else f" (got {got!r})"
        lines.append(f"  field '{loc}': {msg}{tail}")
    return "\n".join(lines)


# --- seed 001: rice transplanting mechanisms ----------------------------------------


class InternalGearSpec(_Strict):
    """Lobed non-circular internal gear (seed 001): control radii over one lobe."""

    lobes: int = Field(4, ge=2, description="n: lobes = mean ratio planet : internal gear")
    radii_mm: list[PositiveMM] = Field(description="r_i over one lobe")
    phases_deg: list[FiniteFloat] | None = Field(
        None, description="lobe phase of each r_i (360 per lobe, in the order the mesh "
        "point meets them); default uniform")
    interpolation: Literal["hermite", "spline"] = "hermite"
    initial_phase_deg: FiniteFloat = Field(0.0, description="sigma: lobe phase of arm 1's "
                                           "mesh point at the start")
    teeth: int | None = Field(None, ge=3, description="tooth count (for the module)")
    centre_distance_mm: PositiveMM | None = Field(None, description="default: solved so the "
                                                  "planet turns once per lobe")
    min_planet_radius_mm: PositiveMM = 2.0
    rim_mm: float = Field(5.0, ge=0, allow_inf_nan=False,
                          description="gearbox wall outside the internal gear's root")

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

    radii_mm: list[PositiveMM]
    angles_deg: list[FiniteFloat] | None = None
    interpolation: Literal["hermite", "spline"] = "hermite"
    teeth: int | None = Field(None, ge=3)
    rim_mm: float = Field(5.0, ge=0, allow_inf_nan=False)

    @model_validator(mode="after")
    def _check(self):
        _check_polar_points(self.radii_mm, self.angles_deg, "angles_deg", "angle")
        return self

    def angles(self) -> list[float]:
        return _uniform(self.angles_deg, len(self.radii_mm))


class Drive(_Strict):
    carrier_speed_deg_s: PositiveMM = Field(360.0, description="omega_2, clockwise")
    speed_ratio: float | None = Field(None, gt=0, allow_inf_nan=False,
                                      description="omega_1/omega_2; default (n - 1)/n")


class Carrier(_Strict):
    initial_angle_deg: FiniteFloat = Field(description="phi_H0, CCW from +x")
    arms: int = Field(3, ge=1, le=6)


class Arm(_Strict):
    S_mm: PositiveMM = Field(description="planet axis to needle tip B")
    H1_mm: PositiveMM = Field(description="planet axis to break point A")
    beta_deg: FiniteFloat = Field(description="arm installation angle on the planet")
    needle_length_mm: PositiveMM = 60.0
    outline: dict[str, list[tuple[FiniteFloat, FiniteFloat]]] | None = Field(
        None, description="{layer: polygon} in the arm frame (mm); default documented")

    @model_validator(mode="after")
    def _check(self):
        if self.H1_mm > self.S_mm:
            raise ValueError(f"H1_mm = {self.H1_mm:g} exceeds S_mm = {self.S_mm:g}: the break "
                             "point must lie between the planet axis and the tip")
        return self


class SeedlingBox(_Strict):
    x_mm: FiniteFloat = Field(description="Yx: door point")
    y_mm: FiniteFloat = Field(description="Yy: door point")
    inclination_deg: FiniteFloat = Field(description="Ya: floor direction, CCW from +x")
    mat_thickness_mm: PositiveMM = 20.0
    sample_mm: PositiveMM = 8.0
    length_mm: PositiveMM = 300.0
    door_length_mm: float = Field(15.0, ge=0, allow_inf_nan=False)
    floor_thickness_mm: PositiveMM = 5.0


class FieldSpec(_Strict):
    planting_depth_mm: PositiveMM = Field(25.0, description="ground above the lowest tip point")
    plant_spacing_mm: PositiveMM = 120.0
    spacing_range_mm: tuple[PositiveMM, PositiveMM] = (60.0, 180.0)
    check_height_mm: PositiveMM = Field(100.0, description="height over which the forward "
                                        "inclination is measured")


class TransplanterLimitsSpec(_Strict):
    picking_angle_deg: tuple[FiniteFloat, FiniteFloat] = (320.0, 350.0)
    pushing_angle_deg: tuple[FiniteFloat, FiniteFloat] = (270.0, 310.0)
    angle_difference_deg: tuple[FiniteFloat, FiniteFloat] = (45.0, 65.0)
    rectangularity_mm: PositiveMM = 0.5
    min_trajectory_height_mm: PositiveMM = 200.0
    min_forward_inclination_deg: PositiveMM = 70.0
    max_hole_width_mm: PositiveMM = 30.0
    min_gearbox_clearance_mm: FiniteFloat = 20.0
    min_module_mm: PositiveMM = 2.5
    min_needle_angle_deg: FiniteFloat = 10.0
    min_equivalent_teeth: PositiveMM = Field(8.0, description="(xiii) smallest equivalent "
                                             "spur-gear tooth count 2|rho|/m of the pitch curves")
    min_internal_teeth_difference: PositiveMM = Field(8.0, description="(xv)")
    max_working_pressure_angle_deg: PositiveMM = Field(45.0, lt=90, description="(xiv)")


class _TransplanterBase(_Strict):
    name: str = "unnamed design"
    description: str = ""
    samples: int = Field(3600, ge=90, le=200_000)
    drive: Drive = Drive()
    carrier: Carrier
    arm: Arm
    seedling_box: SeedlingBox
    field: FieldSpec = FieldSpec()
    limits: TransplanterLimitsSpec = TransplanterLimitsSpec()
    manufacturing: Manufacturing = Manufacturing()


class TransplanterDesign(_TransplanterBase):
    """Differential internal-engagement train (seed 001)."""

    mechanism: Literal["rice_transplanter"]
    internal_gear: InternalGearSpec

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

    mechanism: Literal["rice_transplanter_khv"]
    sun_gear: SunGearSpec


MECHANISMS = {"sugarcane_seeder": SeederDesign, "rice_transplanter": TransplanterDesign,
              "rice_transplanter_khv": KHVDesign}


def load_design(path: str | Path):
    """Read and validate a design file; raise DesignError naming file and field."""
    path = Path(path)
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise DesignError(f"{path}: no such design file") from None
    except tomllib.TOMLDecodeError as exc:
        raise DesignError(f"{path}: not valid TOML: {exc}") from None
    except UnicodeDecodeError:
        raise DesignError(f"{path}: not a UTF-8 text file") from None
    mech = raw.get("mechanism")
    known = ", ".join(f'"{m}"' for m in MECHANISMS)
    if mech is None:
        raise DesignError(f"{path}: field 'mechanism' is missing (expected one of {known})")
    if mech not in MECHANISMS:
        raise DesignError(f"{path}: field 'mechanism': unknown mechanism {mech!r} "
                          f"(expected one of {known})")
    if mech != "sugarcane_seeder":
        try:
            return MECHANISMS[mech].model_validate(raw)
        except ValidationError as exc:
            raise DesignError(_format_error(path, exc)) from None
    if "trajectory" not in raw and "train" not in raw:
        raise DesignError(f"{path}: field 'trajectory' is missing: give a [trajectory] "
                          "(inverse design) or a [train] (pitch curves), or both")
    try:
        design = SeederDesign.model_validate(raw)
    except ValidationError as exc:
        raise DesignError(_format_error(path, exc)) from None
    pts = design.trajectory.points if design.trajectory is not None else []
    for i, (x, y) in enumerate(pts):
        if math.hypot(x, y) < 1e-9:
            raise DesignError(f"{path}: field 'trajectory.points.{i}': q{i} is at the "
                              "rotation centre; the tip cannot pass through the carrier axis")
    for i in range(len(pts)):
        j = (i + 1) % len(pts)
        if pts[i] == pts[j]:
            raise DesignError(f"{path}: field 'trajectory.points': q{i} and q{j} coincide")
    return design
