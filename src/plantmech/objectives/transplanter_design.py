"""Objectives (i)-(xiv) of a transplanter design file for one design or P variants: the
field and seedling box (``field_setup``), the evaluation of the simulated motion
(``transplanter_population``, ``evaluate_transplanter_population``) and the pitch curves'
tooth fit (``gear_fit``)."""

from __future__ import annotations

import numpy as np

from plantmech.gears.manufacturability import rules_for
from plantmech.mechanisms.transplanter_design import design_param as _param
from plantmech.mechanisms.transplanter_design import simulate_transplanter


def field_setup(design, params=None):
    from plantmech.objectives.transplanter import FieldSetup

    b, f = design.seedling_box, design.field
    return FieldSetup(
        box_x=_param(design, params, "box_x_mm"), box_y=_param(design, params, "box_y_mm"),
        box_inclination_deg=_param(design, params, "box_inclination_deg"),
        mat_thickness=b.mat_thickness_mm, sample=b.sample_mm, box_length=b.length_mm,
        door_length=b.door_length_mm, floor_thickness=b.floor_thickness_mm,
        planting_depth=f.planting_depth_mm,
        spacing_nominal=_param(design, params, "plant_spacing_mm"),
        spacing_range=tuple(f.spacing_range_mm), check_height=f.check_height_mm,
        carrier_speed_deg_s=design.drive.carrier_speed_deg_s,
        needle_length=design.arm.needle_length_mm,
        outline={k: list(v) for k, v in design.arm.outline.items()} if design.arm.outline
        else None)


def transplanter_limits(design):
    """The design file's limits of objectives (iii)-(xii)."""
    return design.limits


def evaluate_transplanter_population(design, radii=None, samples: int = 720,
                                    interference: bool = False, params: dict | None = None,
                                    dense: int = 1024):
    """Simulate and evaluate P variants of the design at once: gear radii (P, N) and
    scalars ``params`` (name -> (P,)): (motion, evaluation). ``dense``: points of the
    pitch curve over one lobe (turn). Interference (exact polygon clearances, compiled)
    is optional: it costs about as much as the rest."""
    _, motion, _, _, ev = transplanter_population(design, radii, samples, dense,
                                                   interference, params)
    return motion, ev


def transplanter_population(design, radii, samples, dense, interference, params):
    """(pair, motion, perimeter, gearbox radius, evaluation) of P designs: the one path of
    the single-design job and of populations."""
    from plantmech.objectives.transplanter import evaluate

    pair, motion, perimeter, box = simulate_transplanter(design, radii, samples, dense=dense,
                                                         params=params)
    teeth = (design.internal_gear.teeth if design.mechanism == "rice_transplanter"
             else design.sun_gear.teeth)
    ev = evaluate(motion, field_setup(design, params), transplanter_limits(design), perimeter,
                  teeth, box, interference=interference,
                  gear_fit=gear_fit(design, pair, perimeter, teeth))
    return pair, motion, perimeter, box, ev


def gear_fit(design, pair, perimeter, teeth):
    """Manufacturability of the internal/planet pitch curves at the design's module
    (objectives xiii, xiv); None for the K-H-V train (its gear check is `plantmech gears`)."""
    from plantmech.gears.internal import tooth_fit

    if design.mechanism != "rice_transplanter" or not teeth:
        return None
    return tooth_fit(pair, np.asarray(perimeter) / (np.pi * teeth), rules_for(design))
