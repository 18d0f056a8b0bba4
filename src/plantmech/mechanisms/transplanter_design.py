"""Seed 001's transplanting mechanisms built from a design file: the pair and motion of
the differential (``rice_transplanter``) and K-H-V trains for one design or P variants
(``simulate_transplanter``), the per-design values of populations (``design_param``) and
the machine's travel speed. Units: mm and rad inside, mm and deg in the design file."""

from __future__ import annotations

import numpy as np

# per-design overrides of scalar design values for populations (name -> (P,) array): the
# design file's fields, and three tolerances the file has no field for:
# "carrier_offset_mm" (the planet axis that much farther from O than the pair's centre
# distance: a carrier-length error), "backlash_deg" (the planet's angular play against its
# drive) and "plant_spacing_mm" ([field]: the spacing the machine's travel speed gives)
TRANSPLANTER_PARAMS = ("initial_angle_deg", "initial_phase_deg", "S_mm", "H1_mm", "beta_deg",
                       "box_x_mm", "box_y_mm", "box_inclination_deg", "carrier_offset_mm",
                       "backlash_deg", "plant_spacing_mm")


def design_param(design, params, name):
    """The value of scalar ``name`` (one of TRANSPLANTER_PARAMS, the design file's units:
    mm, deg) per design: ``params[name]`` as a (P,) array when given, else the design's own
    (0 for the carrier offset)."""
    if params and name in params:
        return np.asarray(params[name], dtype=float)
    return {"initial_angle_deg": lambda: design.carrier.initial_angle_deg,
            "initial_phase_deg": lambda: design.internal_gear.initial_phase_deg,
            "S_mm": lambda: design.arm.S_mm, "H1_mm": lambda: design.arm.H1_mm,
            "beta_deg": lambda: design.arm.beta_deg,
            "box_x_mm": lambda: design.seedling_box.x_mm,
            "box_y_mm": lambda: design.seedling_box.y_mm,
            "box_inclination_deg": lambda: design.seedling_box.inclination_deg,
            "carrier_offset_mm": lambda: 0.0,
            "plant_spacing_mm": lambda: design.field.plant_spacing_mm}[name]()


def transplanter_travel_speed(design) -> float:
    """The machine's travel speed v (m/s) that one plant per arm per carrier turn at the
    design's plant spacing s needs: v = s J omega / 360 (s in mm, J arms, omega the
    carrier speed in deg/s) / 1000."""
    return (design.field.plant_spacing_mm * design.carrier.arms
            * design.drive.carrier_speed_deg_s / 360.0 / 1000.0)


def simulate_transplanter(design, radii=None, samples: int | None = None, dense: int = 4096,
                          params: dict | None = None):
    """(pair, motion, perimeter (P,), gearbox radius (P,)) for ``design`` or for P
    variants of its gear radii (P, N) and of the scalars in ``params`` (name -> (P,),
    names in TRANSPLANTER_PARAMS). A carrier offset or a backlash moves the planet, not
    the gears: the perimeter and the gearbox are the pair's."""
    from plantmech.gears.internal import internal_perimeter, lobed_internal_pair
    from plantmech.mechanisms.transplanter import (
        ArmGeometry,
        khv_pair,
        simulate_differential,
        simulate_khv,
    )

    samples = samples or design.samples
    arm = ArmGeometry(design_param(design, params, "S_mm"),
                      design_param(design, params, "H1_mm"),
                      np.radians(design_param(design, params, "beta_deg")))
    carrier0 = np.radians(design_param(design, params, "initial_angle_deg"))
    offset = design_param(design, params, "carrier_offset_mm")
    play = (np.radians(params["backlash_deg"]) if params and "backlash_deg" in params
            else None)
    g = getattr(design, "internal_gear", None)  # the differential's lobed internal gear
    if g is not None:
        r = np.atleast_2d(g.radii_mm if radii is None else radii).astype(float)
        pair = lobed_internal_pair(np.radians(g.phases()), r, g.lobes, g.interpolation, dense,
                                   g.min_planet_radius_mm, g.centre_distance_mm)
        k = design.drive.speed_ratio
        k = (g.lobes - 1) / g.lobes if k is None else k
        phase0 = np.radians(design_param(design, params, "initial_phase_deg"))
        motion = simulate_differential(pair, k, carrier0, arm, phase0,
                                       design.carrier.arms, samples, offset, play)
        perimeter = internal_perimeter(pair)
        module = perimeter / (np.pi * g.teeth) if g.teeth else np.zeros_like(perimeter)
        box = pair.R.max(axis=1) + 1.25 * module + g.rim_mm
    else:
        g = design.sun_gear
        r = np.atleast_2d(g.radii_mm if radii is None else radii).astype(float)
        pair = khv_pair(np.radians(g.angles()), r, carrier0, g.interpolation, dense)
        motion = simulate_khv(pair, carrier0, arm, design.carrier.arms, samples, offset, play)
        h = pair.sigma[1] - pair.sigma[0]
        # sun perimeter: polar curve over absolute angle (sigma runs clockwise)
        dr = np.gradient(pair.r_sun, h, axis=1)
        ds = np.sqrt(pair.r_sun**2 + dr**2)
        perimeter = np.sum(0.5 * (ds[:, 1:] + ds[:, :-1]), axis=1) * h
        module = perimeter / (np.pi * g.teeth) if g.teeth else np.zeros_like(perimeter)
        # the carrier box holds the planets at 2a: its reach is 2a + largest planet radius
        box = 2 * pair.a + pair.r_sun.max(axis=1) + 1.25 * module + g.rim_mm
    return pair, motion, perimeter, box
