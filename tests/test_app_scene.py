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


def test_align_pitch_curve_recovers_a_known_turn():
    """A non-circular curve turned by a known angle is turned back to within 0.01 deg,
    with a residual of micrometres (the polar resampling's)."""
    t = np.linspace(0.0, 2 * np.pi, 900, endpoint=False)
    r = 40.0 + 8.0 * np.cos(t) + 3.0 * np.sin(3 * t)
    cut = np.c_[r * np.cos(t), r * np.sin(t)]
    for deg in (0.0, 37.3, 200.05, 359.9):
        d = np.radians(deg)
        drawn = cut @ np.array([[np.cos(d), -np.sin(d)], [np.sin(d), np.cos(d)]]).T
        delta, residual = scene.align_pitch_curve(drawn, cut)
        assert np.degrees(np.angle(np.exp(1j * (delta - d)))) == pytest.approx(0.0, abs=0.01)
        assert residual < 0.01


def test_teeth_refused_when_the_cut_pitch_curve_is_another():
    """A cut gear whose pitch curve is not the drawn one is not drawn with teeth."""
    from shapely.geometry import Polygon

    t = np.linspace(0.0, 2 * np.pi, 720, endpoint=False)
    drawn = 40.0 + 8.0 * np.cos(t)
    other = 40.0 + 2.0 * np.cos(2 * t)
    gear = {"role": "sun", "body": np.c_[drawn * np.cos(t), drawn * np.sin(t)].tolist()}
    xy = np.c_[other * np.cos(t), other * np.sin(t)]
    out = scene.teeth_for_scene([gear], {"sun": (Polygon(xy), xy)})
    assert out["sun"]["drawn"] is False and "differs from the drawn one" in out["sun"]["reason"]
    same = np.c_[drawn * np.cos(t), drawn * np.sin(t)]
    out = scene.teeth_for_scene([gear], {"sun": (Polygon(same), same)})
    assert out["sun"]["drawn"] is True and out["sun"]["residual_mm"] < 0.01


def test_khv_teeth_drawn_in_mesh(khv_scene, tmp_path):
    """The cut K-H-V gears placed on the animated pitch curves mesh in every frame: the
    toothed outlines of sun and middle, middle and planet never overlap by more than a
    sliver (they were cut with 0.1 mm backlash), while each pair's teeth reach into the
    other's tooth spaces (their outlines come within a tenth of a module)."""
    from plantmech.workflows import run_gears

    job, sc = khv_scene
    outlines: dict = {}
    rec = run_gears(job.design, tmp_path, steps=36, outlines=outlines)
    assert set(outlines) == {"sun", "middle", "planet"}
    teeth = scene.teeth_for_scene(sc["gears"], outlines)
    assert all(teeth[n]["drawn"] for n in ("sun", "middle", "planet")), teeth
    module = rec["gears"][0]["module_mm"]
    gears = {g["name"]: g for g in sc["gears"]}

    def toothed(name, f):
        g = gears[name]
        rings = teeth[g["role"]]["rings"]
        a, c = g["rot"][f], np.asarray(g["centre"][f], dtype=float)
        rot = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
        return Polygon(np.asarray(rings[0]) @ rot.T + c,
                       [np.asarray(h) @ rot.T + c for h in rings[1:]]).buffer(0)

    for f in range(0, 36, 4):
        for pair in (("sun (fixed)", "middle 1"), ("middle 1", "planet 1")):
            a, b = (toothed(n, f) for n in pair)
            overlap = a.intersection(b).area
            assert overlap < 0.02 * module**2, (f, pair, overlap)
            assert a.distance(b) < 0.1 * module, (f, pair)


def test_align_pitch_curve_ignores_a_differing_sector():
    """A sector of 45 deg drawn differently (a sun's toothless dwell arc) neither moves
    the fitted turn nor counts in the residual of the best-fitting 80 % of the turn."""
    t = np.linspace(0.0, 2 * np.pi, 1440, endpoint=False)
    r = 60.0 + 10.0 * np.cos(t) + 4.0 * np.sin(2 * t)
    cut = np.c_[r * np.cos(t), r * np.sin(t)]
    d = np.radians(123.4)
    rd = np.where(np.mod(t - 1.0, 2 * np.pi) < np.radians(45.0), 58.0, r)  # an arc
    drawn = np.c_[rd * np.cos(t + d), rd * np.sin(t + d)]
    delta, residual = scene.align_pitch_curve(drawn, cut)
    assert np.degrees(np.angle(np.exp(1j * (delta - d)))) == pytest.approx(0.0, abs=0.02)
    assert residual < 0.01


def _planetary_scene(name, frames=36):
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import build_from_design

    design = load_design(EXAMPLES / name)
    motion = simulate(build_from_design(design), 720)
    return design, motion, scene.planetary_scene(design, motion, frames=frames, detail=720)


@pytest.mark.parametrize("name", ["rotary_transplanter_elliptic.toml",
                                  "planetary/sugarcane_seeder_optimized.toml",
                                  "planetary/rice_transplanter.toml"])
def test_planetary_pitch_curves_touch_without_crossing(name):
    """A general train's gears as the page draws them: every pair of every arm touches in
    every frame, external pairs without crossing, an internal pair's planet inside its
    ring; the arm leaves the last gear's centre (the engine's planet axis)."""
    from plantmech.trains.gearing import gear_names

    design, motion, sc = _planetary_scene(name)
    J = design.carrier.arms
    pairs = design.train.pairs
    label = {n: (n if n == "sun" or J == 1 else None) for p in gear_names(design) for n in p}
    gears = {g["name"]: g for g in sc["gears"]}
    assert len(sc["tip_paths"]) == J
    for j in range(J):
        def g(n, j=j):
            return gears[label[n] or f"{n} {j + 1}"]
        for k, (driver, follower) in enumerate(gear_names(design)):
            ring = pairs[k].kind in ("internal", "internal_ring_follower")
            for f in range(0, 36, 4):
                a, b = Polygon(placed(g(driver), f)), Polygon(placed(g(follower), f))
                assert a.is_valid and b.is_valid
                assert a.exterior.distance(b.exterior) < 0.01, (name, driver, follower, f)
                if ring:  # the smaller gear inside the ring
                    inner, outer = (b, a) if a.area > b.area else (a, b)
                    assert inner.difference(outer).area < 1e-4 * inner.area
                else:
                    assert a.intersection(b).area < 1e-4 * min(a.area, b.area)
        k = scene.frame_index(len(motion.carrier_angle), 36)
        arm = next(li for li in sc["frames"]["links"] if li["name"] == f"arm {j + 1}")
        axis = np.asarray([p[0] for p in arm["points"]])
        assert np.allclose(axis[:, 0] + 1j * axis[:, 1], motion.centre[0, j, k], atol=2e-3)
        assert np.allclose(g("planet")["centre"], axis, atol=2e-3)
