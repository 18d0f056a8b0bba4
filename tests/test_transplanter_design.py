"""mechanisms/transplanter_design.py and objectives/transplanter_design.py: seed 001's trains
and objectives from a design file, for one design or P variants."""

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.mechanisms.transplanter_design import (
    TRANSPLANTER_PARAMS,
    design_param,
    simulate_transplanter,
    transplanter_travel_speed,
)
from plantmech.objectives.transplanter_design import evaluate_transplanter_population

from .conftest import EXAMPLES


def test_design_param_reads_the_file_or_the_population():
    d = load_design(EXAMPLES / "rice_transplanter.toml")
    assert design_param(d, None, "S_mm") == d.arm.S_mm
    assert design_param(d, {}, "carrier_offset_mm") == 0.0
    got = design_param(d, {"S_mm": [1.0, 2.0]}, "S_mm")
    assert isinstance(got, np.ndarray) and got.tolist() == [1.0, 2.0]
    # every scalar but the backlash (the simulation's own argument) has a file value
    for name in TRANSPLANTER_PARAMS:
        if name != "backlash_deg":
            assert np.isfinite(design_param(d, None, name)), name


def test_travel_speed_is_one_plant_per_arm_per_turn():
    """v = s J omega / 360 / 1000: the spacing s (mm) per arm, J arms per carrier turn."""
    d = load_design(EXAMPLES / "rice_transplanter.toml")
    s, J, w = d.field.plant_spacing_mm, d.carrier.arms, d.drive.carrier_speed_deg_s
    assert transplanter_travel_speed(d) == pytest.approx(s * J * (w / 360.0) / 1000.0)


@pytest.mark.parametrize("example", ["rice_transplanter.toml", "rice_transplanter_khv.toml"])
def test_a_population_of_copies_is_the_single_design(example):
    """Two rows of the design's own radii give the P = 1 motion and objectives twice (the
    K-H-V train's per-row tables to 2.5e-13 mm, measured; 1e-9 here)."""
    d = load_design(EXAMPLES / example)
    radii = (d.internal_gear.radii_mm if d.mechanism == "rice_transplanter"
             else d.sun_gear.radii_mm)
    _, one, _, _ = simulate_transplanter(d, samples=90, dense=512)
    _, two, _, _ = simulate_transplanter(d, np.array([radii, radii]), samples=90, dense=512)
    assert np.abs(two.B - one.B[0]).max() < 1e-9
    m1, e1 = evaluate_transplanter_population(d, samples=90, dense=512)
    m2, e2 = evaluate_transplanter_population(d, np.array([radii, radii]), samples=90,
                                              dense=512)
    assert np.allclose(e2.values, e1.values[0], rtol=0, atol=1e-7, equal_nan=True)
    assert e2.values.shape == (2, e1.values.shape[1])
