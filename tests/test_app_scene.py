"""Drawing data of the app (plantmech.app.scene): the gears the page animates are placed so
that mating pitch curves touch without crossing in every frame (an independent check with
shapely on the placed polygons; a wrong centre, rotation sign or phase makes them overlap
or part)."""

import numpy as np
import pytest
from shapely.geometry import Polygon

from plantmech.app import scene
from plantmech.design import load_design
from plantmech.workflows import run_transplanter

from .conftest import EXAMPLES


def placed(gear: dict, frame: int) -> np.ndarray:
    """A gear's body outline (mm) at its centre and rotation of ``frame``."""
    body = np.asarray(gear["body"], dtype=float)
    c = np.asarray(gear["centre"][frame], dtype=float)
    a = gear["rot"][frame]
    rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    return body @ rot.T + c


@pytest.fixture(scope="module")
def khv_scene():
    job = run_transplanter(load_design(EXAMPLES / "rice_transplanter_khv.toml"))
    return job, scene.transplanter_scene(job, frames=36, detail=720)


def test_khv_draws_sun_middles_and_planets(khv_scene):
    job, sc = khv_scene
    arms = job.design.carrier.arms
    names = [g["name"] for g in sc["gears"]]
    assert names[0] == "sun (fixed)"
    assert sorted(names[1:]) == sorted([f"middle {j + 1}" for j in range(arms)]
                                       + [f"planet {j + 1}" for j in range(arms)])
    a = float(job.pair.a[0])
    for g in sc["gears"]:
        c = np.asarray(g["centre"], dtype=float)
        radius = np.hypot(c[:, 0], c[:, 1])
        if g["role"] == "middle":  # on the carrier at a
            assert radius == pytest.approx(a, abs=2e-3)
        elif g["role"] == "planet":  # at 2a, the engine's planet axis
            assert radius == pytest.approx(2 * a, abs=2e-3)


@pytest.mark.parametrize("pair", [("sun (fixed)", "middle 1"), ("middle 1", "planet 1"),
                                  ("sun (fixed)", "middle 2"), ("middle 2", "planet 2")])
def test_khv_pitch_curves_touch_without_crossing(khv_scene, pair):
    _, sc = khv_scene
    gears = {g["name"]: g for g in sc["gears"]}
    for f in range(0, 36, 3):
        a, b = (Polygon(placed(gears[n], f)) for n in pair)
        assert a.is_valid and b.is_valid
        assert a.distance(b) < 0.01  # touching (mm)
        assert a.exterior.distance(b.exterior) < 0.01
        # crossing: the overlap is below the rounding of the drawing data
        assert a.intersection(b).area < 1e-4 * min(a.area, b.area)


def test_khv_planets_turn_with_the_engines_planet_angle(khv_scene):
    """The planet's drawn rotation is the engine's phi_2 (the arm is fixed to it)."""
    job, sc = khv_scene
    k = scene.frame_index(len(job.motion.carrier_angle), 36)
    planet = next(g for g in sc["gears"] if g["name"] == "planet 1")
    assert np.allclose(planet["rot"], job.motion.planet_angle[0, 0, k], atol=1e-5)
